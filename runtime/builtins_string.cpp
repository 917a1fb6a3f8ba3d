// String built-ins: sprintf (C formats %d %i %o %u %x %X %c %e %f %g %a %s, %% and %v for
// vectors), printf (the same, appended to the block's message buffer), and the table entry that
// documents getVar (which the compiler compiles itself).
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace gale::runtime {
namespace {

// One piece of a parsed format: literal text, or a conversion taking the next argument.
struct FormatPiece {
    bool isSpec = false;
    std::string text; // literal text, or the C format of the conversion ("%-8.3f"; %v uses 'g')
    char conv = 0;    // d i o u x X c e E f F g G a A s v
    bool bare = false; // no flags, width or precision ("%f")
};

constexpr std::string_view kIntConvs = "diouxXc";
constexpr std::string_view kFloatConvs = "eEfFgGaA";

constexpr size_t kMaxFormatWidth = 1000;

bool isIntConv(char c) { return kIntConvs.find(c) != std::string_view::npos; }
bool isFloatConv(char c) { return kFloatConvs.find(c) != std::string_view::npos; }

// Splits `fmt` into pieces. Length modifiers (h l L q j z t) are accepted and dropped. On a
// malformed conversion, returns false with a message; the rest of the text is kept literally.
bool parseFormat(std::string_view fmt, std::vector<FormatPiece>& out, std::string* error) {
    out.clear();
    std::string lit;
    auto flushText = [&] {
        if (lit.empty()) return;
        FormatPiece p;
        p.text = std::move(lit);
        out.push_back(std::move(p));
        lit.clear();
    };
    size_t i = 0;
    while (i < fmt.size()) {
        const char ch = fmt[i];
        if (ch != '%') {
            lit += ch;
            ++i;
            continue;
        }
        if (i + 1 < fmt.size() && fmt[i + 1] == '%') {
            lit += '%';
            i += 2;
            continue;
        }
        size_t j = i + 1;
        std::string spec = "%";
        while (j < fmt.size() && std::string_view("-+ #0").find(fmt[j]) != std::string_view::npos) spec += fmt[j++];
        size_t widest = 0; // the larger of width and precision
        for (size_t w = 0; j < fmt.size() && fmt[j] >= '0' && fmt[j] <= '9'; ++j) {
            spec += fmt[j];
            widest = w = std::min<size_t>(w * 10 + static_cast<size_t>(fmt[j] - '0'), 1u << 30);
        }
        if (j < fmt.size() && fmt[j] == '.') {
            spec += fmt[j++];
            for (size_t w = 0; j < fmt.size() && fmt[j] >= '0' && fmt[j] <= '9'; ++j) {
                spec += fmt[j];
                w = std::min<size_t>(w * 10 + static_cast<size_t>(fmt[j] - '0'), 1u << 30);
                widest = std::max(widest, w);
            }
        }
        while (j < fmt.size() && std::string_view("hlLqjzt").find(fmt[j]) != std::string_view::npos) ++j;
        const char conv = j < fmt.size() ? fmt[j] : '\0';
        // Width and precision are capped: "%999999999d" would make a 1 GB string per point.
        if (widest > kMaxFormatWidth) {
            if (error)
                *error = "format width or precision too large in '" + std::string(fmt.substr(i, j + 1 - i)) +
                         "' (at most " + std::to_string(kMaxFormatWidth) + ")";
            lit += fmt.substr(i);
            flushText();
            return false;
        }
        if (conv == '\0' || !(isIntConv(conv) || isFloatConv(conv) || conv == 's' || conv == 'v')) {
            if (error) {
                *error = conv == '\0' ? "incomplete format specifier '" + std::string(fmt.substr(i)) + "'"
                                      : "unsupported format specifier '" + std::string(fmt.substr(i, j + 1 - i)) +
                                            "' (use %d %i %o %u %x %X %c %e %f %g %a %s %v or %%)";
            }
            lit += fmt.substr(i);
            flushText();
            return false;
        }
        flushText();
        FormatPiece p;
        p.isSpec = true;
        p.bare = spec.size() == 1;
        p.conv = conv;
        p.text = spec + (conv == 'v' ? 'g' : conv);
        out.push_back(std::move(p));
        i = j + 1;
    }
    flushText();
    return true;
}

template <class V>
void appendFormatted(std::string& out, const char* cfmt, V value) {
    char buf[128];
    const int len = std::snprintf(buf, sizeof buf, cfmt, value);
    if (len < 0) return;
    if (static_cast<size_t>(len) < sizeof buf) {
        out.append(buf, static_cast<size_t>(len));
        return;
    }
    std::string big(static_cast<size_t>(len) + 1, '\0');
    std::snprintf(big.data(), big.size(), cfmt, value);
    out.append(big.data(), static_cast<size_t>(len));
}

void appendNumber(std::string& out, const FormatPiece& p, double v, bool seexprPrintf) {
    const char c = p.conv;
    if (c == 'd' || c == 'i' || c == 'c') {
        appendFormatted(out, p.text.c_str(), detail::truncToInt(v));
    } else if (isIntConv(c)) {
        appendFormatted(out, p.text.c_str(), static_cast<unsigned>(detail::truncToInt(v)));
    } else if (seexprPrintf && p.bare && c == 'f') {
        appendFormatted(out, "%g", v); // SeExpr2's printf streams %f with the default format
    } else {
        appendFormatted(out, p.text.c_str(), v);
    }
}

// Formats lane i of the call's arguments (args[1..]) with the parsed pieces. Arguments that do
// not fit their conversion (possible only with a non-constant format) are printed as they are;
// a conversion without argument is printed literally.
template <class T>
void formatLane(std::string& out, const std::vector<FormatPiece>& pieces, const KernelFrame<T>& f, int i,
                bool seexprPrintf) {
    int next = 1;
    for (const FormatPiece& p : pieces) {
        if (!p.isSpec) {
            out += p.text;
            continue;
        }
        if (next >= f.nargs) {
            out += p.text;
            continue;
        }
        const Operand<T>& a = f.args[next++];
        if (a.str != nullptr) {
            if (p.conv == 's') appendFormatted(out, p.text.c_str(), a.string(i).c_str());
            else out += a.string(i);
            continue;
        }
        if (p.conv == 'v') {
            const int w = a.width == 1 ? 3 : a.width;
            out += '[';
            for (int k = 0; k < w; ++k) {
                if (k) out += ',';
                appendFormatted(out, p.text.c_str(), double(a.at(k, i)));
            }
            out += ']';
        } else if (p.conv == 's') {
            appendFormatted(out, "%g", double(a.at(0, i)));
        } else {
            appendNumber(out, p, double(a.at(0, i)), seexprPrintf);
        }
    }
}

// Runs `emit(i, pieces)` per lane, parsing the format once when it is the same for all lanes.
template <class T, class Emit>
void forEachLane(const KernelFrame<T>& f, Emit emit) {
    const Operand<T>& fmt = f.args[0];
    std::vector<FormatPiece> pieces;
    if (fmt.uniform()) parseFormat(fmt.string(0), pieces, nullptr);
    for (int i = 0; i < f.n; ++i) {
        if (!fmt.uniform()) parseFormat(fmt.string(i), pieces, nullptr);
        emit(i, pieces);
    }
}

struct SprintfK {
    template <class T> static void run(const KernelFrame<T>& f) {
        forEachLane(f, [&](int i, const std::vector<FormatPiece>& pieces) {
            std::string& s = f.outStr[i];
            s.clear();
            formatLane(s, pieces, f, i, false);
        });
    }
};

// printf: only active lanes print, in lane order, each call ending its line (SeExpr2 ends
// the line itself; a format that already ends with a newline gets no second one). Result 0.
struct PrintfK {
    template <class T> static void run(const KernelFrame<T>& f) {
        T* __restrict o = f.outComp(0);
        for (int i = 0; i < f.n; ++i) o[i] = 0;
        if (f.messages == nullptr) return;
        forEachLane(f, [&](int i, const std::vector<FormatPiece>& pieces) {
            if (!f.active(i)) return;
            std::string& m = *f.messages;
            const size_t before = m.size();
            formatLane(m, pieces, f, i, true);
            if (m.size() == before || m.back() != '\n') m += '\n';
        });
    }
};

// With a constant format: the conversions must match the arguments in number and type.
bool validateFormatCall(lang::CallSite& site, bool isPrintf) {
    const size_t nargs = site.argTypes.size();
    bool ok = true;
    for (size_t j = 1; j < nargs; ++j) {
        const lang::Type& t = site.argTypes[j];
        if (t.isError()) ok = false;
    }
    if (!ok) return false;
    const std::string* fmt = site.constStrings.empty() ? nullptr : site.constStrings[0];
    if (fmt == nullptr) return true; // checked per lane at run time
    std::vector<FormatPiece> pieces;
    std::string error;
    if (!parseFormat(*fmt, pieces, &error)) {
        site.sink->error(site.argSpans[0], std::string(site.name) + ": " + error);
        return false;
    }
    size_t arg = 1;
    for (const FormatPiece& p : pieces) {
        if (!p.isSpec) continue;
        if (arg >= nargs) {
            site.sink->error(site.argSpans[0], std::string(site.name) + ": the format has more conversions than the " +
                                                   std::to_string(nargs - 1) + " values given");
            return false;
        }
        const lang::Type& t = site.argTypes[arg];
        const lang::Span& span = site.argSpans[arg];
        if (p.conv == 's') {
            if (!t.isString()) {
                site.sink->error(span, std::string(site.name) + ": %s expects a STRING, got " + lang::typeName(t));
                ok = false;
            }
        } else if (!t.isFloat()) {
            site.sink->error(span, std::string(site.name) + ": %" + std::string(1, p.conv) + " expects a number, got " +
                                       lang::typeName(t));
            ok = false;
        } else if (p.conv != 'v' && t.width != 1 && !isPrintf) {
            site.sink->error(span, std::string(site.name) + ": %" + std::string(1, p.conv) + " expects FP[1], got " +
                                       lang::typeName(t) + " (use %v for vectors)");
            ok = false;
        }
        ++arg;
    }
    if (arg < nargs) {
        site.sink->error(site.argSpans[arg], std::string(site.name) + ": more values than the format's " +
                                                 std::to_string(arg - 1) + " conversions");
        return false;
    }
    return ok;
}

bool validateSprintf(lang::CallSite& site) { return validateFormatCall(site, false); }
bool validatePrintf(lang::CallSite& site) { return validateFormatCall(site, true); }

} // namespace

void addStringBuiltins(FunctionTable& t) {
    Builtin sprintf = kernelBuiltin<SprintfK>(
        "sprintf", "STRING sprintf(STRING format, ANY values...)",
        "C-style formatting: %d %i %o %u %x %X %c %e %f %g %a %s %%, and %v for a vector as [x,y,z]");
    sprintf.info.validate = &validateSprintf;
    t.add(sprintf);

    Builtin printf = kernelBuiltin<PrintfK>(
        "printf", "FP[1] printf(STRING format, ANY values...)",
        "prints a line formatted like sprintf (a bare %f prints like SeExpr2, as %g) to the diagnostics; returns 0");
    printf.info.validate = &validatePrintf;
    printf.info.foldable = false;
    printf.info.sideEffects = true;
    t.add(printf);

    Builtin getVar;
    getVar.info.name = "getVar";
    getVar.info.signature = "ANY getVar(STRING name, ANY default)";
    getVar.info.doc = "the variable called name if it exists (a local or host variable), else default";
    getVar.info.foldable = false;
    t.add(getVar);
}

} // namespace gale::runtime
