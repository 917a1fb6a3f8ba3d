// `gale wedge` without the command line: --vary parsing, the cartesian product of variants and
// their folder names, the resolved scene of one variant (scene/document.h), the shell command of a task,
// the manifest lines, and a small local process pool that runs tasks.txt lines.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace gale::cli {

// One --vary KEY=V1,V2,...: a dotted scene path (as `gale sim --set` takes it) and its values,
// each a `--set` value (a number, `[1, 0, 0]`, `{ keys = ... }`, a word).
struct VaryAxis {
    std::string key;
    std::vector<std::string> values;
};
// Splits at top-level commas (not inside [], {}, () or quotes). False with `error` set when the
// text is not KEY=V1,... with a non-empty key and values.
bool parseVary(const std::string& text, VaryAxis& out, std::string& error);

// The output files a variant's run writes per frame (from its resolved scene).
struct VariantObject {
    std::string name;
    std::string format; // obj | ply
};

// One combination of the axes' values.
struct Variant {
    int index = 0;
    std::string id;     // v000, v001, ...
    std::string folder; // id plus the values, e.g. v003_lift=0.3_drag=1.2 (sanitised)
    std::vector<std::pair<std::string, std::string>> values; // (key, value) per axis
    std::vector<std::string> sets; // key=value, for loading and resolving the scene
    // Filled once the scene was loaded with the variant's overrides.
    int frameStart = 0, frameEnd = 0;
    std::vector<VariantObject> objects;
};

// Each key's shortest dotted suffix that no other key shares (cloth.cape.lift -> lift).
std::vector<std::string> shortKeyNames(const std::vector<std::string>& keys);

// Every combination, the first axis varying slowest. Names use each key's shortest dotted suffix
// that tells the axes apart (`lift` for cloth.cape.lift unless another axis ends in `lift`).
std::vector<Variant> expandVariants(const std::vector<VaryAxis>& axes);

// A folder-name-safe copy: letters, digits and `._=+-` kept, anything else becomes `_`.
std::string sanitiseName(const std::string& text);

// The scene file with `sets` applied by dotted path (the same paths as `gale sim --set`) and
// every relative file name (field expr, cloth mesh, hair strands, painted-map expr, collider mesh) made
// absolute, so it can live in another folder; `header` becomes leading comment lines. False
// with `error` set (a rendered scene error) when the file cannot be read or an override cannot be
// applied (load the scene with gale's loaders first for all its diagnostics).
bool resolveVariantScene(const std::string& scenePath, const std::vector<std::string>& sets,
                         const std::string& header, std::string& out, std::string& error);

// A single-quoted shell word.
std::string shellQuote(const std::string& text);

// The idempotent task line of a variant folder: skips when DONE exists, else runs (or resumes)
// `gale sim scene.toml -o .` there, appending to log.txt, and touches DONE on success. Each of
// `allowPaths` (absolute) is passed on as --allow-path, `cache` (when set) as --cache.
std::string taskCommand(const std::string& galeBinary, const std::string& variantDir, int threads,
                        const std::vector<std::string>& allowPaths = {}, const std::string& cache = "");

// True when `dir` has DONE and every object's frame file of the variant.
bool variantComplete(const Variant& v, const std::string& dir);

// The manifest line (JSON) of a variant: id, index, folder, path, values (numbers as numbers),
// frames, objects, command, status ("pending", "done", "failed") and exit_code when it ran.
std::string manifestLine(const Variant& v, const std::string& dir, const std::string& command,
                         const std::string& status, int exitCode);

// Runs shell commands (`/bin/sh -c`), at most `jobs` at once, each in its own process group.
// `done(i, exitCode)` is called (from the calling thread) as each finishes; exit codes of
// commands killed by a signal are 128 + the signal. SIGINT, SIGTERM and SIGHUP received meanwhile
// are passed on to the running commands before the pool re-raises them.
void runPool(const std::vector<std::string>& commands, int jobs,
             const std::function<void(size_t, int)>& done);

// The Slurm array script of a wedge in `outDir` (absolute) with `tasks` lines in tasks.txt:
// one array task per line, logs in outDir/logs/%A_%a.out, --requeue, --cpus-per-task `threads`
// (when > 0), --partition when given (cli/wedge/wedge_farm.cpp).
std::string slurmScript(const std::string& outDir, size_t tasks, int threads, const std::string& partition,
                        const std::string& scene);
// Runs `sbatch --parsable script`; the job id in `jobId`. Prints the problem and returns an
// exit code on failure.
int submitSlurm(const std::string& script, std::string& jobId);
// `gale wedge --status OUTDIR`: prints each variant of the manifest as done, partial (frames so
// far), failed or not started, from the frames on disk; returns an exit code.
int runWedgeStatus(const std::string& outDir);

} // namespace gale::cli
