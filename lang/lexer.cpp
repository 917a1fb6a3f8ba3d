// Streaming lexer for the expression language: numbers, names, $variables, strings, comments and
// operators. Malformed input becomes an Error token plus one diagnostic; lexing always continues.
#include "lang/lexer.h"

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <system_error>

namespace gale::lang {

namespace {

bool isDigit(char c) {
    return c >= '0' && c <= '9';
}
bool isAlpha(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}
bool isNameStart(char c) {
    return isAlpha(c) || c == '_';
}
bool isNameChar(char c) {
    return isAlpha(c) || isDigit(c) || c == '_' || c == '.';
}
bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// One byte as a diagnostic shows it: printable ASCII as itself, anything else as \xNN.
std::string showByte(char c) {
    unsigned char u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7F) return std::string(1, c);
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02x", u);
    return buf;
}

// Decimal magnitude of a number literal's mantissa: the power of ten of its leading non-zero
// digit (1 for "5", 2 for "12", -1 for ".05"). Used to tell overflow from underflow.
long mantissaMagnitude(std::string_view s) {
    long intDigits = 0;
    size_t i = 0;
    bool seenNonZero = false;
    for (; i < s.size() && isDigit(s[i]); ++i) {
        if (s[i] != '0') seenNonZero = true;
        if (seenNonZero) ++intDigits;
    }
    if (seenNonZero) return intDigits;
    if (i < s.size() && s[i] == '.') {
        long mag = 0;
        for (++i; i < s.size() && isDigit(s[i]); ++i) {
            if (s[i] != '0') return mag;
            --mag;
        }
    }
    return -1000000; // zero mantissa
}

long exponentValue(std::string_view s) {
    size_t e = s.find_first_of("eE");
    if (e == std::string_view::npos) return 0;
    bool neg = false;
    size_t i = e + 1;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
    long v = 0;
    for (; i < s.size() && isDigit(s[i]); ++i)
        if (v < 100000000) v = v * 10 + (s[i] - '0');
    return neg ? -v : v;
}

} // namespace

const char* tokenKindName(TokenKind kind) {
    static const char* const kNames[] = {
#define GALE_X(name, text) text,
        GALE_TOKEN_KINDS(GALE_X)
#undef GALE_X
    };
    size_t i = static_cast<size_t>(kind);
    return i < sizeof kNames / sizeof kNames[0] ? kNames[i] : "token";
}

bool isReservedWord(std::string_view name) {
    return name == "if" || name == "else" || name == "def" || name == "extern";
}

Lexer::Lexer(const SourceFile& file, DiagnosticSink& sink) : mText(file.text()), mSink(sink) {}

void Lexer::skipSpaceAndComments() {
    const size_t n = mText.size();
    while (mPos < n) {
        char c = mText[mPos];
        if (isSpace(c)) {
            ++mPos;
        } else if (c == '#') {
            while (mPos < n && mText[mPos] != '\n') ++mPos;
        } else {
            break;
        }
    }
}

Token Lexer::make(TokenKind kind, uint32_t begin) {
    Token t;
    t.kind = kind;
    t.span = {begin, mPos};
    return t;
}

Token Lexer::next() {
    skipSpaceAndComments();
    const size_t n = mText.size();
    if (mPos >= n) return make(TokenKind::End, static_cast<uint32_t>(n));

    const uint32_t begin = mPos;
    const char c = mText[mPos];
    const char c1 = mPos + 1 < n ? mText[mPos + 1] : '\0';

    if (isDigit(c) || (c == '.' && isDigit(c1))) return lexNumber();
    if (isNameStart(c)) return lexName(false);
    if (c == '$' && isNameStart(c1)) return lexName(true);
    if (c == '"' || c == '\'') return lexString(c);

    auto op = [&](TokenKind kind, uint32_t len) {
        mPos += len;
        return make(kind, begin);
    };
    switch (c) {
    case '(':
        return op(TokenKind::LParen, 1);
    case ')':
        return op(TokenKind::RParen, 1);
    case '{':
        return op(TokenKind::LBrace, 1);
    case '}':
        return op(TokenKind::RBrace, 1);
    case '[':
        return op(TokenKind::LBracket, 1);
    case ']':
        return op(TokenKind::RBracket, 1);
    case ',':
        return op(TokenKind::Comma, 1);
    case ';':
        return op(TokenKind::Semicolon, 1);
    case '?':
        return op(TokenKind::Question, 1);
    case ':':
        return op(TokenKind::Colon, 1);
    case '~':
        return op(TokenKind::Tilde, 1);
    case '+':
        return c1 == '=' ? op(TokenKind::PlusAssign, 2) : op(TokenKind::Plus, 1);
    case '-':
        if (c1 == '>') return op(TokenKind::Arrow, 2);
        return c1 == '=' ? op(TokenKind::MinusAssign, 2) : op(TokenKind::Minus, 1);
    case '*':
        return c1 == '=' ? op(TokenKind::StarAssign, 2) : op(TokenKind::Star, 1);
    case '/':
        return c1 == '=' ? op(TokenKind::SlashAssign, 2) : op(TokenKind::Slash, 1);
    case '%':
        return c1 == '=' ? op(TokenKind::PercentAssign, 2) : op(TokenKind::Percent, 1);
    case '^':
        return c1 == '=' ? op(TokenKind::CaretAssign, 2) : op(TokenKind::Caret, 1);
    case '!':
        return c1 == '=' ? op(TokenKind::NotEq, 2) : op(TokenKind::Bang, 1);
    case '<':
        return c1 == '=' ? op(TokenKind::LessEq, 2) : op(TokenKind::Less, 1);
    case '>':
        return c1 == '=' ? op(TokenKind::GreaterEq, 2) : op(TokenKind::Greater, 1);
    case '=':
        return c1 == '=' ? op(TokenKind::EqEq, 2) : op(TokenKind::Assign, 1);
    case '&':
        if (c1 == '&') return op(TokenKind::AndAnd, 2);
        break;
    case '|':
        if (c1 == '|') return op(TokenKind::OrOr, 2);
        break;
    default:
        break;
    }

    // A run of bytes that cannot start a token: one diagnostic for the whole run.
    auto isBad = [&](uint32_t p) {
        char b = mText[p];
        char b1 = p + 1 < n ? mText[p + 1] : '\0';
        if (isSpace(b) || b == '#' || isDigit(b) || isNameStart(b) || b == '"' || b == '\'')
            return false;
        if (b == '$') return !isNameStart(b1);
        if (b == '.') return !isDigit(b1);
        if (b == '&' || b == '|') return b1 != b;
        static const char kOps[] = "(){}[],;?:~+-*/%^!<>=";
        for (const char* o = kOps; *o; ++o)
            if (*o == b) return false;
        return true;
    };
    ++mPos;
    while (mPos < n && isBad(mPos)) ++mPos;
    Token t = make(TokenKind::Error, begin);
    uint32_t len = mPos - begin;
    if (len == 1 && c == '$') {
        t.text = "expected a variable name after '$'";
    } else if (len == 1) {
        t.text = "unexpected character '" + showByte(c) + "'";
        if (c == '&') t.text += " (did you mean '&&'?)";
        if (c == '|') t.text += " (did you mean '||'?)";
    } else {
        t.text = "unexpected characters '";
        for (uint32_t i = 0; i < len && i < 16; ++i) t.text += showByte(mText[begin + i]);
        if (len > 16) t.text += "...";
        t.text += "'";
    }
    mSink.error(t.span, t.text);
    return t;
}

Token Lexer::lexNumber() {
    const uint32_t begin = mPos;
    const size_t n = mText.size();
    while (mPos < n && isDigit(mText[mPos])) ++mPos;
    if (mPos < n && mText[mPos] == '.') {
        ++mPos;
        while (mPos < n && isDigit(mText[mPos])) ++mPos;
    }
    if (mPos < n && (mText[mPos] == 'e' || mText[mPos] == 'E')) {
        uint32_t p = mPos + 1;
        if (p < n && (mText[p] == '+' || mText[p] == '-')) ++p;
        if (p < n && isDigit(mText[p])) {
            mPos = p;
            while (mPos < n && isDigit(mText[mPos])) ++mPos;
        }
    }
    if (mPos < n && isNameChar(mText[mPos])) {
        // `2x`, `1.5.3`, `3e`: a number glued to a name is a mistake, not two tokens.
        while (mPos < n && isNameChar(mText[mPos])) ++mPos;
        Token t = make(TokenKind::Error, begin);
        t.text = "invalid number '" + mText.substr(begin, mPos - begin) + "'";
        mSink.error(t.span, t.text);
        return t;
    }

    Token t = make(TokenKind::Number, begin);
    const char* first = mText.data() + begin;
    const char* last = mText.data() + mPos;
    if (last - first <= 15) {
        // Fast path: a short integer is exact in a double.
        uint64_t v = 0;
        const char* p = first;
        while (p < last && isDigit(*p)) v = v * 10 + static_cast<uint64_t>(*p++ - '0');
        if (p == last) {
            t.number = static_cast<double>(v);
            return t;
        }
    }
    double value = 0.0;
    auto res = std::from_chars(first, last, value, std::chars_format::general);
    std::string_view spelling(first, static_cast<size_t>(last - first));
    if (res.ec == std::errc::result_out_of_range) {
        if (mantissaMagnitude(spelling) + exponentValue(spelling) > 0) {
            t.kind = TokenKind::Error;
            t.text = "number '" + std::string(spelling) + "' is too large";
            mSink.error(t.span, t.text);
            return t;
        }
        value = 0.0; // underflow: the nearest double is zero
    } else if (res.ec != std::errc() || res.ptr != last) {
        t.kind = TokenKind::Error;
        t.text = "invalid number '" + std::string(spelling) + "'";
        mSink.error(t.span, t.text);
        return t;
    }
    t.number = value;
    return t;
}

Token Lexer::lexName(bool dollar) {
    const uint32_t begin = mPos;
    const size_t n = mText.size();
    if (dollar) ++mPos;
    const uint32_t nameBegin = mPos;
    while (mPos < n && isNameChar(mText[mPos])) ++mPos;
    std::string_view name(mText.data() + nameBegin, mPos - nameBegin);
    TokenKind kind = TokenKind::Name;
    if (dollar) {
        kind = TokenKind::Variable;
    } else if (name == "if") {
        kind = TokenKind::KwIf;
    } else if (name == "else") {
        kind = TokenKind::KwElse;
    } else if (name == "def") {
        kind = TokenKind::KwDef;
    } else if (name == "extern") {
        kind = TokenKind::KwExtern;
    }
    Token t = make(kind, begin);
    t.text = std::string(name);
    return t;
}

Token Lexer::lexString(char quote) {
    const uint32_t begin = mPos;
    const size_t n = mText.size();
    ++mPos;
    std::string value;
    bool bad = false;
    for (;;) {
        if (mPos >= n || mText[mPos] == '\n') {
            uint32_t end = mPos;
            if (end > begin + 1 && mText[end - 1] == '\r') --end;
            Token t = make(TokenKind::Error, begin);
            t.span.end = end;
            t.text = std::string("unterminated string: missing closing ") +
                     (quote == '"' ? "'\"'" : "\"'\"");
            mSink.error(t.span, t.text);
            return t;
        }
        char c = mText[mPos];
        if (c == quote) {
            ++mPos;
            break;
        }
        if (c != '\\') {
            value += c;
            ++mPos;
            continue;
        }
        char e = mPos + 1 < n ? mText[mPos + 1] : '\0';
        switch (e) {
        case '"':
            value += '"';
            break;
        case '\'':
            value += '\'';
            break;
        case '\\':
            value += '\\';
            break;
        case 't':
            value += '\t';
            break;
        case 'n':
            value += '\n';
            break;
        case '\n':
        case '\0':
            if (mPos + 1 >= n || e == '\n') {
                ++mPos; // a backslash at the end of the line: the string is unterminated
                continue;
            }
            [[fallthrough]];
        default: {
            bad = true;
            std::string msg = "unknown escape sequence '\\" + showByte(e) +
                              "' in string (escapes are \\\" \\' \\\\ \\t \\n)";
            mSink.error(Span{mPos, mPos + 2}, msg);
            break;
        }
        }
        mPos += 2;
    }
    Token t = make(bad ? TokenKind::Error : TokenKind::String, begin);
    t.text = bad ? std::string("invalid string") : std::move(value);
    return t;
}

} // namespace gale::lang
