// Type checker and code generator: one walk over the AST that infers types and lifetimes,
// reports every error it can without cascades, inlines `def` functions per call site, and
// emits register bytecode with constant work folded away. This file: diagnostics, registers
// and emission (constant folding), and the finishing passes (recursion, dead code); the type
// rules of expressions are in compiler_expressions.cpp, statements in compiler_statements.cpp.
#include "lang/compiler_impl.h"

namespace gale::lang::compiler_detail {

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

} // namespace gale::lang::compiler_detail

namespace gale::lang {

std::optional<Bytecode> compile(const Ast& ast, const CompileOptions& options, DiagnosticSink& sink) {
    compiler_detail::Compiler c(ast, options, sink);
    return c.run();
}

} // namespace gale::lang
