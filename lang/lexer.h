// Streaming lexer: turns source text into tokens on demand, reporting bad characters,
// unterminated strings and malformed numbers as diagnostics (an Error token, never a throw).
#pragma once

#include "lang/diagnostics.h"
#include "lang/token.h"

namespace gale::lang {

class Lexer {
public:
    Lexer(const SourceFile& file, DiagnosticSink& sink);

    // The next token; End forever once the input is exhausted.
    Token next();

private:
    void skipSpaceAndComments();
    Token lexNumber();
    Token lexName(bool dollar);
    Token lexString(char quote);
    Token make(TokenKind kind, uint32_t begin);

    const std::string& mText;
    DiagnosticSink& mSink;
    uint32_t mPos = 0;
};

bool isReservedWord(std::string_view name);

} // namespace gale::lang
