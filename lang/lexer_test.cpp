// Lexer tests: token sequences, number forms, names, variables, strings, comments, operators,
// and bad input (which must give one diagnostic per run of bad bytes and keep lexing).
#include "lang/lexer.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace gale::lang;

namespace {

struct Lexed {
    std::vector<Token> tokens; // including the final End
    DiagnosticSink sink;
};

Lexed lexAll(const std::string& text) {
    SourceFile file("t.se", text);
    Lexed out;
    Lexer lexer(file, out.sink);
    for (int i = 0; i < 1000000; ++i) {
        out.tokens.push_back(lexer.next());
        if (out.tokens.back().kind == TokenKind::End) break;
    }
    return out;
}

std::vector<TokenKind> kinds(const std::string& text) {
    std::vector<TokenKind> k;
    for (const Token& t : lexAll(text).tokens) k.push_back(t.kind);
    return k;
}

// The first diagnostic as "line:col: message".
std::string firstError(const std::string& text) {
    SourceFile file("t.se", text);
    Lexed l = lexAll(text);
    if (l.sink.diagnostics().empty()) return "";
    const Diagnostic& d = l.sink.diagnostics().front();
    LineCol lc = file.lineCol(d.span.begin);
    return std::to_string(lc.line) + ":" + std::to_string(lc.col) + ": " + d.message;
}

double numberOf(const std::string& text) {
    Lexed l = lexAll(text);
    REQUIRE(l.tokens.size() == 2);
    REQUIRE(l.tokens[0].kind == TokenKind::Number);
    REQUIRE_FALSE(l.sink.hasErrors());
    return l.tokens[0].number;
}

using K = TokenKind;

} // namespace

TEST_CASE("lexer: token sequence of a small program", "[lexer]") {
    auto k = kinds("x = $P[0] * 2.5; # comment\nif (x > 1) { x += 1; } else { x = 0; }\nx");
    std::vector<K> want = {K::Name,     K::Assign,    K::Variable,   K::LBracket,  K::Number,
                           K::RBracket, K::Star,      K::Number,     K::Semicolon, K::KwIf,
                           K::LParen,   K::Name,      K::Greater,    K::Number,    K::RParen,
                           K::LBrace,   K::Name,      K::PlusAssign, K::Number,    K::Semicolon,
                           K::RBrace,   K::KwElse,    K::LBrace,     K::Name,      K::Assign,
                           K::Number,   K::Semicolon, K::RBrace,     K::Name,      K::End};
    CHECK(k == want);
}

TEST_CASE("lexer: every operator token", "[lexer]") {
    auto k =
        kinds("-> <= >= == != && || += -= *= /= %= ^= = < > + - * / % ^ ! ~ ? : , ; ( ) [ ] { }");
    std::vector<K> want = {
        K::Arrow,       K::LessEq,        K::GreaterEq,   K::EqEq,        K::NotEq,
        K::AndAnd,      K::OrOr,          K::PlusAssign,  K::MinusAssign, K::StarAssign,
        K::SlashAssign, K::PercentAssign, K::CaretAssign, K::Assign,      K::Less,
        K::Greater,     K::Plus,          K::Minus,       K::Star,        K::Slash,
        K::Percent,     K::Caret,         K::Bang,        K::Tilde,       K::Question,
        K::Colon,       K::Comma,         K::Semicolon,   K::LParen,      K::RParen,
        K::LBracket,    K::RBracket,      K::LBrace,      K::RBrace,      K::End};
    CHECK(k == want);
    // Greedy: `a->b` is an arrow, `x--1` is two minuses, `a=-1` is assign then minus.
    CHECK(kinds("a->b") == std::vector<K>{K::Name, K::Arrow, K::Name, K::End});
    CHECK(kinds("x--1") == std::vector<K>{K::Name, K::Minus, K::Minus, K::Number, K::End});
    CHECK(kinds("a=-1") == std::vector<K>{K::Name, K::Assign, K::Minus, K::Number, K::End});
    CHECK(kinds("a===b") == std::vector<K>{K::Name, K::EqEq, K::Assign, K::Name, K::End});
}

TEST_CASE("lexer: number forms", "[lexer]") {
    CHECK(numberOf("12") == 12.0);
    CHECK(numberOf("1.5") == 1.5);
    CHECK(numberOf(".5") == 0.5);
    CHECK(numberOf("1.") == 1.0);
    CHECK(numberOf("2e-3") == 0.002);
    CHECK(numberOf("1E+4") == 10000.0);
    CHECK(numberOf("1e4") == 10000.0);
    CHECK(numberOf("1.e2") == 100.0);
    CHECK(numberOf("0.1") == 0.1);
    CHECK(numberOf("007") == 7.0);
    CHECK(numberOf("1e-999") == 0.0); // underflow is zero, not an error
    CHECK(numberOf("0e999") == 0.0);
    CHECK(numberOf("1.7976931348623157e308") == 1.7976931348623157e308);
    CHECK(numberOf("123456789012345") == 123456789012345.0);
    CHECK(numberOf("1234567890123456789") == 1234567890123456789.0);
    CHECK(numberOf("9007199254740993") == 9007199254740992.0); // rounds to nearest
    // The span covers the spelling.
    CHECK(lexAll("  2.50").tokens[0].span.begin == 2);
    CHECK(lexAll("  2.50").tokens[0].span.end == 6);
    // No sign in a literal.
    CHECK(kinds("-1") == std::vector<K>{K::Minus, K::Number, K::End});
    // `1.x`-style glue and a trailing dot followed by a digit.
    CHECK(kinds("1..5").front() == K::Error);
}

TEST_CASE("lexer: malformed numbers", "[lexer]") {
    CHECK(firstError("1e999") == "1:1: number '1e999' is too large");
    CHECK(firstError("x + 2x") == "1:5: invalid number '2x'");
    CHECK(firstError("1.5.3") == "1:1: invalid number '1.5.3'");
    CHECK(firstError("3e") == "1:1: invalid number '3e'");
    CHECK(firstError("0x1F") == "1:1: invalid number '0x1F'");
    auto l = lexAll("2x + 1");
    REQUIRE(l.tokens.size() == 4);
    CHECK(l.tokens[0].kind == K::Error);
    CHECK(l.tokens[0].span.begin == 0);
    CHECK(l.tokens[0].span.end == 2);
    CHECK(l.tokens[1].kind == K::Plus);
    CHECK(l.sink.errorCount() == 1);
}

TEST_CASE("lexer: names, keywords and variables", "[lexer]") {
    auto l = lexAll("wind.speed _a1 $P $wind.dir if else def extern iff");
    REQUIRE(l.tokens.size() == 10);
    CHECK(l.tokens[0].kind == K::Name);
    CHECK(l.tokens[0].text == "wind.speed");
    CHECK(l.tokens[1].text == "_a1");
    CHECK(l.tokens[2].kind == K::Variable);
    CHECK(l.tokens[2].text == "P");
    CHECK(l.tokens[2].span.begin == 15);
    CHECK(l.tokens[2].span.end == 17);
    CHECK(l.tokens[3].kind == K::Variable);
    CHECK(l.tokens[3].text == "wind.dir");
    CHECK(l.tokens[4].kind == K::KwIf);
    CHECK(l.tokens[5].kind == K::KwElse);
    CHECK(l.tokens[6].kind == K::KwDef);
    CHECK(l.tokens[7].kind == K::KwExtern);
    CHECK(l.tokens[8].kind == K::Name);
    CHECK(l.tokens[8].text == "iff");
    CHECK_FALSE(l.sink.hasErrors());

    CHECK(isReservedWord("if"));
    CHECK(isReservedWord("else"));
    CHECK(isReservedWord("def"));
    CHECK(isReservedWord("extern"));
    CHECK_FALSE(isReservedWord("PI"));
    CHECK_FALSE(isReservedWord("If"));
}

TEST_CASE("lexer: a '$' without a name", "[lexer]") {
    CHECK(firstError("$ + 1") == "1:1: expected a variable name after '$'");
    CHECK(firstError("1 + $1") == "1:5: expected a variable name after '$'");
    auto l = lexAll("$$$ x");
    CHECK(l.sink.errorCount() == 1); // one run
    CHECK(l.tokens[1].kind == K::Name);
}

TEST_CASE("lexer: strings and escapes", "[lexer]") {
    auto l = lexAll(R"("a\"b" 'c\'d' "\\\t\n" 'say "hi"' "it's")");
    REQUIRE(l.tokens.size() == 6);
    CHECK(l.tokens[0].kind == K::String);
    CHECK(l.tokens[0].text == "a\"b");
    CHECK(l.tokens[1].text == "c'd");
    CHECK(l.tokens[2].text == "\\\t\n");
    CHECK(l.tokens[3].text == "say \"hi\"");
    CHECK(l.tokens[4].text == "it's");
    CHECK(l.tokens[0].span.begin == 0);
    CHECK(l.tokens[0].span.end == 6);
    CHECK_FALSE(l.sink.hasErrors());

    CHECK(firstError(R"(x = "a\qb")") == "1:7: unknown escape sequence '\\q' in string "
                                         "(escapes are \\\" \\' \\\\ \\t \\n)");
    CHECK(firstError("x = \"abc\ny") == "1:5: unterminated string: missing closing '\"'");
    CHECK(firstError("x = 'abc") == "1:5: unterminated string: missing closing \"'\"");
    CHECK(firstError("\"abc\\") == "1:1: unterminated string: missing closing '\"'");
    // Lexing continues on the next line after an unterminated string.
    auto u = lexAll("'abc\n7");
    REQUIRE(u.tokens.size() == 3);
    CHECK(u.tokens[0].kind == K::Error);
    CHECK(u.tokens[1].kind == K::Number);
    CHECK(u.sink.errorCount() == 1);
}

TEST_CASE("lexer: comments and whitespace", "[lexer]") {
    CHECK(kinds("# all comment") == std::vector<K>{K::End});
    CHECK(kinds("1 # one\n# two\n\t2\r\n") == std::vector<K>{K::Number, K::Number, K::End});
    CHECK(kinds("") == std::vector<K>{K::End});
    CHECK(kinds("a#b\nc") == std::vector<K>{K::Name, K::Name, K::End});
}

TEST_CASE("lexer: End repeats forever", "[lexer]") {
    SourceFile file("t.se", "x");
    DiagnosticSink sink;
    Lexer lexer(file, sink);
    CHECK(lexer.next().kind == K::Name);
    for (int i = 0; i < 5; ++i) {
        Token t = lexer.next();
        CHECK(t.kind == K::End);
        CHECK(t.span.begin == 1);
    }
}

TEST_CASE("lexer: bad characters", "[lexer]") {
    CHECK(firstError("1 @ 2") == "1:3: unexpected character '@'");
    CHECK(firstError("a\x01") == "1:2: unexpected character '\\x01'");
    CHECK(firstError(std::string("a\0b", 3)) == "1:2: unexpected character '\\x00'");
    CHECK(firstError("x & y") == "1:3: unexpected character '&' (did you mean '&&'?)");
    CHECK(firstError("x | y") == "1:3: unexpected character '|' (did you mean '||'?)");
    CHECK(firstError("a . b") == "1:3: unexpected character '.'");
    CHECK(firstError("`") == "1:1: unexpected character '`'");
    // One error per run; lexing continues after it.
    auto l = lexAll("1 @@\x7f` 2 \xc3\xa9 3");
    CHECK(l.sink.errorCount() == 2);
    CHECK(l.sink.diagnostics()[0].message == "unexpected characters '@@\\x7f`'");
    CHECK(l.sink.diagnostics()[1].message == "unexpected characters '\\xc3\\xa9'");
    std::vector<K> want = {K::Number, K::Error, K::Number, K::Error, K::Number, K::End};
    CHECK(kinds("1 @@\x7f` 2 \xc3\xa9 3") == want);
}

TEST_CASE("lexer: all 256 byte values", "[lexer]") {
    std::string text;
    for (int rep = 0; rep < 4; ++rep)
        for (int b = 0; b < 256; ++b) text += static_cast<char>(b);
    auto l = lexAll(text);
    CHECK(l.tokens.back().kind == K::End);
    CHECK(l.sink.hasErrors());
    CHECK(l.sink.errorCount() <= DiagnosticSink::kMaxErrors + 1);
}

TEST_CASE("lexer: token kind names", "[lexer]") {
    CHECK(std::string(tokenKindName(K::End)) == "end of input");
    CHECK(std::string(tokenKindName(K::Semicolon)) == "';'");
    CHECK(std::string(tokenKindName(K::Arrow)) == "'->'");
    CHECK(std::string(tokenKindName(K::CaretAssign)) == "'^='");
    CHECK(std::string(tokenKindName(K::KwIf)) == "'if'");
}
