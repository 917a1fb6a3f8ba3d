// `gale wedge SCENE.toml --vary KEY=V1,V2,... -o OUTDIR`: one resolved scene per combination of
// values in OUTDIR/<variant>/scene.toml, tasks.txt (one idempotent shell command per variant, for
// GNU parallel, a Slurm array or OpenCue) and manifest.jsonl, then runs the pending ones locally.
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/wedge/wedge.h"

#include "io/atomic_file.h"
#include "scene/load.h"
#include "scene/sim_scene.h"

#include <CLI/CLI.hpp>
#include <unistd.h>

#include <climits>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <set>

namespace gale::cli {

namespace {

namespace fs = std::filesystem;

// The absolute path of the running gale binary (argv[0] is not reliable under a shell).
std::string selfPath() {
    char buf[PATH_MAX];
    const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
    if (n > 0) return std::string(buf, static_cast<size_t>(n));
    return "gale";
}

bool readAll(const fs::path& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

std::string describe(const Variant& v) {
    std::string s = v.id + " (";
    for (size_t i = 0; i < v.values.size(); ++i)
        s += (i ? ", " : "") + v.values[i].first + "=" + v.values[i].second;
    return s + ")";
}

} // namespace

int runWedge(const WedgeOptions& o) {
    if (!o.status.empty()) {
        if (!o.scene.empty() || !o.vary.empty() || !o.output.empty()) {
            printError("--status OUTDIR reports on a wedge folder: give it alone (no SCENE, --vary "
                       "or -o)");
            return kExitUsage;
        }
        return runWedgeStatus(o.status);
    }
    if (o.scene.empty() || o.vary.empty() || o.output.empty()) {
        printError("gale wedge needs SCENE.toml, at least one --vary KEY=V1,V2,... and -o OUTDIR "
                   "(or --status OUTDIR)");
        return kExitUsage;
    }
    if (!o.farm.empty() && o.farm != "slurm") {
        printError("--farm must be slurm, not '" + o.farm +
                   "' (for GNU parallel or OpenCue use --emit-only and "
                   "tasks.txt; docs/wedge.md)");
        return kExitUsage;
    }
    if (!o.cache.empty() && o.cache != "mdd") {
        printError("--cache must be mdd (each variant's OUTDIR/<variant>/<object>.mdd), not '" +
                   o.cache + "'");
        return kExitUsage;
    }
    if ((o.submit || !o.partition.empty()) && o.farm.empty()) {
        printError("--submit and --partition go with --farm slurm");
        return kExitUsage;
    }
    if (o.jobs < 1 || o.threads < 0) {
        printError("--jobs must be at least 1 and --threads not negative");
        return kExitUsage;
    }
    std::vector<VaryAxis> axes;
    std::set<std::string> keys;
    size_t total = 1;
    for (const std::string& text : o.vary) {
        VaryAxis axis;
        std::string error;
        if (!parseVary(text, axis, error)) {
            printError(error);
            return kExitUsage;
        }
        if (!keys.insert(axis.key).second) {
            printError("--vary " + axis.key + " is given twice; list all its values in one --vary");
            return kExitUsage;
        }
        total *= axis.values.size();
        if (total > 100000) {
            printError("the --vary lists make more than 100000 variants");
            return kExitUsage;
        }
        axes.push_back(std::move(axis));
    }
    std::vector<std::string> common = o.sets;
    if (!o.frames.empty()) {
        int a = 0, b = 0;
        if (!parseFrames(o.frames, a, b)) {
            printError("--frames must be A:B with whole numbers A <= B, at most " +
                       std::to_string(kMaxFrames) + " frames, not '" + o.frames + "'");
            return kExitUsage;
        }
        common.push_back("scene.frames=[" + std::to_string(a) + ", " + std::to_string(b) + "]");
    }
    std::error_code ec;
    if (!fs::is_regular_file(o.scene, ec)) {
        printError(o.scene + ": cannot read the scene: " +
                   (fs::exists(o.scene, ec) ? "not a regular file" : "no such file"));
        return kExitIo;
    }

    // Every variant's scene must load: the loaders report file:line:col and bad --vary keys.
    std::vector<Variant> variants = expandVariants(axes);
    for (Variant& v : variants) {
        std::vector<std::string> sets = common;
        sets.insert(sets.end(), v.sets.begin(), v.sets.end());
        v.sets = sets;
        scene::SimScene scene;
        std::vector<scene::SceneError> errors;
        if (!gale::scene::loadSimScene(o.scene, scene, errors, sets)) {
            const int rc = printSceneErrors(errors);
            printError("variant " + describe(v) + " does not load; no variant was written");
            return rc;
        }
        v.frameStart = scene.wind.settings.frameStart;
        v.frameEnd = scene.wind.settings.frameEnd;
        for (const scene::ClothSpec& c : scene.cloths) v.objects.push_back({c.name, c.output});
        for (const scene::HairSpec& h : scene.hairs) v.objects.push_back({h.name, h.output});
        if (v.objects.empty()) {
            printError(o.scene + ": the scene has no [[cloth]] or [[hair]] to simulate");
            return kExitInput;
        }
    }

    const fs::path out = fs::absolute(o.output, ec).lexically_normal();
    fs::create_directories(out, ec);
    if (ec || !fs::is_directory(out)) {
        printError(o.output + ": cannot create the output folder" +
                   (ec ? ": " + ec.message() : std::string()));
        return kExitIo;
    }
    const std::string gale = selfPath();
    const std::string sceneAbs = fs::absolute(o.scene, ec).lexically_normal().string();
    // A variant's scene lives in its own folder, so the folder the expressions could reach from
    // the original scene is allowed explicitly, with every --allow-path (absolute: the task runs
    // in the variant folder).
    std::vector<std::string> allowPaths = {fs::path(sceneAbs).parent_path().string()};
    for (const std::string& dir : o.allowPaths)
        allowPaths.push_back(fs::absolute(dir, ec).lexically_normal().string());
    std::vector<std::string> commands, status(variants.size()), dirs;
    std::string tasks;
    int restarted = 0;
    for (const Variant& v : variants) {
        const fs::path dir = out / v.folder;
        dirs.push_back(dir.string());
        std::string header = "gale wedge variant " + v.id + " of " + sceneAbs + "\nwith";
        for (const std::string& s : v.sets) header += " --set " + s;
        header += "\nrun it with: " + std::string("gale sim scene.toml -o . --resume");
        std::string text, error;
        if (!resolveVariantScene(o.scene, v.sets, header, text, error)) {
            printError("variant " + describe(v) + ": " + error);
            return kExitInput;
        }
        fs::create_directories(dir, ec);
        if (ec) {
            printError(dir.string() + ": cannot create the variant folder: " + ec.message());
            return kExitIo;
        }
        // A changed scene invalidates what ran before: drop the marker and the resume state.
        std::string old;
        if (readAll(dir / "scene.toml", old) && old != text) {
            fs::remove(dir / "DONE", ec);
            fs::remove_all(dir / ".state", ec);
            ++restarted;
        }
        if (int rc = writeTextFileAtomic((dir / "scene.toml").string(), text)) return rc;
        commands.push_back(taskCommand(gale, dir.string(), o.threads, allowPaths, o.cache));
        tasks += commands.back() + '\n';
    }
    if (int rc = writeTextFileAtomic((out / "tasks.txt").string(), tasks)) return rc;

    std::vector<int> exitCodes(variants.size(), -1);
    auto writeManifest = [&]() {
        std::string text;
        for (size_t i = 0; i < variants.size(); ++i)
            text += manifestLine(variants[i], dirs[i], commands[i], status[i], exitCodes[i]) + '\n';
        return writeTextFileAtomic((out / "manifest.jsonl").string(), text);
    };
    std::vector<std::string> pending;
    std::vector<size_t> pendingIndex;
    for (size_t i = 0; i < variants.size(); ++i) {
        status[i] = variantComplete(variants[i], dirs[i]) ? "done" : "pending";
        if (status[i] == "pending") {
            pending.push_back(commands[i]);
            pendingIndex.push_back(i);
        }
    }
    if (int rc = writeManifest()) return rc;
    const size_t already = variants.size() - pending.size();
    if (restarted > 0)
        std::cerr << "gale wedge: " << restarted
                  << " variant(s) had a different scene before; they start over\n";
    if (!o.farm.empty()) {
        fs::create_directories(out / "logs", ec);
        if (ec) {
            printError((out / "logs").string() + ": cannot create the log folder: " + ec.message());
            return kExitIo;
        }
        const std::string script = (out / "submit.sbatch").string();
        if (int rc = writeTextFileAtomic(script, slurmScript(out.string(), variants.size(),
                                                             o.threads, o.partition, sceneAbs)))
            return rc;
        std::cerr << "gale wedge: " << variants.size() << " variant(s) in " << out.string() << " ("
                  << already << " complete); "
                  << (o.submit ? "submitting " : "submit with: sbatch ") << script << '\n';
        if (!o.submit) return kExitOk;
        std::string jobId;
        if (int rc = submitSlurm(script, jobId)) return rc;
        std::cout << jobId << '\n' << std::flush;
        std::cerr << "gale wedge: Slurm job " << jobId << "; progress: gale wedge --status "
                  << out.string() << '\n';
        return kExitOk;
    }
    if (o.emitOnly) {
        std::cerr << "gale wedge: " << variants.size() << " variant(s) in " << out.string() << " ("
                  << already << " complete); run " << (out / "tasks.txt").string()
                  << " with GNU parallel, a Slurm array "
                  << "or cuecmd (see docs/wedge.md)\n";
        return kExitOk;
    }
    if (already > 0)
        std::cerr << "gale wedge: " << already << " variant(s) already complete, skipped\n";

    const bool tty = isatty(2) != 0;
    size_t finished = 0;
    int firstFailure = -1;
    int result = kExitOk;
    runPool(pending, o.jobs, [&](size_t k, int code) {
        const size_t i = pendingIndex[k];
        ++finished;
        exitCodes[i] = code;
        status[i] = code == 0 && variantComplete(variants[i], dirs[i]) ? "done" : "failed";
        if (status[i] == "failed") {
            printError("variant " + describe(variants[i]) + " failed (exit " +
                       std::to_string(code) + "); see " + (fs::path(dirs[i]) / "log.txt").string());
            if (firstFailure < 0 || static_cast<int>(i) < firstFailure) {
                firstFailure = static_cast<int>(i);
                result = code >= 1 && code <= 4 ? code : kExitInput;
            }
        } else if (tty) {
            std::cerr << "gale wedge: " << variants[i].folder << " done (" << finished << "/"
                      << pending.size() << ")\n";
        }
        writeManifest();
    });
    size_t done = 0;
    for (const std::string& s : status) done += s == "done";
    std::cerr << "gale wedge: " << done << " of " << variants.size() << " variant(s) complete in "
              << out.string() << '\n';
    return result;
}

Command addWedgeCommand(CLI::App& app) {
    auto o = std::make_shared<WedgeOptions>();
    CLI::App* sub = app.add_subcommand(
        "wedge", "Run variants of a scene: one per combination of the --vary values. Writes "
                 "OUTDIR/<variant>/scene.toml (the scene resolved with the variant's values, file "
                 "names made "
                 "absolute), OUTDIR/tasks.txt (one idempotent shell command per variant, for GNU "
                 "parallel, a "
                 "Slurm array or OpenCue's cuecmd) and OUTDIR/manifest.jsonl, then runs the "
                 "variants not yet "
                 "complete with --jobs processes (none with --emit-only).");
    sub->add_option("scene", o->scene, "Scene file (.toml) with [[cloth]] and/or [[hair]]")
        ->type_name("SCENE");
    sub->add_option("--vary", o->vary,
                    "A dotted scene path (as gale sim --set takes it) and its values: "
                    "cloth.cape.lift=0.1,0.3,0.5; "
                    "vectors in brackets: windicator.direction=[1,0,0],[1,0,1]. Repeatable: the "
                    "variants are "
                    "every combination, the first --vary varying slowest")
        ->type_name("KEY=V1,V2,...")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    sub->add_option("-o,--output", o->output, "Output folder")->type_name("OUTDIR");
    sub->add_option("--set", o->sets,
                    "Override a scene key in every variant (as gale sim --set). Repeatable")
        ->type_name("KEY=VALUE")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    sub->add_option("--frames", o->frames, "Frames A to B in every variant instead of the scene's")
        ->type_name("A:B");
    CLI::Option* jobs =
        sub->add_option("--jobs", o->jobs, "Variants run at once on this machine (default 1)")
            ->type_name("N");
    CLI::Option* emit =
        sub->add_flag("--emit-only", o->emitOnly,
                      "Write the scenes, tasks.txt and manifest.jsonl, run nothing (run tasks.txt "
                      "on a farm; running gale wedge again refreshes the manifest's status)");
    jobs->excludes(emit);
    CLI::Option* farm =
        sub->add_option(
               "--farm", o->farm,
               "slurm: also write OUTDIR/submit.sbatch, an array job with one task per line "
               "of tasks.txt (logs in OUTDIR/logs/, --requeue); runs nothing locally")
            ->type_name("slurm");
    farm->excludes(jobs);
    sub->add_flag("--submit", o->submit,
                  "With --farm slurm: submit it with sbatch and print the job id");
    sub->add_option("--partition", o->partition, "With --farm slurm: the partition to run in")
        ->type_name("P");
    sub->add_option("--status", o->status,
                    "Print each variant of the wedge in OUTDIR as done, partial (frames so far), "
                    "failed or not "
                    "started, from manifest.jsonl and the frames on disk (give it alone)")
        ->type_name("OUTDIR");
    sub->add_option("--cache", o->cache,
                    "Each variant's simulation also writes point caches: mdd (gale sim --cache)")
        ->type_name("FORMAT");
    sub->add_option("--threads", o->threads, "Threads of each simulation (default 1; 0: all)")
        ->type_name("N");
    addAllowPathOption(*sub, o->allowPaths);
    sub->footer(
        "Re-running skips variants already complete (DONE marker and every frame present) and "
        "resumes\n"
        "interrupted ones. Exit codes: 1 a variant's scene is wrong (nothing written) or a "
        "variant\n"
        "failed to load when run, 2 bad flags, 3 I/O error, 4 a variant failed numerically; with\n"
        "several failures, the code of the first failed variant. See docs/wedge.md.");
    return {sub, [o] { return runWedge(*o); }};
}

} // namespace gale::cli
