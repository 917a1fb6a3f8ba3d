// Parameter and ramp literals of an expression file, and their in-place rewriting
// (literals.h). Parameters come from fields::findParameters; ramps from the parsed AST.
#include "live/literals.h"

#include "fields/expression_field.h"
#include "lang/diagnostics.h"
#include "lang/parser.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace gale::live {

namespace {

bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n';
}

// A literal number, or a negated one: its value.
bool literalNumber(const lang::Expr* e, double& v) {
    if (!e) return false;
    if (e->kind == lang::ExprKind::Number) {
        v = e->number;
        return true;
    }
    if (e->kind == lang::ExprKind::Unary && e->args.size() == 1 &&
        (e->unaryOp == lang::UnaryOp::Neg || e->unaryOp == lang::UnaryOp::Plus) &&
        literalNumber(e->args[0], v)) {
        if (e->unaryOp == lang::UnaryOp::Neg) v = -v;
        return true;
    }
    return false;
}

bool literalValue(const lang::Expr* e, size_t width, std::vector<double>& out) {
    out.clear();
    double v = 0.0;
    if (width == 1) {
        if (!literalNumber(e, v)) return false;
        out.push_back(v);
        return true;
    }
    if (!e || e->kind != lang::ExprKind::Vector || e->args.size() != width) return false;
    for (const lang::Expr* a : e->args) {
        if (!literalNumber(a, v)) return false;
        out.push_back(v);
    }
    return true;
}

void visit(const lang::Expr* e, const lang::SourceFile& src, std::vector<RampLiteral>& out,
           int depth) {
    if (!e || depth > 2000) return;
    if (e->kind == lang::ExprKind::Call && !e->piped &&
        (e->text == "curve" || e->text == "ccurve") && e->args.size() >= 4 &&
        (e->args.size() - 1) % 3 == 0) {
        RampLiteral r;
        r.function = e->text;
        const size_t width = e->text == "curve" ? 1 : 3;
        bool ok = true;
        for (size_t k = 1; ok && k + 2 < e->args.size(); k += 3) {
            RampPoint p;
            double interp = 0.0;
            ok = literalNumber(e->args[k], p.position) &&
                 literalValue(e->args[k + 1], width, p.value) &&
                 literalNumber(e->args[k + 2], interp) && interp == std::floor(interp) &&
                 interp >= 0 && interp <= 4;
            p.interp = static_cast<int>(interp);
            r.points.push_back(std::move(p));
        }
        if (ok) {
            const lang::LineCol lc = src.lineCol(e->span.begin);
            r.line = static_cast<int>(lc.line);
            r.col = static_cast<int>(lc.col);
            r.begin = e->args[1]->span.begin;
            r.end = e->args.back()->span.end;
            out.push_back(std::move(r));
        }
    }
    for (const lang::Expr* a : e->args) visit(a, src, out, depth + 1);
}

void visit(const std::vector<lang::Stmt*>& body, const lang::SourceFile& src,
           std::vector<RampLiteral>& out) {
    for (const lang::Stmt* s : body) {
        if (!s) continue;
        visit(s->value, src, out, 0);
        visit(s->cond, src, out, 0);
        visit(s->thenBody, src, out);
        visit(s->elseBody, src, out);
    }
}

bool whole(double v) {
    return std::isfinite(v) && v == std::floor(v);
}

std::string valueText(const std::vector<double>& v) {
    if (v.size() == 1) return numberText(v[0]);
    std::string s = "[";
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + numberText(v[i]);
    return s + "]";
}

} // namespace

std::string numberText(double v) {
    if (v == 0) return "0";
    char buf[40];
    for (int digits = 1; digits <= 17; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (std::strtod(buf, nullptr) == v) break;
    }
    return buf;
}

SourceLiterals findLiterals(const lang::SourceFile& source) {
    SourceLiterals out;
    const std::string& text = source.text();
    const std::vector<fields::ParameterDecl> decls = fields::findParameters(source);
    for (const fields::ParameterDecl& d : decls) {
        ParamLiteral p;
        p.name = d.name;
        p.value = d.defaultValue;
        p.hasRange = d.hasRange;
        p.min = d.min;
        p.max = d.max;
        p.doc = d.doc;
        p.line = d.line;
        p.col = static_cast<int>(source.lineCol(d.span.begin).col);
        const size_t eq = text.find('=', d.span.begin);
        if (eq == std::string::npos || eq >= d.span.end) continue;
        size_t b = eq + 1, e = d.span.end - 1; // e: the ';'
        while (b < e && isSpace(text[b])) ++b;
        while (e > b && isSpace(text[e - 1])) --e;
        p.begin = static_cast<uint32_t>(b);
        p.end = static_cast<uint32_t>(e);
        bool allWhole = true;
        for (double v : p.value) allWhole = allWhole && whole(v);
        p.integer = p.hasRange && whole(p.min) && whole(p.max) && allWhole;
        out.params.push_back(std::move(p));
    }
    // Parsed as the compiler sees it: the declarations blanked (every other byte keeps its
    // offset), so `def`s may follow them.
    const lang::SourceFile parsed = fields::withoutParameters(source, decls);
    lang::DiagnosticSink sink;
    std::unique_ptr<lang::Ast> ast = lang::parseProgram(parsed, sink);
    if (ast && !sink.hasErrors()) {
        for (const lang::FunctionDef* d : ast->defs) {
            visit(d->body, parsed, out.ramps);
            visit(d->result, parsed, out.ramps, 0);
        }
        visit(ast->statements, parsed, out.ramps);
        visit(ast->result, parsed, out.ramps, 0);
    }
    return out;
}

bool rewriteParam(std::string& text, const ParamLiteral& p, const std::vector<double>& value,
                  std::string& error) {
    if (value.size() != p.value.size()) {
        error = "$" + p.name + " has " + std::to_string(p.value.size()) + " component(s); " +
                std::to_string(value.size()) + " given";
        return false;
    }
    for (double v : value)
        if (!std::isfinite(v)) {
            error = "$" + p.name + ": the value must be a finite number";
            return false;
        }
    if (p.end > text.size() || p.begin > p.end) {
        error = "$" + p.name + ": the file changed; reload";
        return false;
    }
    text.replace(p.begin, p.end - p.begin, valueText(value));
    return true;
}

bool rewriteRamp(std::string& text, const RampLiteral& r, const std::vector<RampPoint>& points,
                 std::string& error) {
    const size_t width = r.function == "curve" ? 1 : 3;
    if (points.empty() || points.size() > 1000) {
        error = r.function + " ramp: give 1 to 1000 control points";
        return false;
    }
    std::string out;
    for (size_t i = 0; i < points.size(); ++i) {
        const RampPoint& p = points[i];
        bool finite = std::isfinite(p.position);
        for (double v : p.value) finite = finite && std::isfinite(v);
        if (p.value.size() != width || !finite || p.interp < 0 || p.interp > 4) {
            error = r.function + " ramp point " + std::to_string(i + 1) +
                    ": expected a finite position, " +
                    (width == 1 ? "a value" : "an [r, g, b] value") +
                    " and an interpolation code 0 to 4";
            return false;
        }
        out += (i ? ", " : "") + numberText(p.position) + "," + valueText(p.value) + "," +
               std::to_string(p.interp);
    }
    if (r.end > text.size() || r.begin > r.end) {
        error = r.function + " ramp: the file changed; reload";
        return false;
    }
    text.replace(r.begin, r.end - r.begin, out);
    return true;
}

} // namespace gale::live
