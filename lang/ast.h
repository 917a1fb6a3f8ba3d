// Abstract syntax tree with source spans. Nodes live in an arena owned by Ast, so trees of any
// shape are freed without recursion; children are plain pointers into the arena.
#pragma once

#include "lang/source.h"
#include "lang/types.h"

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace gale::lang {

enum class UnaryOp : uint8_t { Neg, Plus, Not, Invert };
enum class BinaryOp : uint8_t { Add, Sub, Mul, Div, Mod, Pow, Lt, Gt, Le, Ge, Eq, Ne, And, Or };

const char* unaryOpText(UnaryOp op);
const char* binaryOpText(BinaryOp op);

enum class ExprKind : uint8_t {
    Number,   // number
    String,   // text
    Variable, // text = name (no '$'), dollar = written with '$'
    Vector,   // [args...]
    Unary,    // unaryOp args[0]
    Binary,   // args[0] binaryOp args[1]
    Ternary,  // args[0] ? args[1] : args[2]
    Call,     // text(args...); pipe `a -> f(b)` is parsed as f(a, b) with piped = true
    Index,    // args[0][args[1]]
};

struct Expr {
    ExprKind kind = ExprKind::Number;
    Span span;
    Span nameSpan; // Variable / Call: the name
    double number = 0.0;
    std::string text;
    bool dollar = false;
    bool piped = false;
    UnaryOp unaryOp = UnaryOp::Neg;
    BinaryOp binaryOp = BinaryOp::Add;
    std::vector<Expr*> args;
};

enum class StmtKind : uint8_t { Assign, If };

struct Stmt {
    StmtKind kind = StmtKind::Assign;
    Span span;
    // Assign: name op= value (compound ops carry the BinaryOp; plain `=` has compound = false).
    std::string name;
    Span nameSpan;
    bool dollar = false;
    bool compound = false;
    BinaryOp compoundOp = BinaryOp::Add;
    Expr* value = nullptr;
    // If: if (cond) { thenBody } else { elseBody }; `else if` is an If alone in elseBody.
    Expr* cond = nullptr;
    std::vector<Stmt*> thenBody;
    std::vector<Stmt*> elseBody;
    bool hasElse = false;
    Span elseSpan;
};

// A written type: FLOAT, FLOAT[n], STRING, with an optional lifetime word.
struct TypeAnnotation {
    Span span;
    Type type;
    bool hasLifetime = false;
};

struct Param {
    std::string name;
    Span span;
    std::optional<TypeAnnotation> type;
};

struct FunctionDef {
    std::string name;
    Span span;     // whole definition
    Span nameSpan;
    std::optional<TypeAnnotation> returnType;
    std::vector<Param> params;
    std::vector<Stmt*> body;
    Expr* result = nullptr;
};

class Ast {
public:
    Expr* newExpr(ExprKind kind, Span span);
    Stmt* newStmt(StmtKind kind, Span span);
    FunctionDef* newDef();

    std::vector<FunctionDef*> defs;
    std::vector<Stmt*> statements;
    Expr* result = nullptr; // null only when parsing failed before the final expression

private:
    std::deque<Expr> mExprs;
    std::deque<Stmt> mStmts;
    std::deque<FunctionDef> mDefs;
};

} // namespace gale::lang
