// A compiled program: typed registers with lifetimes, straight-line instructions over them,
// constants, and the host inputs it reads. Produced by the compiler, run by runtime::Vm.
#pragma once

#include "lang/opcodes.h"
#include "lang/source.h"
#include "lang/types.h"

#include <string>
#include <vector>

namespace gale::lang {

using Reg = int32_t;
constexpr Reg kNoReg = -1;

struct RegInfo {
    TypeKind kind = TypeKind::Float; // Float or String
    uint8_t width = 1;
    Lifetime lifetime = Lifetime::Varying;
    // Constant registers: index of the first component in Bytecode::constants (floats) or of
    // the string in Bytecode::strings. -1 otherwise.
    int32_t constIndex = -1;
    // A width-1 view of component `component` of register `aliasOf` (no storage of its own).
    Reg aliasOf = kNoReg;
    uint8_t component = 0;
    // Host input index (Bytecode::inputs) when the host fills this register, else -1.
    int32_t input = -1;
};

struct Instr {
    Op op = Op::Copy;
    uint8_t width = 1; // width of the destination
    Reg dst = kNoReg;
    Reg a = kNoReg, b = kNoReg, c = kNoReg;
    int32_t imm = 0;           // Call: function index in the FunctionScope used to compile
    int32_t argBegin = 0;      // List / Call: first operand in Bytecode::args
    int32_t argCount = 0;
    Reg mask = kNoReg;         // Call of a side-effecting function: lanes where it runs
    bool sideEffects = false;  // never removed, folded or hoisted (printf)
    Span span;                 // source of the operation (runtime diagnostics)
};

// A variable the host provides: `$P`, `$t`, a --set parameter, an input column.
struct HostInput {
    std::string name;
    Type type; // width and lifetime as bound
    Reg reg = kNoReg;
};

struct Bytecode {
    std::vector<RegInfo> regs;
    std::vector<Instr> code;
    std::vector<Reg> args;
    std::vector<double> constants;
    std::vector<std::string> strings;
    std::vector<HostInput> inputs;
    Reg result = kNoReg;
    Type resultType = Type::error();

    Reg addReg(const RegInfo& info) {
        regs.push_back(info);
        return static_cast<Reg>(regs.size() - 1);
    }
    const RegInfo& reg(Reg r) const { return regs[static_cast<size_t>(r)]; }
    bool isConstant(Reg r) const { return reg(r).lifetime == Lifetime::Constant; }
    // Value of component k of a constant float register (a width-1 register broadcasts).
    double constant(Reg r, int k = 0) const;
    const std::string& constantString(Reg r) const;
};

// One line per instruction: `  12  Add     r7:FP[3]v = r3, r5      ; r[d] = r[a] + r[b]`.
// `functionName` maps a Call's imm to a name (may be null).
std::string disassemble(const Bytecode& bc, const char* (*functionName)(int32_t, const void*) = nullptr,
                        const void* user = nullptr);

} // namespace gale::lang
