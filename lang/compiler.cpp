// Type checker and code generator: one walk over the AST that infers types and lifetimes,
// reports every error it can without cascades, inlines `def` functions per call site, and
// emits register bytecode with constant work folded away.
#include "lang/compiler.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

namespace gale::lang {
namespace {

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
constexpr BuiltinConstant kConstants[] = {
    {"PI", 3.14159265358979323846}, {"E", 2.71828182845904523536}, {"linear", 0},
    {"smooth", 1},                  {"gaussian", 2},               {"box", 3},
};

const BuiltinConstant* findConstant(std::string_view name) {
    for (const BuiltinConstant& c : kConstants)
        if (name == c.name) return &c;
    return nullptr;
}

Op binaryOpcode(BinaryOp op) {
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
bool isErrorExpr(const Expr& e) { return e.kind == ExprKind::Number && e.text == "<error>"; }

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

// ------------------------------------------------------------------------------------------
// Diagnostics

Diagnostic* Compiler::error(Span span, std::string message) {
    if (!mReported.insert({span.begin, message}).second) return nullptr; // same error again
    Diagnostic& d = mSink.error(span, std::move(message));
    if (!mCallSites.empty()) {
        d.notes.push_back({"in the call of '" + mInlineStack.back()->name + "' here", mCallSites.back(), true});
    }
    return &d;
}

void Compiler::note(Diagnostic* d, Span span, std::string message) {
    if (d) d->notes.push_back({std::move(message), span, true});
}

// ------------------------------------------------------------------------------------------
// Registers

Reg Compiler::newReg(const Type& t) {
    RegInfo info;
    info.kind = t.isString() ? TypeKind::String : TypeKind::Float;
    info.width = t.width;
    info.lifetime = t.lifetime;
    return mBc.addReg(info);
}

Value Compiler::constant(const std::vector<double>& values) {
    std::vector<uint64_t> key(values.size());
    for (size_t i = 0; i < values.size(); ++i) std::memcpy(&key[i], &values[i], sizeof(double));
    Type t = Type::fp(static_cast<int>(values.size()), Lifetime::Constant);
    auto it = mConstCache.find(key);
    if (it != mConstCache.end()) return {it->second, t};
    RegInfo info;
    info.width = static_cast<uint8_t>(values.size());
    info.lifetime = Lifetime::Constant;
    info.constIndex = static_cast<int32_t>(mBc.constants.size());
    mBc.constants.insert(mBc.constants.end(), values.begin(), values.end());
    Reg r = mBc.addReg(info);
    mConstCache[key] = r;
    return {r, t};
}

Value Compiler::constantString(const std::string& s) {
    auto it = mStringCache.find(s);
    if (it != mStringCache.end()) return {it->second, Type::string(Lifetime::Constant)};
    RegInfo info;
    info.kind = TypeKind::String;
    info.lifetime = Lifetime::Constant;
    info.constIndex = static_cast<int32_t>(mBc.strings.size());
    mBc.strings.push_back(s);
    Reg r = mBc.addReg(info);
    mStringCache[s] = r;
    return {r, Type::string(Lifetime::Constant)};
}

bool Compiler::allConstant(const Instr& in) const {
    auto isConst = [&](Reg r) { return r == kNoReg || mBc.isConstant(r); };
    if (!isConst(in.a) || !isConst(in.b) || !isConst(in.c)) return false;
    for (int32_t k = 0; k < in.argCount; ++k)
        if (!isConst(mBc.args[static_cast<size_t>(in.argBegin + k)])) return false;
    return true;
}

// Appends `in` with a fresh destination of type `result` — or, when every operand is a
// constant and the operation is pure, evaluates it now and returns a constant instead.
Value Compiler::emit(Instr in, Type result, bool pure) {
    if (mBc.code.size() >= mOpt.maxInstructions) {
        if (!mTooLarge) {
            mSink.error(in.span, "program too large (more than " + std::to_string(mOpt.maxInstructions) +
                                     " instructions after inlining)");
            mTooLarge = true;
        }
        return {};
    }
    in.width = result.width;
    if (pure && mOpt.folder && allConstant(in)) {
        std::vector<double> values;
        std::string text;
        in.dst = kNoReg;
        if (mOpt.folder->fold(mBc, in, values, text)) {
            if (result.isString()) return constantString(text);
            if (values.size() == result.width) return constant(values);
        }
    }
    if (!pure) result.lifetime = Lifetime::Varying;
    // Not folded (no folder, or it declined): the value is computed at run time, once per call,
    // so it is uniform; a Constant register must hold its value in Bytecode::constants.
    else if (result.lifetime == Lifetime::Constant) result.lifetime = Lifetime::Uniform;
    in.dst = newReg(result);
    in.width = result.width;
    mBc.code.push_back(in);
    return {in.dst, result};
}

// Component k of a numeric value as a width-1 value (no code: an alias or a constant).
Value Compiler::component(const Value& v, int k, Span) {
    if (!v.ok()) return v;
    const RegInfo info = mBc.reg(v.reg); // a copy: addReg below may reallocate
    if (k < 0 || k >= info.width) return constant(0.0);
    if (info.width == 1) return v;
    if (info.lifetime == Lifetime::Constant) return constant(mBc.constant(v.reg, k));
    RegInfo alias;
    alias.width = 1;
    alias.lifetime = info.lifetime;
    alias.aliasOf = v.reg;
    alias.component = static_cast<uint8_t>(k);
    const Reg r = mBc.addReg(alias);
    return {r, Type::fp(1, info.lifetime)};
}

Value Compiler::splat(const Value& v, int width, Span span) {
    if (!v.ok() || v.type.width == width) return v;
    if (v.type.lifetime == Lifetime::Constant)
        return constant(std::vector<double>(static_cast<size_t>(width), mBc.constant(v.reg, 0)));
    Instr in;
    in.op = Op::Copy;
    in.a = v.reg;
    in.span = span;
    return emit(in, Type::fp(width, v.type.lifetime));
}

Value Compiler::hostInput(const HostVariable& hv) {
    auto it = mInputRegs.find(hv.name);
    if (it != mInputRegs.end()) return {it->second, hv.type};
    Reg r = newReg(hv.type);
    mBc.regs[static_cast<size_t>(r)].input = static_cast<int32_t>(mBc.inputs.size());
    mBc.inputs.push_back({hv.name, hv.type, r});
    mInputRegs[hv.name] = r;
    return {r, hv.type};
}

// ------------------------------------------------------------------------------------------
// Expressions

Value Compiler::expr(const Expr* e) {
    if (!e || isErrorExpr(*e)) return {};
    switch (e->kind) {
    case ExprKind::Number: return constant(e->number);
    case ExprKind::String: return constantString(e->text);
    case ExprKind::Variable: return variable(e);
    case ExprKind::Vector: return vectorLiteral(e);
    case ExprKind::Unary: return unary(e);
    case ExprKind::Binary: return binary(e);
    case ExprKind::Ternary: return ternary(e);
    case ExprKind::Call: return call(e);
    case ExprKind::Index: return index(e);
    }
    return {};
}

Value Compiler::variable(const Expr* e) {
    auto it = mEnv->find(e->text);
    if (it != mEnv->end()) {
        const Binding& b = it->second;
        if (!b.problem.empty()) {
            Diagnostic* d = error(e->span, b.problem);
            if (d)
                for (const DiagnosticNote& n : b.notes) d->notes.push_back(n);
            return {};
        }
        return b.value;
    }
    if (const BuiltinConstant* c = findConstant(e->text)) return constant(c->value);
    if (const HostVariable* hv = findHost(e->text)) return hostInput(*hv);
    Diagnostic* d = error(e->span, "unknown variable '" + std::string(e->dollar ? "$" : "") + e->text + "'");
    if (d) {
        std::vector<std::string_view> names;
        for (const auto& kv : *mEnv) names.push_back(kv.first);
        for (const HostVariable& hv : mOpt.variables) names.push_back(hv.name);
        std::string_view best = closestName(e->text, names);
        if (!best.empty())
            d->notes.push_back({"did you mean '" + std::string(best) + "'?", {}, false});
        else if (e->dollar)
            d->notes.push_back({"bind it on the command line with --set " + e->text + "=VALUE", {}, false});
    }
    return {};
}

Value Compiler::vectorLiteral(const Expr* e) {
    std::vector<Value> parts;
    bool ok = true;
    for (const Expr* a : e->args) {
        Value v = expr(a);
        if (v.ok() && v.type.isString()) {
            error(a->span, "a vector element must be a number, not a string");
            v = {};
        }
        ok = ok && v.ok();
        parts.push_back(component(v, 0, a->span));
    }
    if (e->args.size() > static_cast<size_t>(kMaxWidth)) {
        error(e->span, "vector literal has " + std::to_string(e->args.size()) + " elements; the widest type is FP[" +
                           std::to_string(kMaxWidth) + "]");
        return {};
    }
    if (!ok) return {};
    if (parts.size() == 1) return parts[0];
    Lifetime l = Lifetime::Constant;
    for (const Value& v : parts) l = combine(l, v.type.lifetime);
    if (l == Lifetime::Constant) {
        std::vector<double> values;
        for (const Value& v : parts) values.push_back(mBc.constant(v.reg, 0));
        return constant(values);
    }
    Instr in;
    in.op = Op::Pack;
    in.span = e->span;
    in.argBegin = static_cast<int32_t>(mBc.args.size());
    in.argCount = static_cast<int32_t>(parts.size());
    for (const Value& v : parts) mBc.args.push_back(v.reg);
    return emit(in, Type::fp(static_cast<int>(parts.size()), l));
}

Value Compiler::unary(const Expr* e) {
    Value a = expr(e->args[0]);
    if (!a.ok()) return a;
    if (a.type.isString()) {
        error(e->span, std::string("operator '") + unaryOpText(e->unaryOp) + "' cannot be applied to a string");
        return {};
    }
    Instr in;
    in.a = a.reg;
    in.span = e->span;
    switch (e->unaryOp) {
    case UnaryOp::Plus: return a;
    case UnaryOp::Neg: in.op = Op::Neg; return emit(in, a.type);
    case UnaryOp::Invert: in.op = Op::Invert; return emit(in, a.type);
    case UnaryOp::Not: in.op = Op::Not; return emit(in, a.type.withWidth(1));
    }
    return {};
}

Value Compiler::binary(const Expr* e) {
    if (e->binaryOp == BinaryOp::And || e->binaryOp == BinaryOp::Or) {
        // Short-circuit for side effects: the right side's printf runs only where it would.
        Value a = expr(e->args[0]);
        Value saved = mMask;
        if (a.ok() && a.type.isFloat()) mMask = andMask(a, e->binaryOp == BinaryOp::Or, e->span);
        Value b = expr(e->args[1]);
        mMask = saved;
        return binaryValues(e->binaryOp, a, b, e->span, e->args[0]->span, e->args[1]->span);
    }
    Value a = expr(e->args[0]);
    Value b = expr(e->args[1]);
    return binaryValues(e->binaryOp, a, b, e->span, e->args[0]->span, e->args[1]->span);
}

Value Compiler::binaryValues(BinaryOp op, const Value& a, const Value& b, Span span, Span aSpan, Span bSpan) {
    if (!a.ok() || !b.ok()) return {};
    Instr in;
    in.a = a.reg;
    in.b = b.reg;
    in.span = span;
    Lifetime l = combine(a.type.lifetime, b.type.lifetime);
    if (a.type.isString() || b.type.isString()) {
        if (a.type.isString() && b.type.isString()) {
            if (op == BinaryOp::Add) { in.op = Op::StrCat; return emit(in, Type::string(l)); }
            if (op == BinaryOp::Eq) { in.op = Op::StrEq; return emit(in, Type::fp(1, l)); }
            if (op == BinaryOp::Ne) { in.op = Op::StrNe; return emit(in, Type::fp(1, l)); }
            error(span, std::string("operator '") + binaryOpText(op) +
                            "' cannot be applied to strings (only + == != can)");
            return {};
        }
        Span s = a.type.isString() ? aSpan : bSpan;
        Diagnostic* d = error(s, std::string("cannot use a string with operator '") + binaryOpText(op) +
                                     "' and a number");
        if (d && op == BinaryOp::Add) d->notes.push_back({"convert the number with sprintf(\"%g\", x)", {}, false});
        return {};
    }
    in.op = binaryOpcode(op);
    int w = broadcastWidth(a.type.width, b.type.width);
    switch (op) {
    case BinaryOp::Lt: case BinaryOp::Gt: case BinaryOp::Le: case BinaryOp::Ge:
    case BinaryOp::And: case BinaryOp::Or:
        return emit(in, Type::fp(1, l));
    default: break;
    }
    if (w == 0) {
        Diagnostic* d = error(span, std::string("operator '") + binaryOpText(op) + "' on vectors of different width: " +
                                        typeName(a.type) + " and " + typeName(b.type));
        note(d, aSpan, "this is " + typeName(a.type));
        note(d, bSpan, "this is " + typeName(b.type));
        return {};
    }
    if (op == BinaryOp::Eq || op == BinaryOp::Ne) return emit(in, Type::fp(1, l));
    // x^2 is x*x: both are the correctly rounded square, and a multiply is far cheaper.
    if (op == BinaryOp::Pow && b.type.lifetime == Lifetime::Constant && b.type.width == 1 &&
        a.type.lifetime != Lifetime::Constant && mBc.constant(b.reg) == 2.0) {
        in.op = Op::Mul;
        in.b = a.reg;
    }
    return emit(in, Type::fp(w, l));
}

Value Compiler::andMask(const Value& cond, bool negate, Span span) {
    Value c = cond;
    if (negate) {
        Instr n;
        n.op = Op::Not;
        n.a = cond.reg;
        n.span = span;
        c = emit(n, Type::fp(1, cond.type.lifetime));
    }
    if (!mMask.ok()) return c;
    Instr in;
    in.op = Op::And;
    in.a = mMask.reg;
    in.b = c.reg;
    in.span = span;
    return emit(in, Type::fp(1, combine(mMask.type.lifetime, c.type.lifetime)));
}

Value Compiler::ternary(const Expr* e) {
    Value c = expr(e->args[0]);
    if (c.ok() && c.type.isString()) {
        error(e->args[0]->span, "the condition of '?:' must be a number, not a string");
        c = {};
    }
    Value saved = mMask;
    if (c.ok()) mMask = andMask(c, false, e->args[0]->span);
    Value a = expr(e->args[1]);
    mMask = saved;
    if (c.ok()) mMask = andMask(c, true, e->args[0]->span);
    Value b = expr(e->args[2]);
    mMask = saved;
    if (!c.ok() || !a.ok() || !b.ok()) return {};
    Instr in;
    in.a = c.reg;
    in.b = a.reg;
    in.c = b.reg;
    in.span = e->span;
    Lifetime l = combine(c.type.lifetime, combine(a.type.lifetime, b.type.lifetime));
    if (a.type.isString() != b.type.isString()) {
        Diagnostic* d = error(e->span, "the branches of '?:' differ: " + typeName(a.type) + " and " + typeName(b.type));
        note(d, e->args[1]->span, "this is " + typeName(a.type));
        note(d, e->args[2]->span, "this is " + typeName(b.type));
        return {};
    }
    if (a.type.isString()) {
        in.op = Op::StrSelect;
        return emit(in, Type::string(l));
    }
    int w = broadcastWidth(a.type.width, b.type.width);
    if (w == 0) {
        Diagnostic* d = error(e->span, "the branches of '?:' have different widths: " + typeName(a.type) + " and " +
                                           typeName(b.type));
        note(d, e->args[1]->span, "this is " + typeName(a.type));
        note(d, e->args[2]->span, "this is " + typeName(b.type));
        return {};
    }
    in.op = Op::Select;
    return emit(in, Type::fp(w, l));
}

Value Compiler::index(const Expr* e) {
    Value v = expr(e->args[0]);
    Value i = expr(e->args[1]);
    if (v.ok() && v.type.isString()) {
        error(e->args[0]->span, "cannot subscript a string");
        return {};
    }
    if (i.ok() && i.type.isString()) {
        error(e->args[1]->span, "a subscript must be a number, not a string");
        return {};
    }
    if (!v.ok() || !i.ok()) return {};
    if (i.type.lifetime == Lifetime::Constant) {
        double k = mBc.constant(i.reg, 0);
        // Truncation toward zero, as SeExpr2; out of range (or negative) gives 0.
        if (!(k > -1.0) || k >= v.type.width) return constant(0.0);
        return component(v, static_cast<int>(k), e->span);
    }
    Instr in;
    in.op = Op::Index;
    in.a = v.reg;
    in.b = component(i, 0, e->args[1]->span).reg;
    in.span = e->span;
    return emit(in, Type::fp(1, combine(v.type.lifetime, i.type.lifetime)));
}

std::vector<Value> Compiler::arguments(const Expr* e) {
    std::vector<Value> args;
    for (const Expr* a : e->args) args.push_back(expr(a));
    return args;
}

Value Compiler::call(const Expr* e) {
    auto def = mDefs.find(e->text);
    if (def != mDefs.end()) return callDef(e, *def->second, arguments(e));
    int32_t index = -1;
    const FunctionInfo* fn = mOpt.functions ? mOpt.functions->findFunction(e->text, &index) : nullptr;
    if (e->text == "getVar") return getVar(e, arguments(e));
    if (!fn) {
        std::vector<Value> args = arguments(e); // still check the arguments
        Diagnostic* d = error(e->nameSpan, "unknown function '" + e->text + "'");
        if (d) {
            std::vector<std::string_view> names;
            if (mOpt.functions) names = mOpt.functions->functionNames();
            for (const auto& kv : mDefs) names.push_back(kv.first);
            std::string_view best = closestName(e->text, names);
            if (!best.empty()) d->notes.push_back({"did you mean '" + std::string(best) + "'?", {}, false});
        }
        return {};
    }
    return callBuiltin(e, *fn, index, arguments(e));
}

Value Compiler::getVar(const Expr* e, const std::vector<Value>& args) {
    if (args.size() != 2) {
        error(e->span, "getVar takes 2 arguments (name, default), got " + std::to_string(args.size()));
        return {};
    }
    if (!args[0].ok() || !args[1].ok()) return {};
    if (!args[0].type.isString() || args[0].type.lifetime != Lifetime::Constant) {
        error(e->args[0]->span, "getVar's first argument must be a constant string (the variable's name)");
        return {};
    }
    std::string name = mBc.constantString(args[0].reg);
    if (!name.empty() && name[0] == '$') name.erase(0, 1);
    auto it = mEnv->find(name);
    if (it != mEnv->end() && it->second.problem.empty()) return it->second.value;
    for (const HostVariable& hv : mOpt.variables)
        if (hv.name == name) return hostInput(hv);
    return args[1];
}

Value Compiler::callBuiltin(const Expr* e, const FunctionInfo& fn, int32_t index, std::vector<Value> args) {
    const ParsedSignature& sig = fn.parsed;
    const size_t nParams = sig.params.size();
    const size_t n = args.size();
    auto arity = [&]() {
        std::string want;
        if (sig.variadic) want = "at least " + std::to_string(sig.minArgs);
        else if (static_cast<size_t>(sig.minArgs) == nParams) want = std::to_string(nParams);
        else want = std::to_string(sig.minArgs) + " to " + std::to_string(nParams);
        Diagnostic* d = error(e->span, "'" + e->text + "' takes " + want + " argument" + (want == "1" ? "" : "s") +
                                           ", got " + std::to_string(n));
        if (d) d->notes.push_back({"signature: " + std::string(fn.signature), {}, false});
    };
    if (n < static_cast<size_t>(sig.minArgs) || (!sig.variadic && n > nParams)) {
        arity();
        return {};
    }
    for (const Value& v : args)
        if (!v.ok()) return {};
    // Defaults for omitted trailing parameters.
    for (size_t i = n; i < nParams; ++i)
        if (sig.params[i].hasDefault) args.push_back(constant(sig.params[i].defaultValue));
    CallSite site;
    site.name = e->text;
    site.span = e->span;
    site.nameSpan = e->nameSpan;
    site.sink = &mSink;
    site.data = fn.hookData;
    std::vector<Span> spans;
    for (size_t i = 0; i < args.size(); ++i) spans.push_back(i < e->args.size() ? e->args[i]->span : e->span);
    // Check kinds and widths; find the broadcast width n of the FP[n] group.
    int groupWidth = 1;
    bool ok = true;
    for (size_t i = 0; i < args.size(); ++i) {
        const ParamSpec& p = sig.params[std::min(i, nParams - 1)];
        const Type& t = args[i].type;
        if (p.kind == ParamSpec::Any) continue;
        if (p.kind == ParamSpec::String) {
            if (!t.isString()) {
                error(spans[i], "argument " + std::to_string(i + 1) + " ('" + p.name + "') of '" + e->text +
                                    "' must be a string, not " + typeName(t));
                ok = false;
            }
            continue;
        }
        if (t.isString()) {
            error(spans[i], "argument " + std::to_string(i + 1) + " ('" + p.name + "') of '" + e->text +
                                "' must be a number, not a string");
            ok = false;
            continue;
        }
        if (p.width == 0) {
            int w = broadcastWidth(groupWidth, t.width);
            if (w == 0) {
                Diagnostic* d = error(spans[i], "argument " + std::to_string(i + 1) + " ('" + p.name + "') of '" +
                                                    e->text + "' is " + typeName(t) + " but earlier arguments are FP[" +
                                                    std::to_string(groupWidth) + "]: vector widths differ");
                if (d) d->notes.push_back({"signature: " + std::string(fn.signature), {}, false});
                ok = false;
            } else {
                groupWidth = w;
            }
        } else if (t.width != p.width && t.width != 1 && !(p.width == 1 && fn.firstComponent)) {
            Diagnostic* d = error(spans[i], "argument " + std::to_string(i + 1) + " ('" + p.name + "') of '" + e->text +
                                                "' must be FP[" + std::to_string(p.width) + "], not " + typeName(t) +
                                                ": vector widths differ");
            if (d) d->notes.push_back({"signature: " + std::string(fn.signature), {}, false});
            ok = false;
        }
    }
    if (!ok) return {};
    Lifetime l = Lifetime::Constant;
    for (size_t i = 0; i < args.size(); ++i) {
        const ParamSpec& p = sig.params[std::min(i, nParams - 1)];
        if (p.kind == ParamSpec::Float && p.width > 1) args[i] = splat(args[i], p.width, spans[i]);
        else if (p.kind == ParamSpec::Float && p.width == 1 && fn.firstComponent &&
                 args[i].type.width > 1)
            args[i] = component(args[i], 0, spans[i]);
        if (!args[i].ok()) return {};
        l = combine(l, args[i].type.lifetime);
        site.argTypes.push_back(args[i].type);
        site.argSpans.push_back(spans[i]);
        std::vector<double> cv;
        const std::string* cs = nullptr;
        if (args[i].type.lifetime == Lifetime::Constant) {
            if (args[i].type.isString()) cs = &mBc.constantString(args[i].reg);
            else
                for (int k = 0; k < args[i].type.width; ++k) cv.push_back(mBc.constant(args[i].reg, k));
        }
        site.constValues.push_back(std::move(cv));
        site.constStrings.push_back(cs);
    }
    Type result;
    if (sig.result.kind == ParamSpec::String) result = Type::string(l);
    else result = Type::fp(sig.result.width == 0 ? groupWidth : sig.result.width, l);
    site.resultType = result;
    if (fn.validate) {
        size_t before = mSink.errorCount();
        if (!fn.validate(site) || mSink.errorCount() > before) return {};
        result.kind = site.resultType.kind;
        result.width = site.resultType.width;
    }
    for (const FunctionInfo::Implicit& im : fn.implicitArgs) {
        const HostVariable* hv = findHost(std::string(im.variable));
        Value v = hv ? hostInput(*hv) : constant(im.fallback);
        result.lifetime = combine(result.lifetime, v.type.lifetime);
        args.push_back(v);
    }
    Instr in;
    in.op = Op::Call;
    in.imm = index;
    in.span = e->span;
    in.argBegin = static_cast<int32_t>(mBc.args.size());
    in.argCount = static_cast<int32_t>(args.size());
    for (const Value& v : args) mBc.args.push_back(v.reg);
    if (fn.sideEffects) {
        in.mask = mMask.ok() ? mMask.reg : kNoReg;
        in.sideEffects = true;
        return emit(in, result, false);
    }
    return emit(in, result, fn.foldable);
}

Value Compiler::convertTo(const Value& v, const TypeAnnotation& t, Span span, const char* what) {
    if (!v.ok()) return v;
    if (t.type.isString() != v.type.isString() ||
        (t.type.isFloat() && v.type.width != t.type.width && v.type.width != 1)) {
        Diagnostic* d = error(span, std::string(what) + " is " + typeName(v.type) + " but is declared " + typeName(t.type));
        note(d, t.span, "declared here");
        return {};
    }
    if (t.hasLifetime && v.type.lifetime > t.type.lifetime) {
        Diagnostic* d = error(span, std::string(what) + " is " + lifetimeName(v.type.lifetime) + " but is declared " +
                                        lifetimeName(t.type.lifetime));
        note(d, t.span, "declared here");
        return {};
    }
    if (t.type.isFloat()) return splat(v, t.type.width, span);
    return v;
}

Value Compiler::callDef(const Expr* e, const FunctionDef& def, std::vector<Value> args) {
    if (args.size() != def.params.size()) {
        Diagnostic* d = error(e->span, "'" + def.name + "' takes " + std::to_string(def.params.size()) + " argument" +
                                           (def.params.size() == 1 ? "" : "s") + ", got " + std::to_string(args.size()));
        note(d, def.nameSpan, "'" + def.name + "' is defined here");
        return {};
    }
    for (const Value& v : args)
        if (!v.ok()) return {};
    if (mRecursive.count(&def)) return {}; // reported once by checkRecursion
    if (mInlineStack.size() >= mOpt.maxInlineDepth) {
        error(e->span, "function calls nested too deeply (limit " + std::to_string(mOpt.maxInlineDepth) + ")");
        return {};
    }
    // Reported once, at the outermost call: expanding would take exponential time and memory.
    if (++mInlinedCalls > mOpt.maxInlinedCalls) {
        if (mInlinedCalls == mOpt.maxInlinedCalls + 1) {
            const Span at = mCallSites.empty() ? e->span : mCallSites.front();
            mSink.error(at, "too many def calls to inline (more than " + std::to_string(mOpt.maxInlinedCalls) +
                                "): every call copies the def's body, so defs that call defs multiply; "
                                "compute a value once into a variable and reuse it");
        }
        return {};
    }
    Env env;
    for (size_t i = 0; i < args.size(); ++i) {
        Value v = args[i];
        if (def.params[i].type)
            v = convertTo(v, *def.params[i].type, e->args[i]->span, ("argument '" + def.params[i].name + "'").c_str());
        if (!v.ok()) return {};
        env[def.params[i].name] = Binding{v, {}, {}, def.params[i].span};
    }
    Env* saved = mEnv;
    mEnv = &env;
    mInlineStack.push_back(&def);
    mCallSites.push_back(e->span);
    statements(def.body);
    Value r = expr(def.result);
    mCallSites.pop_back();
    mInlineStack.pop_back();
    mEnv = saved;
    if (r.ok() && def.returnType) r = convertTo(r, *def.returnType, def.result->span, "the result");
    return r;
}

// ------------------------------------------------------------------------------------------
// Statements

void Compiler::statements(const std::vector<Stmt*>& list) {
    for (const Stmt* s : list) {
        if (!s) continue;
        if (s->kind == StmtKind::Assign) assign(s);
        else ifStatement(s);
    }
}

void Compiler::assign(const Stmt* s) {
    if (findConstant(s->name)) {
        error(s->nameSpan, "cannot assign to the constant '" + s->name + "'");
        expr(s->value);
        return;
    }
    Value v;
    if (s->compound) {
        Expr lhs;
        lhs.kind = ExprKind::Variable;
        lhs.span = s->nameSpan;
        lhs.nameSpan = s->nameSpan;
        lhs.text = s->name;
        lhs.dollar = s->dollar;
        Value a = variable(&lhs);
        Value b = expr(s->value);
        v = binaryValues(s->compoundOp, a, b, s->span, s->nameSpan, s->value ? s->value->span : s->span);
    } else {
        v = expr(s->value);
    }
    Binding& b = (*mEnv)[s->name];
    b.value = v;
    b.assignedAt = s->nameSpan;
    b.notes.clear();
    // An assignment that failed type-checking leaves the variable unusable without a new
    // message at each use: an error value propagates silently.
    b.problem.clear();
}

void Compiler::ifStatement(const Stmt* s) {
    Value c = expr(s->cond);
    if (c.ok() && c.type.isString()) {
        error(s->cond->span, "the condition of 'if' must be a number, not a string");
        c = {};
    }
    Env before = *mEnv;
    Env thenEnv = before, elseEnv = before;
    Value savedMask = mMask;
    Env* savedEnv = mEnv;
    if (c.ok()) mMask = andMask(c, false, s->cond->span);
    mEnv = &thenEnv;
    statements(s->thenBody);
    mMask = savedMask;
    if (c.ok()) mMask = andMask(c, true, s->cond->span);
    mEnv = &elseEnv;
    statements(s->elseBody);
    mMask = savedMask;
    mEnv = savedEnv;

    Env merged;
    std::set<std::string> names;
    for (const auto& kv : thenEnv) names.insert(kv.first);
    for (const auto& kv : elseEnv) names.insert(kv.first);
    for (const std::string& name : names) {
        auto t = thenEnv.find(name);
        auto f = elseEnv.find(name);
        auto b = before.find(name);
        if (t == thenEnv.end() || f == elseEnv.end()) {
            // Assigned in one branch only, and not before as a local. A host variable or a
            // built-in constant of that name is the value before: merge with it.
            Value outer;
            if (const HostVariable* hv = findHost(name)) outer = hostInput(*hv);
            if (outer.ok()) {
                Binding ob{outer, {}, {}, {}};
                (t == thenEnv.end() ? thenEnv : elseEnv)[name] = ob;
                t = thenEnv.find(name);
                f = elseEnv.find(name);
                b = before.end();
            }
        }
        if (t == thenEnv.end() || f == elseEnv.end()) {
            // Assigned in one branch only, and not before (else both maps would have it).
            const Binding& only = t != thenEnv.end() ? t->second : f->second;
            Binding u;
            u.problem = "'" + name + "' is not defined here: it is assigned in only one branch of 'if'";
            u.notes.push_back({"assigned here", only.assignedAt, true});
            u.notes.push_back({"assign it before the 'if' or in both branches", {}, false});
            u.assignedAt = only.assignedAt;
            merged[name] = u;
            continue;
        }
        const Binding& bt = t->second;
        const Binding& bf = f->second;
        if (b != before.end() && bt.value.reg == b->second.value.reg && bf.value.reg == b->second.value.reg &&
            bt.problem == b->second.problem) {
            merged[name] = b->second; // untouched
            continue;
        }
        if (!bt.problem.empty() || !bf.problem.empty()) {
            merged[name] = !bt.problem.empty() ? bt : bf;
            continue;
        }
        Binding m;
        m.assignedAt = bt.assignedAt;
        if (!bt.value.ok() || !bf.value.ok() || !c.ok()) {
            merged[name] = m; // error value: silent
            continue;
        }
        const Type& ta = bt.value.type;
        const Type& tb = bf.value.type;
        if (ta.isString() != tb.isString() || (ta.isFloat() && broadcastWidth(ta.width, tb.width) == 0)) {
            m.problem = "'" + name + "' has different types after 'if': " + typeName(ta) + " in one branch, " +
                        typeName(tb) + " in the other";
            m.notes.push_back({"this is " + typeName(ta), bt.assignedAt, true});
            m.notes.push_back({"this is " + typeName(tb), bf.assignedAt, true});
            merged[name] = m;
            continue;
        }
        Instr in;
        in.op = ta.isString() ? Op::StrSelect : Op::Select;
        in.a = c.reg;
        in.b = bt.value.reg;
        in.c = bf.value.reg;
        in.span = s->span;
        Lifetime l = combine(c.type.lifetime, combine(ta.lifetime, tb.lifetime));
        Type rt = ta.isString() ? Type::string(l) : Type::fp(broadcastWidth(ta.width, tb.width), l);
        m.value = emit(in, rt);
        merged[name] = m;
    }
    *mEnv = std::move(merged);
}

// ------------------------------------------------------------------------------------------
// Finishing

void Compiler::checkRecursion() {
    // Call graph between defs, by name, from the syntax (so unused recursive defs are caught).
    std::map<const FunctionDef*, std::vector<std::pair<const FunctionDef*, Span>>> calls;
    for (const auto& kv : mDefs) {
        const FunctionDef* def = kv.second;
        std::vector<const Expr*> stack;
        auto pushStmts = [&](const std::vector<Stmt*>& body, auto& self) -> void {
            for (const Stmt* s : body) {
                if (!s) continue;
                if (s->value) stack.push_back(s->value);
                if (s->cond) stack.push_back(s->cond);
                self(s->thenBody, self);
                self(s->elseBody, self);
            }
        };
        pushStmts(def->body, pushStmts);
        if (def->result) stack.push_back(def->result);
        while (!stack.empty()) {
            const Expr* e = stack.back();
            stack.pop_back();
            if (!e) continue;
            if (e->kind == ExprKind::Call) {
                auto it = mDefs.find(e->text);
                if (it != mDefs.end()) calls[def].push_back({it->second, e->nameSpan});
            }
            for (const Expr* a : e->args) stack.push_back(a);
        }
    }
    // Reachability in the call graph.
    auto reaches = [&](const FunctionDef* from, const FunctionDef* to) {
        std::set<const FunctionDef*> seen;
        std::vector<const FunctionDef*> work{from};
        while (!work.empty()) {
            const FunctionDef* f = work.back();
            work.pop_back();
            if (!seen.insert(f).second) continue;
            for (const auto& c : calls[f]) {
                if (c.first == to) return true;
                work.push_back(c.first);
            }
        }
        return false;
    };
    // In source order, a call from D back to a def E at or before D that reaches D closes a
    // cycle: report it there, once per cycle (every def on it is then known recursive).
    std::map<const FunctionDef*, size_t> order;
    for (size_t i = 0; i < mAst.defs.size(); ++i)
        if (mAst.defs[i] && !order.count(mAst.defs[i])) order[mAst.defs[i]] = i;
    for (const FunctionDef* d : mAst.defs) {
        if (!d || mDefs.count(d->name) == 0 || mDefs[d->name] != d) continue;
        for (const auto& [callee, span] : calls[d]) {
            if (order[callee] > order[d] || (callee != d && !reaches(callee, d))) continue;
            if (mRecursive.count(d) && mRecursive.count(callee)) continue; // cycle already reported
            for (const auto& kv : mDefs)
                if (kv.second == d || kv.second == callee || (reaches(kv.second, d) && reaches(d, kv.second)))
                    mRecursive.insert(kv.second);
            Diagnostic* diag = error(span, "function '" + d->name + "' recurses (" +
                                               (callee == d ? "calls itself" : "through '" + callee->name + "'") +
                                               "); recursion is not allowed");
            note(diag, callee->nameSpan, "'" + callee->name + "' is defined here");
        }
    }
}

void Compiler::eliminateDeadCode() {
    std::vector<char> live(mBc.regs.size(), 0);
    auto mark = [&](Reg r) {
        while (r != kNoReg) {
            live[static_cast<size_t>(r)] = 1;
            r = mBc.regs[static_cast<size_t>(r)].aliasOf;
        }
    };
    mark(mBc.result);
    std::vector<char> keep(mBc.code.size(), 0);
    for (size_t i = mBc.code.size(); i-- > 0;) {
        const Instr& in = mBc.code[i];
        bool needed = live[static_cast<size_t>(in.dst)] || in.sideEffects;
        if (!needed) continue;
        keep[i] = 1;
        mark(in.a);
        mark(in.b);
        mark(in.c);
        mark(in.mask);
        for (int32_t k = 0; k < in.argCount; ++k) mark(mBc.args[static_cast<size_t>(in.argBegin + k)]);
    }
    std::vector<Instr> code;
    for (size_t i = 0; i < mBc.code.size(); ++i)
        if (keep[i]) code.push_back(mBc.code[i]);
    mBc.code = std::move(code);
    // Drop inputs nothing reads.
    std::vector<HostInput> inputs;
    for (HostInput& hi : mBc.inputs) {
        if (!live[static_cast<size_t>(hi.reg)]) {
            mBc.regs[static_cast<size_t>(hi.reg)].input = -1;
            continue;
        }
        mBc.regs[static_cast<size_t>(hi.reg)].input = static_cast<int32_t>(inputs.size());
        inputs.push_back(hi);
    }
    mBc.inputs = std::move(inputs);
}

std::optional<Bytecode> Compiler::run() {
    for (const FunctionDef* def : mAst.defs) {
        if (!def) continue;
        if (findConstant(def->name)) {
            error(def->nameSpan, "cannot define a function named after the constant '" + def->name + "'");
            continue;
        }
        auto [it, fresh] = mDefs.insert({def->name, def});
        if (!fresh) {
            Diagnostic* d = error(def->nameSpan, "function '" + def->name + "' is defined twice");
            note(d, it->second->nameSpan, "first defined here");
        }
    }
    checkRecursion();
    Env env;
    mEnv = &env;
    statements(mAst.statements);
    Value r = mAst.result ? expr(mAst.result) : Value{};
    Span rs = mAst.result ? mAst.result->span : Span{};
    if (r.ok() && r.type.isString() && (!mOpt.allowStringResult || mOpt.wantWidth > 0)) {
        error(rs, "the program's value is a string, but a number " +
                      (mOpt.wantWidth > 0 ? "FP[" + std::to_string(mOpt.wantWidth) + "]" : std::string()) +
                      " is wanted here");
        r = {};
    }
    if (r.ok() && r.type.isFloat() && mOpt.wantWidth > 0 && r.type.width != mOpt.wantWidth) {
        if (r.type.width == 1) {
            r = splat(r, mOpt.wantWidth, rs);
        } else {
            error(rs, "the program's value is " + typeName(r.type) + " but FP[" + std::to_string(mOpt.wantWidth) +
                          "] is wanted here");
            r = {};
        }
    }
    if (mSink.hasErrors() || !r.ok()) return std::nullopt;
    mBc.result = r.reg;
    mBc.resultType = r.type;
    eliminateDeadCode();
    return std::move(mBc);
}

} // namespace

std::optional<Bytecode> compile(const Ast& ast, const CompileOptions& options, DiagnosticSink& sink) {
    Compiler c(ast, options, sink);
    return c.run();
}

} // namespace gale::lang
