// Internals of the parser, shared by parser.cpp (tokens, errors, limits, expressions) and
// parser_statements.cpp (statements, blocks, bodies and defs). Not part of the public API.
#pragma once

#include "lang/lexer.h"
#include "lang/parser.h"

#include <string>
#include <string_view>
#include <vector>

namespace gale::lang::parser_detail {

// An expression and the depth of its tree (a leaf has depth 1).
struct P {
    Expr* e = nullptr;
    uint32_t depth = 1;
};

inline bool isAssignOp(TokenKind k) {
    switch (k) {
    case TokenKind::Assign:
    case TokenKind::PlusAssign:
    case TokenKind::MinusAssign:
    case TokenKind::StarAssign:
    case TokenKind::SlashAssign:
    case TokenKind::PercentAssign:
    case TokenKind::CaretAssign:
        return true;
    default:
        return false;
    }
}

inline bool isKeyword(TokenKind k) {
    return k == TokenKind::KwIf || k == TokenKind::KwElse || k == TokenKind::KwDef ||
           k == TokenKind::KwExtern;
}

class Parser {
public:
    Parser(const SourceFile& file, DiagnosticSink& sink, const ParseLimits& limits, Ast& ast)
        : mFile(file), mSink(sink), mLimits(limits), mAst(ast), mLexer(file, sink) {
        advance();
    }

    void run() {
        Expr* result = parseBody(mAst.statements, nullptr, Span{});
        mAst.result = mAbort ? nullptr : result;
    }

private:
    // RAII nesting counter: `ok` is false once the nesting limit is exceeded.
    struct Nest {
        explicit Nest(Parser& p) : parser(p) { ok = ++p.mNesting <= p.mLimits.maxNesting; }
        ~Nest() { --parser.mNesting; }
        Parser& parser;
        bool ok;
    };

    // ---- Tokens -------------------------------------------------------------------------

    void advance();
    void setEnd();
    const Token& peek();
    bool at(TokenKind k) const { return mTok.kind == k; }

    Span endOfPrev() const { return {mPrevEnd, mPrevEnd}; }
    // Where a diagnostic about the current token points: the token, or just after the last
    // real token when the input has ended.
    Span foundSpan() const { return at(TokenKind::End) ? endOfPrev() : mTok.span; }

    std::string where(Span s) const {
        LineCol lc = mFile.lineCol(s.begin);
        return std::to_string(lc.line) + ":" + std::to_string(lc.col);
    }

    std::string spelling(const Token& t) const;
    std::string describe(const Token& t) const;
    bool onLaterLine(uint32_t a, uint32_t b) const {
        return mFile.lineCol(b).line > mFile.lineCol(a).line;
    }

    // ---- Errors -------------------------------------------------------------------------

    // Records an error; returns false when it was suppressed (after a fatal limit).
    bool error(Span span, std::string msg);

    // An error about the current token. An invalid token already has its diagnostic.
    bool errorFound(std::string msg);

    // `expected ')' to close '(' at 3:5, found ';'` plus a note at the opener — unless an
    // error inside the group (counted since `before`) already explains the mismatch.
    void missingCloser(TokenKind closer, Span open, size_t before);

    // Skips the rest of an expression: up to a ')' ']' '}' ',' or ';' outside any group.
    void skipExpression();

    // Skips a '{ ... }' group starting at the current '{', braces balanced.
    void skipBraces();

    // Statement recovery: skip past the next ';', or past a '{...}' block, or up to a '}'
    // that closes the enclosing block.
    void syncStatement();

    // ---- Nodes --------------------------------------------------------------------------

    Expr* newExpr(ExprKind kind, Span span) {
        countNode();
        return mAst.newExpr(kind, span);
    }

    Stmt* newStmt(StmtKind kind, Span span) {
        countNode();
        return mAst.newStmt(kind, span);
    }

    void countNode();

    // Error expressions are Number nodes with text "<error>"; a diagnostic always exists.
    P errorExpr(Span span);

    // Checks the tree-depth limit for a node just built from children of depth `childDepth`.
    P finish(Expr* e, uint32_t childDepth);

    // Reports the nesting limit (once per parse, like the depth limit: the two explain each
    // other) and skips the over-deep expression.
    P tooDeep(Span at);
    P binary(BinaryOp op, P l, P r);

    // ---- Expressions --------------------------------------------------------------------

    // expr := ternary { '->' name '(' args ')' }
    P parsePipe();
    bool canStartExpression() const;

    // ternary := binary [ '?' expr ':' ternary ]
    P parseTernary();

    // Left-associative binary operators by precedence climbing (levels 3..8 of the spec).
    P parseBinary(int minPrec);

    // unary := ('-' | '+' | '!' | '~') unary | power
    P parseUnary();

    // power := postfix [ '^' unary ]   (right-associative; `2^-1` works)
    P parsePow();

    // postfix := primary { '[' expr ']' }
    P parsePostfix();

    // name '(' args ')' at the current Name; `piped` is the left side of `->`, if any.
    P parseCall(P* piped);
    P parsePrimary();
    void variableCalled() {
        error(mTok.span,
              "'" + spelling(mTok) + "' is a variable, not a function: call functions without '$'");
    }

    P variable(bool dollar);

    // '[' expr { ',' expr } ']'
    P parseVector();

    // ---- Statements ---------------------------------------------------------------------

    bool atAssignment() {
        return (at(TokenKind::Name) || at(TokenKind::Variable)) && isAssignOp(peek().kind);
    }

    // name op= expr ';'
    Stmt* parseAssign();

    // if '(' expr ')' block { else if '(' expr ')' block } [ else block ]; built iteratively.
    // Nesting is bounded by the blocks (parseBlock), chain length by maxTreeDepth.
    Stmt* parseIf();

    // 'if' '(' cond ')' block, at the current 'if'.
    Stmt* parseIfHead();

    // '{' { statement } '}' — a branch holds statements only.
    void parseBlock(std::vector<Stmt*>& out, const char* what);

    // Parses a statement, or reports and skips a misplaced def/extern/else/reserved word.
    // Returns false (consuming nothing) when the current token starts an expression instead.
    bool parseStatementLike(std::vector<Stmt*>& out, bool nested);

    // { statement } expr, up to the end of input (program, `def` = nullptr) or to the '}' of
    // a function body. Returns the final expression (null when missing).
    Expr* parseBody(std::vector<Stmt*>& stmts, FunctionDef* def, Span open);

    // A ')' or ']' that closes nothing.
    void strayCloser();

    // Something follows what should have been the final expression.
    void reportTrailing(bool inDef);

    // ---- Definitions --------------------------------------------------------------------

    bool atTypeAnnotation();

    // FLOAT | FLOAT[n] | STRING, then an optional lifetime word (any case).
    TypeAnnotation parseType();

    // Recovery for a broken def header: skip to its body and over it.
    void skipDef();

    // def [TYPE] name '(' [ [TYPE] name { ',' [TYPE] name } ] ')' '{' body '}'
    FunctionDef* parseDef();

    // '(' params ')' at the current '('.
    void parseParams(FunctionDef& d);
    const SourceFile& mFile;
    DiagnosticSink& mSink;
    const ParseLimits& mLimits;
    Ast& mAst;
    Lexer mLexer;
    Token mTok;
    Token mPeek;
    bool mHasPeek = false;
    uint32_t mPrevEnd = 0;
    size_t mErrorEvents = 0; // errors reported, suppressed, or lexed: for cascade suppression
    uint32_t mNesting = 0;
    size_t mNodes = 0;
    bool mAbort = false;
    bool mLimitReported = false; // nesting or tree depth: reported once per parse
};

} // namespace gale::lang::parser_detail
