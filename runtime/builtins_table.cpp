// The built-in function table: the standard library built once from the builtins_*.cpp
// families, name lookup for the compiler, and signature parsing when entries are added.
#include "runtime/builtins.h"

namespace gale::runtime {

std::shared_ptr<const FunctionTable> FunctionTable::standard() {
    static const std::shared_ptr<const FunctionTable> table = [] {
        auto t = std::make_shared<FunctionTable>();
        addMathBuiltins(*t);
        addCurveBuiltins(*t);
        addStringBuiltins(*t);
        addNoiseBuiltins(*t);
        return std::shared_ptr<const FunctionTable>(std::move(t));
    }();
    return table;
}

bool FunctionTable::add(Builtin b, std::string* error) {
    if (!lang::parseSignature(b.info.signature, b.info.parsed, error)) return false;
    for (Builtin& existing : mBuiltins) {
        if (existing.info.name == b.info.name) {
            existing = std::move(b);
            return true;
        }
    }
    mBuiltins.push_back(std::move(b));
    return true;
}

const lang::FunctionInfo* FunctionTable::findFunction(std::string_view name, int32_t* index) const {
    for (size_t i = 0; i < mBuiltins.size(); ++i) {
        if (mBuiltins[i].info.name == name) {
            if (index) *index = static_cast<int32_t>(i);
            return &mBuiltins[i].info;
        }
    }
    return nullptr;
}

std::vector<std::string_view> FunctionTable::functionNames() const {
    std::vector<std::string_view> names;
    names.reserve(mBuiltins.size());
    for (const Builtin& b : mBuiltins) names.push_back(b.info.name);
    return names;
}

} // namespace gale::runtime
