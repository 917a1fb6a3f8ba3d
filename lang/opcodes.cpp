// Opcode names, shapes and docs generated from GALE_OPCODES, and the disassembler.
#include "lang/bytecode.h"

#include <cstdio>

namespace gale::lang {

namespace {
struct OpRow {
    const char* name;
    OpShape shape;
    const char* doc;
};
constexpr OpRow kOps[] = {
#define GALE_X(name, shape, doc) {#name, OpShape::shape, doc},
    GALE_OPCODES(GALE_X)
#undef GALE_X
};
static_assert(sizeof(kOps) / sizeof(kOps[0]) == kOpCount, "one row per opcode");
} // namespace

const char* opName(Op op) { return kOps[static_cast<int>(op)].name; }
OpShape opShape(Op op) { return kOps[static_cast<int>(op)].shape; }
const char* opDoc(Op op) { return kOps[static_cast<int>(op)].doc; }

double Bytecode::constant(Reg r, int k) const {
    const RegInfo& info = reg(r);
    if (info.aliasOf != kNoReg) return constant(info.aliasOf, info.component);
    return constants[static_cast<size_t>(info.constIndex + (info.width == 1 ? 0 : k))];
}

const std::string& Bytecode::constantString(Reg r) const { return strings[static_cast<size_t>(reg(r).constIndex)]; }

namespace {

std::string regText(const Bytecode& bc, Reg r) {
    if (r == kNoReg) return "-";
    const RegInfo& info = bc.reg(r);
    char buf[96];
    if (info.lifetime == Lifetime::Constant && info.aliasOf == kNoReg && info.constIndex >= 0) {
        if (info.kind == TypeKind::String) {
            std::string s = "\"" + bc.strings[static_cast<size_t>(info.constIndex)] + "\"";
            return s.size() > 24 ? s.substr(0, 21) + "...\"" : s;
        }
        std::string s = "k" + std::to_string(r) + "(";
        for (int k = 0; k < info.width; ++k) {
            std::snprintf(buf, sizeof buf, "%s%.9g", k ? "," : "", bc.constants[static_cast<size_t>(info.constIndex + k)]);
            s += buf;
            if (k == 3 && info.width > 5) { s += ",..."; break; }
        }
        return s + ")";
    }
    const char lt = info.lifetime == Lifetime::Varying ? 'v' : info.lifetime == Lifetime::Uniform ? 'u' : 'c';
    std::string s = (info.kind == TypeKind::String ? "s" : "r") + std::to_string(r);
    if (info.aliasOf != kNoReg) s += "=" + regText(bc, info.aliasOf) + "[" + std::to_string(info.component) + "]";
    std::snprintf(buf, sizeof buf, ":%s%c", info.kind == TypeKind::String ? "S" : ("" + std::to_string(info.width)).c_str(), lt);
    s += buf;
    if (info.input >= 0) s += "($" + bc.inputs[static_cast<size_t>(info.input)].name + ")";
    return s;
}

} // namespace

std::string disassemble(const Bytecode& bc, const char* (*functionName)(int32_t, const void*), const void* user) {
    std::string out;
    char buf[64];
    for (size_t i = 0; i < bc.code.size(); ++i) {
        const Instr& in = bc.code[i];
        std::snprintf(buf, sizeof buf, "%4zu  %-9s ", i, opName(in.op));
        std::string line = buf + regText(bc, in.dst) + " = ";
        switch (opShape(in.op)) {
        case OpShape::Unary: line += regText(bc, in.a); break;
        case OpShape::Binary: line += regText(bc, in.a) + ", " + regText(bc, in.b); break;
        case OpShape::Ternary: line += regText(bc, in.a) + ", " + regText(bc, in.b) + ", " + regText(bc, in.c); break;
        case OpShape::List:
        case OpShape::Call:
            if (in.op == Op::Call)
                line += std::string(functionName ? functionName(in.imm, user) : ("fn" + std::to_string(in.imm)).c_str());
            line += "(";
            for (int32_t k = 0; k < in.argCount; ++k)
                line += (k ? ", " : "") + regText(bc, bc.args[static_cast<size_t>(in.argBegin + k)]);
            line += ")";
            if (in.mask != kNoReg) line += " if " + regText(bc, in.mask);
            break;
        }
        if (line.size() < 56) line.resize(56, ' ');
        out += line + "  ; " + opDoc(in.op) + "\n";
    }
    out += "result: " + regText(bc, bc.result) + " " + typeNameWithLifetime(bc.resultType) + "\n";
    return out;
}

} // namespace gale::lang
