// Arena allocation of syntax nodes and the source spelling of operators.
#include "lang/ast.h"

namespace gale::lang {

const char* unaryOpText(UnaryOp op) {
    switch (op) {
    case UnaryOp::Neg:
        return "-";
    case UnaryOp::Plus:
        return "+";
    case UnaryOp::Not:
        return "!";
    case UnaryOp::Invert:
        return "~";
    }
    return "?";
}

const char* binaryOpText(BinaryOp op) {
    switch (op) {
    case BinaryOp::Add:
        return "+";
    case BinaryOp::Sub:
        return "-";
    case BinaryOp::Mul:
        return "*";
    case BinaryOp::Div:
        return "/";
    case BinaryOp::Mod:
        return "%";
    case BinaryOp::Pow:
        return "^";
    case BinaryOp::Lt:
        return "<";
    case BinaryOp::Gt:
        return ">";
    case BinaryOp::Le:
        return "<=";
    case BinaryOp::Ge:
        return ">=";
    case BinaryOp::Eq:
        return "==";
    case BinaryOp::Ne:
        return "!=";
    case BinaryOp::And:
        return "&&";
    case BinaryOp::Or:
        return "||";
    }
    return "?";
}

Expr* Ast::newExpr(ExprKind kind, Span span) {
    Expr& e = mExprs.emplace_back();
    e.kind = kind;
    e.span = span;
    return &e;
}

Stmt* Ast::newStmt(StmtKind kind, Span span) {
    Stmt& s = mStmts.emplace_back();
    s.kind = kind;
    s.span = span;
    return &s;
}

FunctionDef* Ast::newDef() {
    return &mDefs.emplace_back();
}

} // namespace gale::lang
