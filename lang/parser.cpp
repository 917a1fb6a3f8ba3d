// Recursive-descent parser for { def } { statement } expr. This file: tokens, errors and
// recovery, node building under the nesting/depth/node limits, and expressions. Errors become
// diagnostics plus error nodes; over-deep input is skipped iteratively, never recursed into.
#include "lang/parser_impl.h"

namespace gale::lang {

namespace parser_detail {

namespace {

// Precedence of a binary operator token (higher binds tighter), 0 if it is not one.
int binaryPrec(TokenKind k, BinaryOp* op) {
    switch (k) {
    case TokenKind::OrOr:
        *op = BinaryOp::Or;
        return 1;
    case TokenKind::AndAnd:
        *op = BinaryOp::And;
        return 2;
    case TokenKind::EqEq:
        *op = BinaryOp::Eq;
        return 3;
    case TokenKind::NotEq:
        *op = BinaryOp::Ne;
        return 3;
    case TokenKind::Less:
        *op = BinaryOp::Lt;
        return 4;
    case TokenKind::Greater:
        *op = BinaryOp::Gt;
        return 4;
    case TokenKind::LessEq:
        *op = BinaryOp::Le;
        return 4;
    case TokenKind::GreaterEq:
        *op = BinaryOp::Ge;
        return 4;
    case TokenKind::Plus:
        *op = BinaryOp::Add;
        return 5;
    case TokenKind::Minus:
        *op = BinaryOp::Sub;
        return 5;
    case TokenKind::Star:
        *op = BinaryOp::Mul;
        return 6;
    case TokenKind::Slash:
        *op = BinaryOp::Div;
        return 6;
    case TokenKind::Percent:
        *op = BinaryOp::Mod;
        return 6;
    default:
        return 0;
    }
}

} // namespace

void Parser::advance() {
    if (mTok.kind != TokenKind::End) mPrevEnd = mTok.span.end;
    if (mTok.kind == TokenKind::Error) ++mErrorEvents; // the lexer reported it
    if (mAbort) {
        setEnd();
        return;
    }
    if (mHasPeek) {
        mTok = std::move(mPeek);
        mHasPeek = false;
    } else {
        mTok = mLexer.next();
    }
    if (mSink.errorCount() > DiagnosticSink::kMaxErrors) {
        mAbort = true; // the sink stopped listening: stop parsing too
        setEnd();
        return;
    }
}

void Parser::setEnd() {
    mHasPeek = false;
    mTok = Token{};
    uint32_t n = static_cast<uint32_t>(mFile.text().size());
    mTok.span = {n, n};
}

const Token& Parser::peek() {
    if (!mHasPeek) {
        if (mAbort || mTok.kind == TokenKind::End) {
            mPeek = Token{};
            mPeek.span = mTok.span;
        } else {
            mPeek = mLexer.next();
        }
        mHasPeek = true;
    }
    return mPeek;
}

std::string Parser::spelling(const Token& t) const {
    std::string s = mFile.text().substr(t.span.begin, t.span.size() > 24 ? 24 : t.span.size());
    if (t.span.size() > 24) s += "...";
    return s;
}

std::string Parser::describe(const Token& t) const {
    switch (t.kind) {
    case TokenKind::End:
        return "end of input";
    case TokenKind::Number:
        return "number '" + spelling(t) + "'";
    case TokenKind::String:
        return "string " + spelling(t);
    case TokenKind::Name:
    case TokenKind::Variable:
        return "'" + spelling(t) + "'";
    default:
        return tokenKindName(t.kind);
    }
}

bool Parser::error(Span span, std::string msg) {
    ++mErrorEvents;
    if (mAbort) return false;
    mSink.error(span, std::move(msg));
    return true;
}

bool Parser::errorFound(std::string msg) {
    if (at(TokenKind::Error)) {
        ++mErrorEvents;
        return false;
    }
    return error(foundSpan(), std::move(msg));
}

void Parser::missingCloser(TokenKind closer, Span open, size_t before) {
    if (before != mErrorEvents) return;
    TokenKind opener = closer == TokenKind::RParen     ? TokenKind::LParen
                       : closer == TokenKind::RBracket ? TokenKind::LBracket
                                                       : TokenKind::LBrace;
    std::string msg = std::string("expected ") + tokenKindName(closer) + " to close " +
                      tokenKindName(opener) + " at " + where(open) + ", found " + describe(mTok);
    if (at(TokenKind::Assign)) msg += " (use '==' to compare)";
    if (errorFound(std::move(msg)))
        mSink.note(open, std::string("to match this ") + tokenKindName(opener));
}

void Parser::skipExpression() {
    size_t balance = 0;
    while (!at(TokenKind::End)) {
        switch (mTok.kind) {
        case TokenKind::LParen:
        case TokenKind::LBracket:
        case TokenKind::LBrace:
            ++balance;
            break;
        case TokenKind::RParen:
        case TokenKind::RBracket:
        case TokenKind::RBrace:
            if (balance == 0) return;
            --balance;
            break;
        case TokenKind::Comma:
        case TokenKind::Semicolon:
            if (balance == 0) return;
            break;
        default:
            break;
        }
        advance();
    }
}

void Parser::skipBraces() {
    size_t balance = 0;
    while (!at(TokenKind::End)) {
        if (at(TokenKind::LBrace)) ++balance;
        if (at(TokenKind::RBrace) && --balance == 0) {
            advance();
            return;
        }
        advance();
    }
}

void Parser::syncStatement() {
    size_t depth = 0;
    while (!at(TokenKind::End)) {
        if (at(TokenKind::LBrace)) {
            ++depth;
        } else if (at(TokenKind::RBrace)) {
            if (depth == 0) return;
            advance();
            if (--depth == 0) return;
            continue;
        } else if (at(TokenKind::Semicolon) && depth == 0) {
            advance();
            return;
        }
        advance();
    }
}

void Parser::countNode() {
    if (++mNodes > mLimits.maxNodes && !mAbort) {
        error(mTok.span,
              "program too large: more than " + std::to_string(mLimits.maxNodes) + " syntax nodes");
        mAbort = true;
        setEnd();
    }
}

P Parser::errorExpr(Span span) {
    Expr* e = newExpr(ExprKind::Number, span);
    e->text = "<error>";
    return {e, 1};
}

P Parser::finish(Expr* e, uint32_t childDepth) {
    uint32_t depth = childDepth + 1;
    if (depth <= mLimits.maxTreeDepth) return {e, depth};
    if (!mLimitReported) {
        mLimitReported = true;
        error(e->span, "expression too complex: its syntax tree is deeper than " +
                           std::to_string(mLimits.maxTreeDepth) +
                           " levels; split it with intermediate variables");
    } else {
        ++mErrorEvents;
    }
    skipExpression();
    return errorExpr(e->span);
}

P Parser::tooDeep(Span at) {
    if (!mLimitReported) {
        mLimitReported = true;
        error(at,
              "expression nested too deeply (limit " + std::to_string(mLimits.maxNesting) + ")");
    } else {
        ++mErrorEvents;
    }
    skipExpression();
    return errorExpr(at);
}

P Parser::binary(BinaryOp op, P l, P r) {
    Expr* e = newExpr(ExprKind::Binary, Span::merge(l.e->span, r.e->span));
    e->binaryOp = op;
    e->args = {l.e, r.e};
    return finish(e, l.depth > r.depth ? l.depth : r.depth);
}

P Parser::parsePipe() {
    P lhs = parseTernary();
    while (at(TokenKind::Arrow)) {
        advance();
        if (at(TokenKind::Name) && peek().kind == TokenKind::LParen) {
            lhs = parseCall(&lhs);
            continue;
        }
        if (at(TokenKind::Variable) && peek().kind == TokenKind::LParen) {
            variableCalled();
            P call = parseCall(&lhs);
            lhs = errorExpr(call.e->span);
            continue;
        }
        errorFound("expected a function call after '->' (e.g. `$P -> noise()`), found " +
                   describe(mTok));
        if (canStartExpression())
            parseTernary(); // consume the operand so it causes no further errors
        lhs = errorExpr(Span{lhs.e->span.begin, mPrevEnd});
    }
    return lhs;
}

bool Parser::canStartExpression() const {
    switch (mTok.kind) {
    case TokenKind::Number:
    case TokenKind::String:
    case TokenKind::Name:
    case TokenKind::Variable:
    case TokenKind::LParen:
    case TokenKind::LBracket:
    case TokenKind::Minus:
    case TokenKind::Plus:
    case TokenKind::Bang:
    case TokenKind::Tilde:
    case TokenKind::Error:
        return true;
    default:
        return false;
    }
}

P Parser::parseTernary() {
    P cond = parseBinary(1);
    if (!at(TokenKind::Question)) return cond;
    Span q = mTok.span;
    Nest nest(*this);
    if (!nest.ok) return tooDeep(q);
    advance();
    size_t before = mErrorEvents;
    P a = parsePipe();
    if (!at(TokenKind::Colon)) {
        if (before == mErrorEvents &&
            errorFound("expected ':' in the conditional expression, found " + describe(mTok)))
            mSink.note(q, "the conditional's '?' is here");
        return errorExpr(Span{cond.e->span.begin, mPrevEnd});
    }
    advance();
    P b = parseTernary();
    Expr* e = newExpr(ExprKind::Ternary, Span::merge(cond.e->span, b.e->span));
    e->args = {cond.e, a.e, b.e};
    uint32_t d = cond.depth > a.depth ? cond.depth : a.depth;
    return finish(e, d > b.depth ? d : b.depth);
}

P Parser::parseBinary(int minPrec) {
    P lhs = parseUnary();
    for (;;) {
        BinaryOp op = BinaryOp::Add;
        int prec = binaryPrec(mTok.kind, &op);
        if (prec == 0 || prec < minPrec) return lhs;
        advance();
        P rhs = parseBinary(prec + 1);
        lhs = binary(op, lhs, rhs);
    }
}

P Parser::parseUnary() {
    UnaryOp op;
    switch (mTok.kind) {
    case TokenKind::Minus:
        op = UnaryOp::Neg;
        break;
    case TokenKind::Plus:
        op = UnaryOp::Plus;
        break;
    case TokenKind::Bang:
        op = UnaryOp::Not;
        break;
    case TokenKind::Tilde:
        op = UnaryOp::Invert;
        break;
    default:
        return parsePow();
    }
    Span opSpan = mTok.span;
    Nest nest(*this);
    if (!nest.ok) return tooDeep(opSpan);
    advance();
    P operand = parseUnary();
    Expr* e = newExpr(ExprKind::Unary, Span::merge(opSpan, operand.e->span));
    e->unaryOp = op;
    e->args = {operand.e};
    return finish(e, operand.depth);
}

P Parser::parsePow() {
    P base = parsePostfix();
    if (!at(TokenKind::Caret)) return base;
    Nest nest(*this);
    if (!nest.ok) return tooDeep(mTok.span);
    advance();
    P exponent = parseUnary();
    return binary(BinaryOp::Pow, base, exponent);
}

P Parser::parsePostfix() {
    P e = parsePrimary();
    while (at(TokenKind::LBracket)) {
        Span open = mTok.span;
        Nest nest(*this);
        if (!nest.ok) return tooDeep(open);
        advance();
        size_t before = mErrorEvents;
        P index = parsePipe();
        if (at(TokenKind::RBracket))
            advance();
        else
            missingCloser(TokenKind::RBracket, open, before);
        Expr* ix = newExpr(ExprKind::Index, Span{e.e->span.begin, mPrevEnd});
        ix->args = {e.e, index.e};
        e = finish(ix, e.depth > index.depth ? e.depth : index.depth);
    }
    return e;
}

P Parser::parseCall(P* piped) {
    Span nameSpan = mTok.span;
    std::string name = mTok.text;
    advance();
    Span open = mTok.span;
    Nest nest(*this);
    if (!nest.ok) return tooDeep(open);
    advance(); // '('
    uint32_t begin = piped ? piped->e->span.begin : nameSpan.begin;
    Expr* call = newExpr(ExprKind::Call, Span{begin, begin});
    call->text = std::move(name);
    call->nameSpan = nameSpan;
    uint32_t depth = 0;
    if (piped) {
        call->piped = true;
        call->args.push_back(piped->e);
        depth = piped->depth;
    }
    size_t before = mErrorEvents;
    if (!at(TokenKind::RParen)) {
        for (;;) {
            P arg = parsePipe();
            call->args.push_back(arg.e);
            if (arg.depth > depth) depth = arg.depth;
            if (at(TokenKind::Comma)) {
                advance();
                continue;
            }
            break;
        }
    }
    if (at(TokenKind::RParen))
        advance();
    else
        missingCloser(TokenKind::RParen, open, before);
    call->span.end = mPrevEnd;
    return finish(call, depth);
}

P Parser::parsePrimary() {
    switch (mTok.kind) {
    case TokenKind::Number: {
        Expr* e = newExpr(ExprKind::Number, mTok.span);
        e->number = mTok.number;
        advance();
        return {e, 1};
    }
    case TokenKind::String: {
        Expr* e = newExpr(ExprKind::String, mTok.span);
        e->text = std::move(mTok.text);
        advance();
        return {e, 1};
    }
    case TokenKind::Name:
        if (peek().kind == TokenKind::LParen) return parseCall(nullptr);
        return variable(false);
    case TokenKind::Variable:
        if (peek().kind == TokenKind::LParen) {
            variableCalled();
            P call = parseCall(nullptr);
            return errorExpr(call.e->span);
        }
        return variable(true);
    case TokenKind::LParen: {
        Span open = mTok.span;
        Nest nest(*this);
        if (!nest.ok) return tooDeep(open);
        advance();
        size_t before = mErrorEvents;
        P inner = parsePipe();
        if (at(TokenKind::RParen)) {
            advance();
            inner.e->span = Span::merge(inner.e->span, Span{open.begin, mPrevEnd});
        } else {
            missingCloser(TokenKind::RParen, open, before);
        }
        return inner;
    }
    case TokenKind::LBracket:
        return parseVector();
    case TokenKind::Error: {
        P e = errorExpr(mTok.span); // the lexer reported it
        advance();
        return e;
    }
    case TokenKind::KwIf:
        errorFound("'if' is a statement and cannot be used inside an expression "
                   "(use `cond ? a : b`)");
        return errorExpr(foundSpan());
    default:
        errorFound("expected an expression, found " + describe(mTok));
        return errorExpr(foundSpan());
    }
}

P Parser::variable(bool dollar) {
    Expr* e = newExpr(ExprKind::Variable, mTok.span);
    e->nameSpan = mTok.span;
    e->dollar = dollar;
    e->text = std::move(mTok.text);
    if (isReservedWord(e->text))
        error(e->span, "'" + e->text + "' is a reserved word and cannot be used as a variable");
    advance();
    return {e, 1};
}

P Parser::parseVector() {
    Span open = mTok.span;
    Nest nest(*this);
    if (!nest.ok) return tooDeep(open);
    advance();
    if (at(TokenKind::RBracket)) {
        advance();
        Span s{open.begin, mPrevEnd};
        error(s, "empty vector literal: a vector needs at least one component, e.g. [0, 0, 0]");
        return errorExpr(s);
    }
    Expr* v = newExpr(ExprKind::Vector, open);
    uint32_t depth = 0;
    size_t before = mErrorEvents;
    for (;;) {
        P elem = parsePipe();
        v->args.push_back(elem.e);
        if (elem.depth > depth) depth = elem.depth;
        if (at(TokenKind::Comma)) {
            advance();
            continue;
        }
        break;
    }
    if (at(TokenKind::RBracket))
        advance();
    else
        missingCloser(TokenKind::RBracket, open, before);
    v->span.end = mPrevEnd;
    return finish(v, depth);
}

} // namespace parser_detail

std::unique_ptr<Ast> parseProgram(const SourceFile& file, DiagnosticSink& sink,
                                  const ParseLimits& limits) {
    auto ast = std::make_unique<Ast>();
    if (file.text().size() > limits.maxSourceBytes) {
        sink.error(Span{0, 0}, "source too large: " + std::to_string(file.text().size()) +
                                   " bytes (the limit is " + std::to_string(limits.maxSourceBytes) +
                                   ")");
        return ast;
    }
    parser_detail::Parser parser(file, sink, limits, *ast);
    parser.run();
    return ast;
}

} // namespace gale::lang
