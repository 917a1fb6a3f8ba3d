// The VM's instruction set, defined once. The enum, names, operand shapes, docs, the
// disassembler and the VM's dispatch switch are all generated from GALE_OPCODES.
// Notation (Lua style): r[x] is a numeric register (all its components, a scalar operand is
// broadcast), s[x] a string register, r[x][0] its first component.
#pragma once

#include <cstdint>

namespace gale::lang {

// Operand shapes, for the disassembler and the verifier.
enum class OpShape : uint8_t {
    Unary,   // d, a
    Binary,  // d, a, b
    Ternary, // d, a, b, c
    List,    // d, args...
    Call,    // d, imm = function, args...
};

// X(name, shape, doc)
#define GALE_OPCODES(X)                                                                            \
    X(Copy, Unary, "r[d] = r[a]  (a scalar a fills every component of d)")                         \
    X(Neg, Unary, "r[d] = -r[a]")                                                                  \
    X(Invert, Unary, "r[d] = 1 - r[a]")                                                            \
    X(Not, Unary, "r[d] = r[a][0] == 0")                                                           \
    X(Add, Binary, "r[d] = r[a] + r[b]")                                                           \
    X(Sub, Binary, "r[d] = r[a] - r[b]")                                                           \
    X(Mul, Binary, "r[d] = r[a] * r[b]")                                                           \
    X(Div, Binary, "r[d] = r[a] / r[b]")                                                           \
    X(Mod, Binary, "r[d] = r[a] - floor(r[a] / r[b]) * r[b];  0 where r[b] == 0")                  \
    X(Pow, Binary, "r[d] = pow(r[a], r[b])")                                                       \
    X(Lt, Binary, "r[d] = r[a][0] < r[b][0]")                                                      \
    X(Gt, Binary, "r[d] = r[a][0] > r[b][0]")                                                      \
    X(Le, Binary, "r[d] = r[a][0] <= r[b][0]")                                                     \
    X(Ge, Binary, "r[d] = r[a][0] >= r[b][0]")                                                     \
    X(Eq, Binary, "r[d] = all(r[a] == r[b])")                                                      \
    X(Ne, Binary, "r[d] = any(r[a] != r[b])")                                                      \
    X(And, Binary, "r[d] = r[a][0] != 0 && r[b][0] != 0")                                          \
    X(Or, Binary, "r[d] = r[a][0] != 0 || r[b][0] != 0")                                           \
    X(Select, Ternary, "r[d] = r[a][0] != 0 ? r[b] : r[c]")                                        \
    X(Index, Binary, "r[d] = r[a][int(r[b][0])];  0 when the index is out of range")               \
    X(Pack, List, "r[d] = [r[args[0]][0], r[args[1]][0], ...]")                                    \
    X(Call, Call, "r[d] = fn[imm](r[args[0]], r[args[1]], ...)")                                   \
    X(StrCat, Binary, "s[d] = s[a] .. s[b]")                                                       \
    X(StrEq, Binary, "r[d] = s[a] == s[b]")                                                        \
    X(StrNe, Binary, "r[d] = s[a] != s[b]")                                                        \
    X(StrSelect, Ternary, "s[d] = r[a][0] != 0 ? s[b] : s[c]")

enum class Op : uint8_t {
#define GALE_X(name, shape, doc) name,
    GALE_OPCODES(GALE_X)
#undef GALE_X
};

constexpr int kOpCount = 0
#define GALE_X(name, shape, doc) +1
    GALE_OPCODES(GALE_X)
#undef GALE_X
    ;

const char* opName(Op op);
OpShape opShape(Op op);
const char* opDoc(Op op);

} // namespace gale::lang
