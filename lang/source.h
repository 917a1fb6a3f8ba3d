// Source text with a name, byte-offset spans into it, and line/column lookup for diagnostics.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace gale::lang {

// A half-open byte range [begin, end) in one SourceFile.
struct Span {
    uint32_t begin = 0;
    uint32_t end = 0;

    static Span merge(Span a, Span b) { return {a.begin < b.begin ? a.begin : b.begin, a.end > b.end ? a.end : b.end}; }
    uint32_t size() const { return end - begin; }
};

// 1-based line and column; columns count bytes.
struct LineCol {
    uint32_t line = 1;
    uint32_t col = 1;
};

class SourceFile {
public:
    SourceFile() = default;
    SourceFile(std::string name, std::string text);

    const std::string& name() const { return mName; }
    const std::string& text() const { return mText; }

    LineCol lineCol(uint32_t offset) const;
    // The text of 1-based line `line`, without its newline.
    std::string_view lineText(uint32_t line) const;
    uint32_t lineCount() const { return static_cast<uint32_t>(mLineStarts.size()); }

private:
    std::string mName;
    std::string mText;
    std::vector<uint32_t> mLineStarts;
};

} // namespace gale::lang
