// Signature mini-language of built-ins ("FP[n] clamp(FP[n] x, FP[n] lo, FP[n] hi)") and
// name suggestions for unknown functions.
#include "lang/functions.h"

#include <algorithm>
#include <cctype>
#include <charconv>

namespace gale::lang {
namespace {

class SigReader {
public:
    explicit SigReader(std::string_view s) : mS(s) {}
    void skip() { while (mPos < mS.size() && std::isspace(static_cast<unsigned char>(mS[mPos]))) ++mPos; }
    bool eat(char c) {
        skip();
        if (mPos < mS.size() && mS[mPos] == c) { ++mPos; return true; }
        return false;
    }
    bool eatWord(std::string_view w) {
        skip();
        if (mS.substr(mPos, w.size()) == w) { mPos += w.size(); return true; }
        return false;
    }
    std::string name() {
        skip();
        size_t b = mPos;
        while (mPos < mS.size() && (std::isalnum(static_cast<unsigned char>(mS[mPos])) || mS[mPos] == '_' || mS[mPos] == '.'))
            ++mPos;
        return std::string(mS.substr(b, mPos - b));
    }
    bool number(double& v) {
        skip();
        size_t b = mPos;
        if (mPos < mS.size() && (mS[mPos] == '-' || mS[mPos] == '+')) ++mPos;
        while (mPos < mS.size() && (std::isdigit(static_cast<unsigned char>(mS[mPos])) || mS[mPos] == '.' ||
                                    mS[mPos] == 'e' || mS[mPos] == 'E' ||
                                    ((mS[mPos] == '-' || mS[mPos] == '+') && (mS[mPos - 1] == 'e' || mS[mPos - 1] == 'E'))))
            ++mPos;
        std::string_view t = mS.substr(b, mPos - b);
        if (!t.empty() && t[0] == '+') t.remove_prefix(1);
        auto r = std::from_chars(t.data(), t.data() + t.size(), v);
        return r.ec == std::errc() && r.ptr == t.data() + t.size() && !t.empty();
    }
    // FP[k] | FP[n] | STRING | ANY
    bool type(ParamSpec& p) {
        if (eatWord("STRING")) { p.kind = ParamSpec::String; p.width = 1; return true; }
        if (eatWord("ANY")) { p.kind = ParamSpec::Any; p.width = 1; return true; }
        if (!eatWord("FP")) return false;
        p.kind = ParamSpec::Float;
        if (!eat('[')) return false;
        skip();
        if (eat('n')) p.width = 0;
        else {
            double w;
            if (!number(w) || w < 1 || w > kMaxWidth) return false;
            p.width = static_cast<int>(w);
        }
        return eat(']');
    }
    bool done() { skip(); return mPos == mS.size(); }

private:
    std::string_view mS;
    size_t mPos = 0;
};

} // namespace

bool parseSignature(std::string_view text, ParsedSignature& out, std::string* error) {
    auto fail = [&](const char* why) {
        if (error) *error = std::string(why) + " in signature '" + std::string(text) + "'";
        return false;
    };
    out = ParsedSignature{};
    SigReader r(text);
    if (!r.type(out.result)) return fail("expected a result type");
    if (r.name().empty()) return fail("expected the function name");
    if (!r.eat('(')) return fail("expected '('");
    bool seenDefault = false;
    if (!r.eat(')')) {
        for (;;) {
            ParamSpec p;
            if (!r.type(p)) return fail("expected a parameter type");
            p.name = r.name();
            bool dotsInName = p.name.size() > 3 && p.name.compare(p.name.size() - 3, 3, "...") == 0;
            if (dotsInName) p.name.resize(p.name.size() - 3);
            if (p.name.empty()) return fail("expected a parameter name");
            if (r.eat('=')) {
                if (p.kind != ParamSpec::Float || !r.number(p.defaultValue)) return fail("bad default value");
                p.hasDefault = true;
                seenDefault = true;
            } else if (seenDefault) {
                return fail("a parameter without default follows one with a default");
            }
            bool variadic = dotsInName || r.eatWord("...");
            out.params.push_back(p);
            if (variadic) {
                out.variadic = true;
                if (!r.eat(')')) return fail("'...' must mark the last parameter");
                break;
            }
            if (r.eat(')')) break;
            if (!r.eat(',')) return fail("expected ',' or ')'");
        }
    }
    if (!r.done()) return fail("unexpected text after ')'");
    out.minArgs = 0;
    for (const ParamSpec& p : out.params) {
        if (p.hasDefault) break;
        ++out.minArgs;
    }
    // A variadic last parameter may appear any number of times, including none.
    if (out.variadic && !out.params.back().hasDefault) --out.minArgs;
    return true;
}

static size_t editDistance(std::string_view a, std::string_view b) {
    std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            size_t sub = prev[j - 1] + (std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                                                std::tolower(static_cast<unsigned char>(b[j - 1]))
                                            ? 0
                                            : 1);
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

std::string_view closestName(std::string_view name, const std::vector<std::string_view>& candidates) {
    if (name.size() > 64) return {};
    std::string_view best;
    size_t bestD = name.size() <= 3 ? 1 : name.size() <= 6 ? 2 : 3;
    bool found = false;
    for (std::string_view c : candidates) {
        if (c.size() > name.size() + bestD + 1 || c.size() + bestD + 1 < name.size()) continue;
        size_t d = editDistance(name, c);
        if (d <= bestD && (!found || d < bestD)) {
            best = c;
            bestD = d;
            found = true;
        }
    }
    return best;
}

} // namespace gale::lang
