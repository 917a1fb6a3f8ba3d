// The compiler's expressions: variables, literals, operators with their type rules (widths,
// scalar promotion, strings), the ternary, indexing, built-in calls (argument checks and
// conversions) and `def` calls inlined per call site.
#include "lang/compiler_impl.h"

namespace gale::lang::compiler_detail {

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

} // namespace gale::lang::compiler_detail
