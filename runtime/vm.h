// The VM's inner loop: executes one instruction over every lane of a block (or once, for
// uniform work), reading registers through their layout. Internal to the runtime.
#pragma once

#include "runtime/program.h"

#include <string>
#include <vector>

namespace gale::runtime {

// Register storage for one pass over one block, and how to find each register in it.
template <class T>
struct ExecContext {
    const lang::Bytecode* bc = nullptr;
    const FunctionTable* functions = nullptr;
    // Evaluation: registers are found through the program's layout.
    const RegLocation* locations = nullptr;
    const T* constants = nullptr;
    T* uniform = nullptr;
    T* varying = nullptr;
    const std::string* constStrings = nullptr;
    std::string* uniformStrings = nullptr;
    std::string* varyingStrings = nullptr;
    // Folding (locations == null): operands are constants read from `bc`, and the result goes
    // to foldOut / foldString.
    T* foldOut = nullptr;
    std::string* foldString = nullptr;

    int n = 1; // lanes in this pass
    std::string* messages = nullptr;
    std::vector<Operand<T>> scratch;

    Operand<T> operand(lang::Reg r) const;
    // Destination of an instruction: where component k of lane i goes is out[k*stride + i].
    T* out(const lang::Instr& in, int& compStride) const;
    std::string* outString(const lang::Instr& in) const;
};

template <class T>
void execute(const lang::Instr& in, ExecContext<T>& ctx);

extern template void execute<float>(const lang::Instr&, ExecContext<float>&);
extern template void execute<double>(const lang::Instr&, ExecContext<double>&);

} // namespace gale::runtime
