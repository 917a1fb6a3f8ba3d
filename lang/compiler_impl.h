// Internals of the compiler, shared by compiler.cpp (diagnostics, registers and emission with
// constant folding, the finishing passes), compiler_expressions.cpp (the type rules of
// expressions and calls, `def` inlining) and compiler_statements.cpp (assignments, if/else and
// the lifetimes of variables across branches). Not part of the public API.
#pragma once

#include "lang/compiler.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

namespace gale::lang::compiler_detail {

struct Value {
    Reg reg = kNoReg;
    Type type = Type::error();
    bool ok() const { return !type.isError(); }
};

// A variable as the compiler knows it at one point of the program.
struct Binding {
    Value value;
    // After if/else: why using it is an error ("" when usable).
    std::string problem;
    std::vector<DiagnosticNote> notes;
    Span assignedAt;
};

using Env = std::map<std::string, Binding>;

struct BuiltinConstant {
    const char* name;
    double value;
};
inline constexpr BuiltinConstant kConstants[] = {
    {"PI", 3.14159265358979323846}, {"E", 2.71828182845904523536}, {"linear", 0},
    {"smooth", 1},                  {"gaussian", 2},               {"box", 3},
};

inline const BuiltinConstant* findConstant(std::string_view name) {
    for (const BuiltinConstant& c : kConstants)
        if (name == c.name) return &c;
    return nullptr;
}

inline Op binaryOpcode(BinaryOp op) {
    switch (op) {
    case BinaryOp::Add: return Op::Add;
    case BinaryOp::Sub: return Op::Sub;
    case BinaryOp::Mul: return Op::Mul;
    case BinaryOp::Div: return Op::Div;
    case BinaryOp::Mod: return Op::Mod;
    case BinaryOp::Pow: return Op::Pow;
    case BinaryOp::Lt: return Op::Lt;
    case BinaryOp::Gt: return Op::Gt;
    case BinaryOp::Le: return Op::Le;
    case BinaryOp::Ge: return Op::Ge;
    case BinaryOp::Eq: return Op::Eq;
    case BinaryOp::Ne: return Op::Ne;
    case BinaryOp::And: return Op::And;
    case BinaryOp::Or: return Op::Or;
    }
    return Op::Add;
}

// The parser marks an expression it could not parse this way (see parser.cpp).
inline bool isErrorExpr(const Expr& e) { return e.kind == ExprKind::Number && e.text == "<error>"; }

class Compiler {
public:
    Compiler(const Ast& ast, const CompileOptions& opt, DiagnosticSink& sink)
        : mAst(ast), mOpt(opt), mSink(sink) {}

    std::optional<Bytecode> run();

private:
    // ---- diagnostics ----
    Diagnostic* error(Span span, std::string message);
    void note(Diagnostic* d, Span span, std::string message);

    // ---- registers and emission ----
    Reg newReg(const Type& t);
    Value constant(const std::vector<double>& values);
    Value constant(double v) { return constant(std::vector<double>{v}); }
    Value constantString(const std::string& s);
    Value emit(Instr in, Type result, bool pure = true);
    Value component(const Value& v, int k, Span span);
    Value splat(const Value& v, int width, Span span);
    Value hostInput(const HostVariable& hv);
    const HostVariable* findHost(const std::string& name) const {
        for (const HostVariable& hv : mOpt.variables)
            if (hv.name == name) return &hv;
        return nullptr;
    }
    bool allConstant(const Instr& in) const;

    // ---- expressions ----
    Value expr(const Expr* e);
    Value variable(const Expr* e);
    Value vectorLiteral(const Expr* e);
    Value unary(const Expr* e);
    Value binary(const Expr* e);
    Value binaryValues(BinaryOp op, const Value& a, const Value& b, Span span, Span aSpan, Span bSpan);
    Value ternary(const Expr* e);
    Value index(const Expr* e);
    Value call(const Expr* e);
    Value callBuiltin(const Expr* e, const FunctionInfo& fn, int32_t index, std::vector<Value> args);
    Value callDef(const Expr* e, const FunctionDef& def, std::vector<Value> args);
    Value getVar(const Expr* e, const std::vector<Value>& args);
    std::vector<Value> arguments(const Expr* e);

    // ---- statements ----
    void statements(const std::vector<Stmt*>& list);
    void assign(const Stmt* s);
    void ifStatement(const Stmt* s);
    Value convertTo(const Value& v, const TypeAnnotation& t, Span span, const char* what);
    Value andMask(const Value& cond, bool negate, Span span);

    // ---- finishing ----
    void checkRecursion();
    void eliminateDeadCode();

    const Ast& mAst;
    const CompileOptions& mOpt;
    DiagnosticSink& mSink;
    Bytecode mBc;
    Env* mEnv = nullptr;
    std::map<std::string, const FunctionDef*> mDefs;
    std::set<const FunctionDef*> mRecursive;
    std::vector<const FunctionDef*> mInlineStack;
    std::vector<Span> mCallSites;
    std::map<std::vector<uint64_t>, Reg> mConstCache;
    std::map<std::string, Reg> mStringCache;
    std::map<std::string, Reg> mInputRegs;
    std::set<std::pair<uint32_t, std::string>> mReported;
    Value mMask; // lanes on which side effects may run (no reg: all)
    bool mTooLarge = false;
    size_t mInlinedCalls = 0;
};

} // namespace gale::lang::compiler_detail
