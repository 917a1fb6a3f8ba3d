// Parser, statement level: program and function bodies ({ statement } expr), assignments,
// if/else-if chains (built iteratively), blocks, and defs with SeExpr-style type annotations.
// Recovery skips to ';' or '}' so one pass reports every independent error.
#include "lang/parser_impl.h"

#include <cmath>

namespace gale::lang::parser_detail {

namespace {

BinaryOp compoundOp(TokenKind k) {
    switch (k) {
    case TokenKind::MinusAssign:
        return BinaryOp::Sub;
    case TokenKind::StarAssign:
        return BinaryOp::Mul;
    case TokenKind::SlashAssign:
        return BinaryOp::Div;
    case TokenKind::PercentAssign:
        return BinaryOp::Mod;
    case TokenKind::CaretAssign:
        return BinaryOp::Pow;
    default:
        return BinaryOp::Add;
    }
}

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i) {
        char x = a[i], y = b[i];
        if (x >= 'a' && x <= 'z') x = static_cast<char>(x - 32);
        if (y >= 'a' && y <= 'z') y = static_cast<char>(y - 32);
        if (x != y) return false;
    }
    return true;
}

bool isTypeWord(std::string_view s) {
    return equalsIgnoreCase(s, "FLOAT") || equalsIgnoreCase(s, "STRING");
}

bool lifetimeWord(std::string_view s, Lifetime* l) {
    if (equalsIgnoreCase(s, "CONSTANT"))
        *l = Lifetime::Constant;
    else if (equalsIgnoreCase(s, "UNIFORM"))
        *l = Lifetime::Uniform;
    else if (equalsIgnoreCase(s, "VARYING"))
        *l = Lifetime::Varying;
    else
        return false;
    return true;
}

} // namespace

Stmt* Parser::parseAssign() {
    Span nameSpan = mTok.span;
    bool dollar = at(TokenKind::Variable);
    std::string name = std::move(mTok.text);
    advance();
    TokenKind op = mTok.kind;
    advance();
    size_t before = mErrorEvents;
    if (isReservedWord(name))
        error(nameSpan, "'" + name + "' is a reserved word and cannot be used as a variable");
    P value = parsePipe();
    Stmt* s = newStmt(StmtKind::Assign, Span{nameSpan.begin, mPrevEnd});
    s->name = std::move(name);
    s->nameSpan = nameSpan;
    s->dollar = dollar;
    s->compound = op != TokenKind::Assign;
    s->compoundOp = compoundOp(op);
    s->value = value.e;
    if (at(TokenKind::Semicolon)) {
        advance();
        s->span.end = mPrevEnd;
    } else if (before != mErrorEvents || at(TokenKind::Error)) {
        // Already explained. Resynchronise, but keep a statement that starts a new line.
        bool nextLine = onLaterLine(mPrevEnd, mTok.span.begin);
        if (!(nextLine && (atAssignment() || at(TokenKind::KwIf)))) syncStatement();
    } else if (at(TokenKind::RParen) || at(TokenKind::RBracket)) {
        strayCloser();
        syncStatement();
    } else {
        bool reported = error(endOfPrev(), "expected ';' after the assignment");
        if (at(TokenKind::End)) {
            if (reported)
                mSink.note("a program ends with the expression that is its value, e.g. `" +
                           s->name + "`");
        } else if (!onLaterLine(mPrevEnd, mTok.span.begin)) {
            syncStatement(); // on a new line we assume only the ';' was forgotten
        }
    }
    return s;
}

Stmt* Parser::parseIf() {
    std::vector<Stmt*> chain;
    Stmt* first = parseIfHead();
    chain.push_back(first);
    Stmt* cur = first;
    while (at(TokenKind::KwElse)) {
        cur->hasElse = true;
        cur->elseSpan = mTok.span;
        advance();
        if (at(TokenKind::KwIf)) {
            if (chain.size() >= mLimits.maxTreeDepth) {
                // Consumers walk else-if chains recursively: bound them like tree depth.
                if (!mLimitReported) {
                    mLimitReported = true;
                    error(mTok.span, "too many 'else if' branches in one chain (limit " +
                                         std::to_string(mLimits.maxTreeDepth) + ")");
                } else {
                    ++mErrorEvents;
                }
                for (;;) { // skip the rest of the chain
                    syncStatement();
                    if (!at(TokenKind::KwElse)) break;
                    advance();
                }
                break;
            }
            Stmt* next = parseIfHead();
            cur->elseBody.push_back(next);
            chain.push_back(next);
            cur = next;
            continue;
        }
        parseBlock(cur->elseBody, "else");
        break;
    }
    for (Stmt* s : chain) s->span.end = mPrevEnd;
    return first;
}

Stmt* Parser::parseIfHead() {
    Span ifSpan = mTok.span;
    advance();
    Stmt* s = newStmt(StmtKind::If, ifSpan);
    size_t before = mErrorEvents;
    bool paren = at(TokenKind::LParen);
    Span open = mTok.span;
    if (paren)
        advance();
    else
        errorFound("expected '(' after 'if', found " + describe(mTok));
    s->cond = paren || canStartExpression() ? parsePipe().e : errorExpr(foundSpan()).e;
    if (paren) {
        if (at(TokenKind::RParen))
            advance();
        else
            missingCloser(TokenKind::RParen, open, before);
    }
    parseBlock(s->thenBody, "if");
    s->span.end = mPrevEnd;
    return s;
}

void Parser::parseBlock(std::vector<Stmt*>& out, const char* what) {
    if (!at(TokenKind::LBrace)) {
        errorFound(std::string("expected '{' to start the '") + what + "' branch, found " +
                   describe(mTok));
        syncStatement();
        return;
    }
    Span open = mTok.span;
    Nest nest(*this);
    if (!nest.ok) {
        tooDeep(open);
        skipBraces();
        return;
    }
    advance();
    size_t before = mErrorEvents;
    for (;;) {
        if (mAbort) return;
        if (at(TokenKind::RBrace)) {
            advance();
            return;
        }
        if (at(TokenKind::End) || at(TokenKind::KwElse)) {
            // `if (c) { x = 1; else { ... }`: the '}' before 'else' was forgotten.
            missingCloser(TokenKind::RBrace, open, before);
            return;
        }
        uint32_t pos = mTok.span.begin;
        if (!parseStatementLike(out, true)) {
            // An expression in a branch.
            size_t b = mErrorEvents;
            P e = parsePipe();
            if (b == mErrorEvents)
                error(e.e->span, "a branch holds statements only: assign the value, e.g. "
                                 "`x = ...;` (only the last line of a program is an "
                                 "expression)");
            if (at(TokenKind::Semicolon))
                advance();
            else if (!at(TokenKind::RBrace))
                syncStatement();
        }
        if (mTok.span.begin == pos && !at(TokenKind::End) && !at(TokenKind::RBrace))
            advance(); // guarantee progress
    }
}

bool Parser::parseStatementLike(std::vector<Stmt*>& out, bool nested) {
    if (at(TokenKind::Semicolon)) {
        error(mTok.span, "unexpected ';': there is no statement before it");
        advance();
        return true;
    }
    if (isKeyword(mTok.kind) && isAssignOp(peek().kind)) {
        error(mTok.span, describe(mTok) + " is a reserved word and cannot be used as a variable");
        syncStatement();
        return true;
    }
    switch (mTok.kind) {
    case TokenKind::KwIf:
        out.push_back(parseIf());
        return true;
    case TokenKind::KwDef:
        error(mTok.span, nested ? "a 'def' cannot appear inside a block or function body"
                                : "'def' must come before all statements");
        if (FunctionDef* d = parseDef(); d && !nested) mAst.defs.push_back(d);
        return true;
    case TokenKind::KwExtern:
        error(mTok.span, "'extern' declarations are not supported");
        syncStatement();
        return true;
    case TokenKind::KwElse:
        error(mTok.span, "'else' without a matching 'if'");
        advance();
        if (at(TokenKind::LBrace)) skipBraces();
        return true;
    default:
        break;
    }
    if (atAssignment()) {
        out.push_back(parseAssign());
        return true;
    }
    return false;
}

Expr* Parser::parseBody(std::vector<Stmt*>& stmts, FunctionDef* def, Span open) {
    const TokenKind terminator = def ? TokenKind::RBrace : TokenKind::End;
    bool seenStatement = false;
    bool lastHadErrors = false;
    bool sawAnything = !at(TokenKind::End) || mErrorEvents != 0;
    Expr* result = nullptr;
    Expr* candidate = nullptr;
    while (!mAbort && !at(TokenKind::End) && !at(terminator)) {
        size_t before = mErrorEvents;
        uint32_t pos = mTok.span.begin;
        if (!def && at(TokenKind::KwDef) && !seenStatement && !candidate) {
            if (FunctionDef* d = parseDef()) mAst.defs.push_back(d);
        } else if (!def && at(TokenKind::RBrace)) {
            error(mTok.span, "unexpected '}' with no matching '{'");
            advance();
        } else if (parseStatementLike(stmts, def != nullptr)) {
            seenStatement = true;
        } else {
            P e = parsePipe();
            if (at(terminator) || (def && at(TokenKind::End))) {
                result = e.e;
                lastHadErrors = before != mErrorEvents;
                break;
            }
            if (before == mErrorEvents) reportTrailing(def != nullptr);
            if (!candidate) candidate = e.e;
            syncStatement();
        }
        lastHadErrors = before != mErrorEvents;
        if (mTok.span.begin == pos && !at(TokenKind::End) && !at(terminator)) advance();
    }
    if (!result) result = candidate;
    if (result || mAbort || lastHadErrors) return result;
    if (def) {
        if (error(at(TokenKind::RBrace) ? mTok.span : endOfPrev(),
                  "expected an expression: a function body ends with the expression that "
                  "is its value"))
            mSink.note(open, "the body of '" + def->name + "' starts here");
    } else if (!sawAnything) {
        error(Span{0, 0}, "empty program: write an expression, e.g. `$P`");
    } else {
        error(endOfPrev(),
              "expected an expression: a program ends with the expression that is its value");
    }
    return nullptr;
}

void Parser::strayCloser() {
    const char* opener = at(TokenKind::RParen) ? "'('" : "'['";
    errorFound(std::string("unmatched ") + tokenKindName(mTok.kind) + ": there is no " + opener +
               " for it to close");
}

void Parser::reportTrailing(bool inDef) {
    std::string msg;
    if (at(TokenKind::RParen) || at(TokenKind::RBracket)) {
        strayCloser();
        return;
    }
    if (at(TokenKind::Semicolon)) {
        TokenKind after = peek().kind;
        if (after == (inDef ? TokenKind::RBrace : TokenKind::End)) {
            msg = std::string("unexpected ';' after the final expression: the last line of ") +
                  (inDef ? "a function body" : "a program") + " is its value, without ';'";
        } else {
            msg = "unexpected ';' after an expression: only assignments (`name = value;`) "
                  "and 'if' are statements; the value is the last line, without ';'";
        }
    } else if (isAssignOp(mTok.kind)) {
        msg = "cannot assign to this expression: only a plain name can be assigned "
              "(`name = value;`)";
    } else {
        msg = "unexpected " + describe(mTok) + " after the expression: expected an operator" +
              (inDef ? " or '}'" : " or the end of the program");
    }
    errorFound(std::move(msg));
}

bool Parser::atTypeAnnotation() {
    if (!at(TokenKind::Name) || !isTypeWord(mTok.text)) return false;
    TokenKind k = peek().kind;
    return k == TokenKind::Name || k == TokenKind::LBracket;
}

TypeAnnotation Parser::parseType() {
    TypeAnnotation t;
    t.span = mTok.span;
    bool isFloat = equalsIgnoreCase(mTok.text, "FLOAT");
    advance();
    int width = 1;
    if (at(TokenKind::LBracket)) {
        Span open = mTok.span;
        advance();
        size_t before = mErrorEvents;
        if (!isFloat) error(open, "STRING has no width: write STRING, not STRING[n]");
        if (at(TokenKind::Number)) {
            double v = mTok.number;
            if (v != std::floor(v) || v < 1 || v > kMaxWidth)
                error(mTok.span, "vector width must be an integer from 1 to 16, found '" +
                                     spelling(mTok) + "'");
            else
                width = static_cast<int>(v);
            advance();
        } else {
            errorFound("expected a vector width (1 to 16), found " + describe(mTok));
        }
        if (at(TokenKind::RBracket))
            advance();
        else
            missingCloser(TokenKind::RBracket, open, before);
    }
    Lifetime life = Lifetime::Varying;
    if (at(TokenKind::Name) && lifetimeWord(mTok.text, &life) && peek().kind == TokenKind::Name) {
        t.hasLifetime = true;
        advance();
    }
    t.type =
        isFloat ? Type::fp(width, life) : (t.hasLifetime ? Type::string(life) : Type::string());
    t.span.end = mPrevEnd;
    return t;
}

void Parser::skipDef() {
    while (!at(TokenKind::End) && !at(TokenKind::LBrace) && !at(TokenKind::Semicolon)) advance();
    if (at(TokenKind::LBrace))
        skipBraces();
    else if (at(TokenKind::Semicolon))
        advance();
}

FunctionDef* Parser::parseDef() {
    Span defSpan = mTok.span;
    advance();
    FunctionDef* d = mAst.newDef();
    d->span = defSpan;
    if (atTypeAnnotation()) d->returnType = parseType();
    if (at(TokenKind::Name) || at(TokenKind::Variable)) {
        if (at(TokenKind::Variable)) error(mTok.span, "function names are written without '$'");
        d->name = mTok.text;
        d->nameSpan = mTok.span;
        advance();
    } else {
        if (isKeyword(mTok.kind))
            error(mTok.span, describe(mTok) + " is a reserved word and cannot name a function");
        else
            errorFound("expected a function name after 'def', found " + describe(mTok));
        skipDef();
        d->span.end = mPrevEnd;
        return d;
    }
    if (!at(TokenKind::LParen)) {
        errorFound("expected '(' after the function name '" + d->name + "', found " +
                   describe(mTok));
        skipDef();
        d->span.end = mPrevEnd;
        return d;
    }
    parseParams(*d);
    if (!at(TokenKind::LBrace)) {
        errorFound("expected '{' to start the body of '" + d->name + "', found " + describe(mTok));
        skipDef();
        d->span.end = mPrevEnd;
        return d;
    }
    Span open = mTok.span;
    Nest nest(*this);
    if (!nest.ok) {
        tooDeep(open);
        skipBraces();
        d->span.end = mPrevEnd;
        return d;
    }
    advance();
    size_t before = mErrorEvents;
    d->result = parseBody(d->body, d, open);
    if (at(TokenKind::RBrace))
        advance();
    else if (!mAbort)
        missingCloser(TokenKind::RBrace, open, before);
    d->span.end = mPrevEnd;
    return d;
}

void Parser::parseParams(FunctionDef& d) {
    Span open = mTok.span;
    advance();
    size_t before = mErrorEvents;
    if (at(TokenKind::RParen)) {
        advance();
        return;
    }
    for (;;) {
        Param p;
        if (atTypeAnnotation()) p.type = parseType();
        if (at(TokenKind::Name) || at(TokenKind::Variable)) {
            if (at(TokenKind::Variable))
                error(mTok.span, "parameter names are written without '$'");
            p.name = mTok.text;
            p.span = mTok.span;
            for (const Param& q : d.params)
                if (q.name == p.name) {
                    error(mTok.span, "duplicate parameter '" + p.name + "'");
                    break;
                }
            advance();
            d.params.push_back(std::move(p));
        } else {
            if (isKeyword(mTok.kind))
                error(mTok.span,
                      describe(mTok) + " is a reserved word and cannot name a parameter");
            else
                errorFound("expected a parameter name, found " + describe(mTok));
            while (!at(TokenKind::End) && !at(TokenKind::RParen) && !at(TokenKind::LBrace))
                advance();
            if (at(TokenKind::RParen)) advance();
            return;
        }
        if (at(TokenKind::Comma)) {
            advance();
            continue;
        }
        if (at(TokenKind::RParen)) {
            advance();
            return;
        }
        missingCloser(TokenKind::RParen, open, before);
        while (!at(TokenKind::End) && !at(TokenKind::RParen) && !at(TokenKind::LBrace)) advance();
        if (at(TokenKind::RParen)) advance();
        return;
    }
}

} // namespace gale::lang::parser_detail
