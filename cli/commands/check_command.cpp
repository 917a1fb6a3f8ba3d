// `gale check FILE.se...`: parse and type-check expression files (or -e EXPR) and print every
// diagnostic with its source line and caret. A SCENE.toml is loaded whole — every [[field]]
// compiled, and the cloth, hair and colliders built as `gale sim` builds them (meshes, sequences,
// painted maps, pins) — so a scene that checks clean also loads for a run. Exit 1 if any has an
// error, 3 if one is unreadable.
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/commands/field_input.h"
#include "fields/expression_field.h"
#include "fields/scene.h"
#include "scene/load.h"
#include "scene/scene_checks.h"
#include "scene/sim_scene.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <memory>

namespace gale::cli {

namespace {

// Loads a scene (with --set applied by dotted path), compiles every field and builds its bodies
// as a run would; returns an exit code after printing every problem.
int checkScene(const std::string& path, const std::vector<std::string>& sets,
               const std::vector<std::string>& allowPaths) {
    gale::scene::SimScene sim;
    std::vector<scene::SceneError> errors;
    if (!gale::scene::loadSimScene(path, sim, errors, sets)) return printSceneErrors(errors);
    std::string report;
    fields::FieldPtr field =
        fields::buildSceneField(sim.wind, runtime::Precision::Float, report, useColor(), allowPaths);
    if (!report.empty()) std::cerr << report << std::flush;
    std::vector<std::unique_ptr<solver::Body>> bodies;
    std::vector<std::string> warnings;
    // The bodies as `gale sim` makes them, so that the two print the same warnings.
    const bool built = gale::scene::buildShotBodies(sim, sim.wind.settings.frameStart, bodies,
                                                    errors, warnings, allowPaths);
    for (const std::string& w : warnings) std::cerr << "gale: warning: " << w << '\n';
    if (!built) return printSceneErrors(errors);
    for (const scene::SceneError& w : gale::scene::runWarnings(
             sim, bodies, sim.wind.settings.frameStart, sim.wind.settings.frameEnd))
        std::cerr << w.render() << '\n';
    return field ? kExitOk : kExitInput;
}

} // namespace

int runCheck(const CheckOptions& options) {
    // --set values apply to expressions as NAME=VALUE and to scenes as dotted scene paths.
    const bool onlyScenes =
        options.expr.empty() &&
        std::all_of(options.files.begin(), options.files.end(), isSceneFile);
    std::vector<SetValue> sets;
    if (!onlyScenes && !parseSets(options.sets, sets)) return kExitUsage;
    if (options.files.empty() && options.expr.empty()) {
        printError("nothing to check: give expression files (FILE.se...) or -e EXPR");
        return kExitUsage;
    }
    io::PointSet points;
    if (!options.points.empty()) {
        if (int rc = loadPoints(options.points, points)) return rc;
    }
    Bindings bindings(0.0, 0.0, 24.0);
    if (!options.points.empty()) bindings.addPoints(points);
    bindings.addSets(sets);

    bool sawError = false, sawIoError = false;
    auto checkOne = [&](const std::string& file, const std::string& expr) {
        if (expr.empty() && isSceneFile(file)) {
            const int rc = checkScene(file, options.sets, options.allowPaths);
            if (rc == kExitIo) sawIoError = true;
            if (rc != kExitOk) sawError = true;
            return;
        }
        lang::SourceFile source;
        int rc = loadSource(file, expr, source);
        if (rc == kExitIo) sawIoError = true;
        if (rc != kExitOk) return;
        // Declared parameters are uniforms, as eval binds them.
        Bindings local = bindings;
        const lang::SourceFile compiled = bindParameters(source, local);
        local.addSets(sets);
        const geometry::FileAccess files = geometry::fileAccessFor(file, options.allowPaths);
        if (!compileAndReport(compiled, local.variables(), wantWidthFor(options.type), &source,
                              &files))
            sawError = true;
    };
    for (const std::string& file : options.files) checkOne(file, "");
    if (!options.expr.empty()) checkOne("", options.expr);
    if (sawIoError) return kExitIo;
    return sawError ? kExitInput : kExitOk;
}

Command addCheckCommand(CLI::App& app) {
    auto options = std::make_shared<CheckOptions>();
    CLI::App* sub = app.add_subcommand(
        "check", "Parse and type-check expression files; print every diagnostic as "
                 "file:line:col: error: message, the source line and a caret underline. "
                 "Silent when all is well; exit 1 if there is any error.");
    sub->add_option("files", options->files,
                    "Expression files (.se) or scenes (.toml: the scene and every [[field]] "
                    "expression of it); '-' reads an expression from stdin")
        ->type_name("FILE");
    sub->add_option("-e,--expr", options->expr, "Also check this expression text (named <expr>)")
        ->type_name("EXPR");
    sub->add_option("--set", options->sets,
                    "Declare host variable $NAME as a uniform of this value's type: a number, a "
                    "vector (1,2,3) or a quoted string; for a scene, override a key by its "
                    "dotted path (windicator.speed=12); repeatable")
        ->type_name("NAME=VALUE")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    sub->add_option("--type", options->type,
                    "Wanted result: auto, float (FP[1]) or vector (FP[3], a scalar is promoted)")
        ->check(CLI::IsMember({"auto", "float", "vector"}))
        ->capture_default_str();
    sub->add_option("--points", options->points,
                    "Declare the columns of this point file (.csv/.ply/.obj) as varying variables, "
                    "as eval --points does")
        ->type_name("IN");
    addAllowPathOption(*sub, options->allowPaths);
    return {sub, [options] { return runCheck(*options); }};
}

} // namespace gale::cli
