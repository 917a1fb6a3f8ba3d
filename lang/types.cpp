// Names and combination rules of value types.
#include "lang/types.h"

namespace gale::lang {

const char* lifetimeName(Lifetime l) {
    switch (l) {
    case Lifetime::Constant: return "constant";
    case Lifetime::Uniform: return "uniform";
    case Lifetime::Varying: return "varying";
    }
    return "?";
}

std::string typeName(const Type& t) {
    switch (t.kind) {
    case TypeKind::Float: return "FP[" + std::to_string(t.width) + "]";
    case TypeKind::String: return "STRING";
    case TypeKind::Error: return "<error>";
    }
    return "?";
}

std::string typeNameWithLifetime(const Type& t) { return typeName(t) + " " + lifetimeName(t.lifetime); }

int broadcastWidth(int a, int b) {
    if (a == b) return a;
    if (a == 1) return b;
    if (b == 1) return a;
    return 0;
}

} // namespace gale::lang
