// Compile pipeline (parse, check, fold with the VM's own kernels, lay out registers) and
// evaluation over blocks: uniform work once per call, varying work per block, blocks split
// over TBB threads with results that do not depend on the thread count.
#include "runtime/program.h"

#include "lang/parser.h"
#include "runtime/vm.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <thread>

namespace gale::runtime {

using lang::Lifetime;
using lang::Reg;

std::vector<lang::HostVariable> standardVariables() {
    return {
        {"P", lang::Type::fp(3, Lifetime::Varying)},   {"t", lang::Type::fp(1, Lifetime::Uniform)},
        {"frame", lang::Type::fp(1, Lifetime::Uniform)}, {"fps", lang::Type::fp(1, Lifetime::Uniform)},
        {"id", lang::Type::fp(1, Lifetime::Varying)},
    };
}

namespace {

// Folds an instruction whose operands are constants by running it, in double, through the
// same exec functions the VM uses.
class VmFolder : public lang::ConstantFolder {
public:
    explicit VmFolder(const FunctionTable& functions) : mFunctions(functions) {}

    bool fold(const lang::Bytecode& bc, const lang::Instr& instr, std::vector<double>& values,
              std::string& text) const override {
        ExecContext<double> ctx;
        ctx.bc = &bc;
        ctx.functions = &mFunctions;
        ctx.constants = bc.constants.data();
        double out[lang::kMaxWidth] = {};
        ctx.foldOut = out;
        ctx.foldString = &text;
        ctx.n = 1;
        std::string messages;
        ctx.messages = &messages;
        lang::Instr in = instr;
        in.dst = lang::kNoReg; // the result goes to foldOut / foldString
        if (in.op == lang::Op::Call) {
            const Builtin& fn = mFunctions.at(in.imm);
            if (!fn.kernelD || fn.info.sideEffects || !fn.info.foldable) return false;
        }
        execute(in, ctx);
        values.assign(out, out + std::max<int>(1, in.width));
        return true;
    }

private:
    const FunctionTable& mFunctions;
};

const char* functionNameOf(int32_t index, const void* table) {
    const auto* t = static_cast<const FunctionTable*>(table);
    return index >= 0 && static_cast<size_t>(index) < t->size() ? t->at(index).info.name.data() : "?";
}

} // namespace

std::shared_ptr<const Program> Program::compile(const lang::SourceFile& source, const CompileSettings& settings,
                                                lang::DiagnosticSink& sink) {
    std::unique_ptr<lang::Ast> ast = lang::parseProgram(source, sink);
    if (sink.hasErrors() || !ast) return nullptr; // syntax errors only: no cascades
    auto program = std::shared_ptr<Program>(new Program());
    program->mFunctions = settings.functions ? settings.functions : FunctionTable::standard();
    VmFolder folder(*program->mFunctions);
    lang::CompileOptions opt;
    opt.variables = settings.variables;
    opt.functions = program->mFunctions.get();
    opt.folder = settings.fold ? &folder : nullptr;
    opt.wantWidth = settings.wantWidth;
    std::optional<lang::Bytecode> bc = lang::compile(*ast, opt, sink);
    if (!bc) return nullptr;
    program->mBytecode = std::move(*bc);
    program->layout();
    return program;
}

std::string Program::disassemble() const {
    return lang::disassemble(mBytecode, &functionNameOf, mFunctions.get());
}

void Program::layout() {
    const auto& regs = mBytecode.regs;
    mLocations.assign(regs.size(), RegLocation{});
    std::vector<char> placed(regs.size(), 0);
    // Registers that need storage: inputs, instruction destinations, and the result.
    auto place = [&](Reg r) {
        if (r == lang::kNoReg || placed[static_cast<size_t>(r)]) return;
        const lang::RegInfo& info = regs[static_cast<size_t>(r)];
        RegLocation& L = mLocations[static_cast<size_t>(r)];
        L.isString = info.kind == lang::TypeKind::String;
        placed[static_cast<size_t>(r)] = 1;
        if (info.aliasOf != lang::kNoReg) return; // resolved below
        if (info.lifetime == Lifetime::Constant && info.constIndex >= 0) {
            L.area = RegLocation::Constant;
            L.offset = info.constIndex;
            L.compStride = 1;
        } else if (info.lifetime != Lifetime::Varying) {
            L.area = RegLocation::Uniform;
            L.compStride = 1;
            if (L.isString) L.offset = static_cast<int32_t>(mUniformStrings++);
            else {
                L.offset = static_cast<int32_t>(mUniformSize);
                mUniformSize += info.width;
            }
        } else {
            L.area = RegLocation::Varying;
            L.compStride = kBlockSize;
            if (L.isString) L.offset = static_cast<int32_t>(mVaryingStrings++ * kBlockSize);
            else {
                L.offset = static_cast<int32_t>(mVaryingSize);
                mVaryingSize += static_cast<size_t>(info.width) * kBlockSize;
            }
        }
    };
    for (size_t r = 0; r < regs.size(); ++r)
        if (regs[r].aliasOf == lang::kNoReg) place(static_cast<Reg>(r));
    for (size_t r = 0; r < regs.size(); ++r) {
        const lang::RegInfo& info = regs[r];
        if (info.aliasOf == lang::kNoReg) continue;
        const RegLocation& base = mLocations[static_cast<size_t>(info.aliasOf)];
        RegLocation& L = mLocations[r];
        L = base;
        L.offset = base.offset + info.component * base.compStride;
    }
    for (size_t i = 0; i < mBytecode.code.size(); ++i) {
        const lang::RegInfo& d = regs[static_cast<size_t>(mBytecode.code[i].dst)];
        (d.lifetime == Lifetime::Varying ? mVaryingCode : mUniformCode).push_back(static_cast<int32_t>(i));
    }
}

// ---------------------------------------------------------------------------------------------
// Evaluation

namespace {

template <class T>
struct ThreadState {
    std::vector<T> varying;
    std::vector<std::string> varyingStrings;
    ExecContext<T> ctx;
};

} // namespace

template <class T>
EvalResult evaluate(const Program& program, const EvalRequest& request, const EvalOutput<T>& out) {
    EvalResult result;
    const lang::Bytecode& bc = program.bytecode();
    const auto& locs = program.locations();

    // Resolve host inputs.
    struct VaryingBind {
        Reg reg;
        int width;
        const VaryingInput* input; // null: the point index ($id)
    };
    std::vector<VaryingBind> varyingBinds;
    std::vector<T> constants(bc.constants.begin(), bc.constants.end());
    std::vector<T> uniform(program.uniformSize() + 1);
    std::vector<std::string> uniformStrings(program.uniformStrings() + 1);
    for (const lang::HostInput& hi : bc.inputs) {
        const RegLocation& L = locs[static_cast<size_t>(hi.reg)];
        if (hi.type.lifetime == Lifetime::Varying) {
            const VaryingInput* found = nullptr;
            for (const VaryingInput& v : request.varyings)
                if (v.name == hi.name) found = &v;
            if (!found && hi.name != "id") {
                result.ok = false;
                result.error = "no values for the varying input $" + hi.name;
                return result;
            }
            if (found && found->width != hi.type.width && found->width != 1) {
                result.ok = false;
                result.error = "input $" + hi.name + " has " + std::to_string(found->width) +
                               " components, the program was compiled for " + std::to_string(hi.type.width);
                return result;
            }
            varyingBinds.push_back({hi.reg, hi.type.width, found});
            continue;
        }
        const UniformValue* found = nullptr;
        for (const UniformValue& u : request.uniforms)
            if (u.name == hi.name) found = &u;
        if (!found) {
            result.ok = false;
            result.error = "no value for $" + hi.name;
            return result;
        }
        if (L.isString) {
            uniformStrings[static_cast<size_t>(L.offset)] = found->text;
        } else {
            for (int k = 0; k < hi.type.width; ++k) {
                double v = found->value.empty() ? 0.0
                           : found->value.size() == 1 ? found->value[0]
                           : k < static_cast<int>(found->value.size()) ? found->value[static_cast<size_t>(k)] : 0.0;
                uniform[static_cast<size_t>(L.offset + k)] = static_cast<T>(v);
            }
        }
    }

    // Uniform pass: once per call.
    std::string uniformMessages;
    ExecContext<T> base;
    base.bc = &bc;
    base.functions = &program.functions();
    base.locations = locs.data();
    base.constants = constants.data();
    base.uniform = uniform.data();
    base.constStrings = bc.strings.data();
    base.uniformStrings = uniformStrings.data();
    base.messages = &uniformMessages;
    base.n = 1;
    for (int32_t i : program.uniformCode()) execute(bc.code[static_cast<size_t>(i)], base);

    const size_t count = request.count;
    const size_t blocks = (count + kBlockSize - 1) / kBlockSize;
    const int width = program.resultWidth();
    const RegLocation resultLoc = locs[static_cast<size_t>(bc.result)];
    const bool hasMessages = std::any_of(bc.code.begin(), bc.code.end(), [](const lang::Instr& in) { return in.sideEffects; });
    std::vector<std::string> blockMessages(hasMessages ? blocks : 0);
    std::vector<size_t> firstBadInBlock(request.checked ? blocks : 0, SIZE_MAX);

    tbb::enumerable_thread_specific<ThreadState<T>> states([&] {
        ThreadState<T> s;
        s.varying.assign(program.varyingSize() + 1, T(0));
        s.varyingStrings.resize(program.varyingStrings() * kBlockSize + 1);
        s.ctx = base;
        s.ctx.varying = s.varying.data();
        s.ctx.varyingStrings = s.varyingStrings.data();
        return s;
    });

    // Fill a block's varying inputs and run its varying code.
    auto runLanes = [&](ThreadState<T>& st, size_t first, int n, std::string* messages) {
        ExecContext<T>& ctx = st.ctx;
        ctx.varying = st.varying.data(); // (the state may have been copied since it was made)
        ctx.varyingStrings = st.varyingStrings.data();
        ctx.n = n;
        ctx.messages = messages;
        for (const VaryingBind& vb : varyingBinds) {
            const RegLocation& L = locs[static_cast<size_t>(vb.reg)];
            T* dst = st.varying.data() + L.offset;
            if (!vb.input) {
                for (int i = 0; i < n; ++i) dst[i] = static_cast<T>(first + static_cast<size_t>(i));
                continue;
            }
            const VaryingInput& in = *vb.input;
            for (int k = 0; k < vb.width; ++k) {
                T* __restrict o = dst + k * L.compStride;
                const int kk = in.width == 1 ? 0 : k;
                const double* __restrict src = in.data + static_cast<std::ptrdiff_t>(first) * in.pointStride + kk * in.compStride;
                // The common layouts get loops with a constant stride (vectorised gathers).
                if (in.pointStride == 1) for (int i = 0; i < n; ++i) o[i] = static_cast<T>(src[i]);
                else if (in.pointStride == 3) for (int i = 0; i < n; ++i) o[i] = static_cast<T>(src[3 * i]);
                else for (int i = 0; i < n; ++i) o[i] = static_cast<T>(src[i * in.pointStride]);
            }
        }
        for (int32_t i : program.varyingCode()) execute(bc.code[static_cast<size_t>(i)], ctx);
    };
    // Where a register's lane i lives after a run.
    auto valueAt = [&](ThreadState<T>& st, Reg r, int k, int i) -> T {
        const RegLocation& L = locs[static_cast<size_t>(r)];
        const T* p = L.area == RegLocation::Varying ? st.varying.data() + L.offset + i
                     : L.area == RegLocation::Uniform ? uniform.data() + L.offset
                                                      : constants.data() + L.offset;
        return p[k * L.compStride];
    };
    std::vector<size_t> badInBlock(request.checked ? blocks : 0, 0);

    auto runBlock = [&](size_t block) {
        ThreadState<T>& st = states.local();
        const size_t first = block * kBlockSize;
        const int n = static_cast<int>(std::min<size_t>(kBlockSize, count - first));
        runLanes(st, first, n, hasMessages ? &blockMessages[block] : nullptr);
        // Copy the result out (a uniform result fills every point).
        if (resultLoc.isString) {
            if (out.strings) {
                const std::string* s = resultLoc.area == RegLocation::Varying ? st.varyingStrings.data() + resultLoc.offset
                                       : resultLoc.area == RegLocation::Uniform ? uniformStrings.data() + resultLoc.offset
                                                                                : bc.strings.data() + resultLoc.offset;
                const int stride = resultLoc.area == RegLocation::Varying ? 1 : 0;
                for (int i = 0; i < n; ++i) out.strings[first + static_cast<size_t>(i)] = s[i * stride];
            }
            return;
        }
        const T* src = resultLoc.area == RegLocation::Varying ? st.varying.data() + resultLoc.offset
                       : resultLoc.area == RegLocation::Uniform ? uniform.data() + resultLoc.offset
                                                                : constants.data() + resultLoc.offset;
        const int laneStride = resultLoc.area == RegLocation::Varying ? 1 : 0;
        if (out.data) {
            for (int k = 0; k < width; ++k) {
                const T* s = src + k * resultLoc.compStride;
                T* o = out.data + static_cast<std::ptrdiff_t>(first) * out.pointStride + k * out.compStride;
                for (int i = 0; i < n; ++i) o[i * out.pointStride] = s[i * laneStride];
            }
        }
        if (request.checked) {
            for (int i = 0; i < n; ++i) {
                bool finite = true;
                for (int k = 0; k < width; ++k)
                    finite = finite && std::isfinite(static_cast<double>(src[k * resultLoc.compStride + i * laneStride]));
                if (finite) continue;
                if (badInBlock[block] == 0) firstBadInBlock[block] = first + static_cast<size_t>(i);
                ++badInBlock[block];
            }
        }
    };

    int threads = request.threads;
    // More threads than cores cannot help (and TBB warns about it): clamp.
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (threads <= 0 || threads > cores) threads = cores;
    if (threads == 1 || blocks <= 1) {
        for (size_t b = 0; b < blocks; ++b) runBlock(b);
    } else {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks, 1), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t b = r.begin(); b != r.end(); ++b) runBlock(b);
            });
        });
    }

    result.messages = uniformMessages;
    for (const std::string& m : blockMessages) result.messages += m;
    if (!request.checked || resultLoc.isString) return result;
    for (size_t b = 0; b < blocks; ++b) {
        if (!badInBlock[b]) continue;
        if (result.nonFinite == 0) result.firstBadPoint = firstBadInBlock[b];
        result.nonFinite += badInBlock[b];
    }
    if (!result.nonFinite) return result;

    // Trace the first bad point back through the data flow to the operation that turned
    // finite operands into a non-finite value.
    ThreadState<T> st = states.local();
    st.ctx.varying = st.varying.data();
    st.ctx.varyingStrings = st.varyingStrings.data();
    std::string ignored;
    runLanes(st, result.firstBadPoint, 1, &ignored);
    std::vector<int32_t> definedBy(bc.regs.size(), -1);
    for (size_t i = 0; i < bc.code.size(); ++i) definedBy[static_cast<size_t>(bc.code[i].dst)] = static_cast<int32_t>(i);
    auto finiteReg = [&](Reg r) {
        const lang::RegInfo& info = bc.reg(r);
        if (info.kind == lang::TypeKind::String) return true;
        for (int k = 0; k < info.width; ++k)
            if (!std::isfinite(static_cast<double>(valueAt(st, r, k, 0)))) return false;
        return true;
    };
    Reg r = bc.result;
    for (size_t guard = 0; guard < bc.code.size() + bc.regs.size() + 1; ++guard) {
        while (bc.reg(r).aliasOf != lang::kNoReg) r = bc.reg(r).aliasOf;
        const int32_t def = definedBy[static_cast<size_t>(r)];
        if (def < 0) {
            lang::Diagnostic d;
            const lang::RegInfo& info = bc.reg(r);
            d.message = info.input >= 0 ? "the input $" + bc.inputs[static_cast<size_t>(info.input)].name +
                                              " is not finite at point " + std::to_string(result.firstBadPoint)
                                        : "a non-finite value at point " + std::to_string(result.firstBadPoint);
            result.diagnostics.push_back(d);
            break;
        }
        const lang::Instr& in = bc.code[static_cast<size_t>(def)];
        std::vector<Reg> operands{in.a, in.b, in.c};
        for (int32_t k = 0; k < in.argCount; ++k) operands.push_back(bc.args[static_cast<size_t>(in.argBegin + k)]);
        Reg bad = lang::kNoReg;
        for (Reg o : operands)
            if (o != lang::kNoReg && !finiteReg(o)) { bad = o; break; }
        // A Select only propagates the branch it took; its other operand may be anything.
        if (in.op == lang::Op::Select && bad != lang::kNoReg) {
            const bool cond = valueAt(st, in.a, 0, 0) != T(0);
            const Reg taken = cond ? in.b : in.c;
            bad = finiteReg(in.a) ? (finiteReg(taken) ? lang::kNoReg : taken) : in.a;
        }
        if (bad == lang::kNoReg) {
            lang::Diagnostic d;
            d.span = in.span;
            std::string what = in.op == lang::Op::Call ? "'" + std::string(program.functions().at(in.imm).info.name) + "'"
                                                       : "this operation";
            d.message = what + " produced a non-finite value (" + (std::isnan(static_cast<double>(valueAt(st, in.dst, 0, 0))) ? "nan" : "inf") +
                        ") at point " + std::to_string(result.firstBadPoint) + " from finite operands";
            d.notes.push_back({std::to_string(result.nonFinite) + " point(s) of " + std::to_string(count) + " are non-finite", {}, false});
            result.diagnostics.push_back(d);
            break;
        }
        r = bad;
    }
    return result;
}

template EvalResult evaluate<float>(const Program&, const EvalRequest&, const EvalOutput<float>&);
template EvalResult evaluate<double>(const Program&, const EvalRequest&, const EvalOutput<double>&);

} // namespace gale::runtime
