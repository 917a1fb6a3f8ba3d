// Tokens of the expression language.
#pragma once

#include "lang/source.h"

#include <cstdint>
#include <string>

namespace gale::lang {

#define GALE_TOKEN_KINDS(X)                                                                        \
    X(End, "end of input")                                                                         \
    X(Error, "invalid token")                                                                      \
    X(Number, "number")                                                                            \
    X(String, "string")                                                                            \
    X(Name, "name")                                                                                \
    X(Variable, "$variable")                                                                       \
    X(KwIf, "'if'")                                                                                \
    X(KwElse, "'else'")                                                                            \
    X(KwDef, "'def'")                                                                              \
    X(KwExtern, "'extern'")                                                                        \
    X(LParen, "'('")                                                                               \
    X(RParen, "')'")                                                                               \
    X(LBrace, "'{'")                                                                               \
    X(RBrace, "'}'")                                                                               \
    X(LBracket, "'['")                                                                             \
    X(RBracket, "']'")                                                                             \
    X(Comma, "','")                                                                                \
    X(Semicolon, "';'")                                                                            \
    X(Question, "'?'")                                                                             \
    X(Colon, "':'")                                                                                \
    X(Arrow, "'->'")                                                                               \
    X(Plus, "'+'")                                                                                 \
    X(Minus, "'-'")                                                                                \
    X(Star, "'*'")                                                                                 \
    X(Slash, "'/'")                                                                                \
    X(Percent, "'%'")                                                                              \
    X(Caret, "'^'")                                                                                \
    X(Bang, "'!'")                                                                                 \
    X(Tilde, "'~'")                                                                                \
    X(Less, "'<'")                                                                                 \
    X(Greater, "'>'")                                                                              \
    X(LessEq, "'<='")                                                                              \
    X(GreaterEq, "'>='")                                                                           \
    X(EqEq, "'=='")                                                                                \
    X(NotEq, "'!='")                                                                               \
    X(AndAnd, "'&&'")                                                                              \
    X(OrOr, "'||'")                                                                                \
    X(Assign, "'='")                                                                               \
    X(PlusAssign, "'+='")                                                                          \
    X(MinusAssign, "'-='")                                                                         \
    X(StarAssign, "'*='")                                                                          \
    X(SlashAssign, "'/='")                                                                         \
    X(PercentAssign, "'%='")                                                                       \
    X(CaretAssign, "'^='")

enum class TokenKind : uint8_t {
#define GALE_X(name, text) name,
    GALE_TOKEN_KINDS(GALE_X)
#undef GALE_X
};

const char* tokenKindName(TokenKind kind);

struct Token {
    TokenKind kind = TokenKind::End;
    Span span;
    double number = 0.0; // Number
    std::string text;    // Name / Variable (without '$') / String (escapes decoded) / Error message
};

} // namespace gale::lang
