// Line-start index of a SourceFile, for turning byte offsets into line:column.
#include "lang/source.h"

#include <algorithm>

namespace gale::lang {

SourceFile::SourceFile(std::string name, std::string text)
    : mName(std::move(name)), mText(std::move(text)) {
    mLineStarts.push_back(0);
    for (uint32_t i = 0; i < mText.size(); ++i)
        if (mText[i] == '\n') mLineStarts.push_back(i + 1);
}

LineCol SourceFile::lineCol(uint32_t offset) const {
    if (offset > mText.size()) offset = static_cast<uint32_t>(mText.size());
    auto it = std::upper_bound(mLineStarts.begin(), mLineStarts.end(), offset);
    uint32_t line = static_cast<uint32_t>(it - mLineStarts.begin());
    return {line, offset - mLineStarts[line - 1] + 1};
}

std::string_view SourceFile::lineText(uint32_t line) const {
    if (line == 0 || line > mLineStarts.size()) return {};
    uint32_t b = mLineStarts[line - 1];
    uint32_t e = line < mLineStarts.size() ? mLineStarts[line] - 1 : static_cast<uint32_t>(mText.size());
    if (e > b && mText[e - 1] == '\r') --e;
    return std::string_view(mText).substr(b, e - b);
}

} // namespace gale::lang
