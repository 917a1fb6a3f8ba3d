// The compiler's statements: assignments (with their declared types) and if/else, whose
// branches run under a lane mask and whose variables are merged, or marked unusable with the
// reason, afterwards.
#include "lang/compiler_impl.h"

namespace gale::lang::compiler_detail {

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

} // namespace gale::lang::compiler_detail
