// Value types of the language — FP[n] (n = 1..16) and STRING — with SeExpr2's lifetimes
// (constant < uniform < varying), and the rules that combine them.
#pragma once

#include <cstdint>
#include <string>

namespace gale::lang {

constexpr int kMaxWidth = 16;

// Ordered so that combining two lifetimes takes the larger (the weaker guarantee).
enum class Lifetime : uint8_t { Constant = 0, Uniform = 1, Varying = 2 };

inline Lifetime combine(Lifetime a, Lifetime b) { return a > b ? a : b; }
const char* lifetimeName(Lifetime l);

enum class TypeKind : uint8_t {
    Float,  // FP[width]
    String,
    Error,  // a sub-expression that already produced a diagnostic: suppresses cascades
};

struct Type {
    TypeKind kind = TypeKind::Error;
    uint8_t width = 1;
    Lifetime lifetime = Lifetime::Varying;

    static Type fp(int width, Lifetime l = Lifetime::Varying) { return {TypeKind::Float, static_cast<uint8_t>(width), l}; }
    static Type string(Lifetime l = Lifetime::Constant) { return {TypeKind::String, 1, l}; }
    static Type error() { return {TypeKind::Error, 1, Lifetime::Constant}; }

    bool isFloat() const { return kind == TypeKind::Float; }
    bool isString() const { return kind == TypeKind::String; }
    bool isError() const { return kind == TypeKind::Error; }
    bool isScalar() const { return kind == TypeKind::Float && width == 1; }

    Type withLifetime(Lifetime l) const { Type t = *this; t.lifetime = l; return t; }
    Type withWidth(int w) const { Type t = *this; t.width = static_cast<uint8_t>(w); return t; }

    // Same kind and width (lifetimes ignored).
    bool sameShape(const Type& o) const { return kind == o.kind && (kind != TypeKind::Float || width == o.width); }
};

// "FP[3]", "FP[1]", "STRING" — as diagnostics print types.
std::string typeName(const Type& t);
// "FP[3] varying"
std::string typeNameWithLifetime(const Type& t);

// Width after broadcasting FP[a] with FP[b]: the larger if one is 1 or both equal, else 0.
int broadcastWidth(int a, int b);

} // namespace gale::lang
