// The `gale` subcommands: exit codes, each command's options and entry point, and the hook
// that adds it to the CLI11 parser. A new subcommand is one new cli/*_command.cpp defining
// its add*Command (declared here) plus one line in main.cpp's command list.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace gale::cli {

// Exit codes (the contract in spec/cli.md).
enum ExitCode : int {
    kExitOk = 0,
    kExitInput = 1,   // the input was read but is wrong (diagnostics printed)
    kExitUsage = 2,   // bad flags
    kExitIo = 3,      // missing file, unwritable output
    kExitNumeric = 4, // non-finite results (eval --checked)
};

// A subcommand registered with the parser, and what to run when it was chosen.
struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

// Options shared by the commands that compile an expression.
struct SourceOptions {
    std::string file;              // FILE.se, or "-" for stdin
    std::string expr;              // -e EXPR
    std::vector<std::string> sets; // --set NAME=VALUE
    std::string type = "auto";     // auto | float | vector
    // --allow-path DIR: folders files named by expressions may reach besides their own
    // (docs/geometry.md).
    std::vector<std::string> allowPaths;
};

struct CheckOptions {
    std::vector<std::string> files;
    std::string expr;
    std::vector<std::string> sets;
    std::string type = "auto";
    std::string points; // declare this point file's columns as variables
    std::vector<std::string> allowPaths; // --allow-path DIR
};

struct EvalOptions {
    SourceOptions source;
    std::string points; // --points IN ("-": CSV on stdin)
    double time = 0.0;
    bool hasTime = false;
    double frame = 0.0;
    bool hasFrame = false;
    double fps = 24.0;
    std::string precision; // "", "float" or "double" ("": float with --points, else double)
    int threads = -1;   // -1: all hardware threads with --points, 1 without
    std::string output; // -o OUT ("-" or empty: stdout)
    std::string format; // csv | ply | ply-ascii | json | npy | obj (empty: from -o, else csv)
    bool disasm = false;
    bool checked = false;
};

struct BenchOptions {
    SourceOptions source;
    long long points = 1'000'000;
    int threads = 1; // 0: all hardware threads
    std::string precision = "float";
    bool json = false;
    int repeat = 0; // 0: until >= 0.5 s and at least 3 runs
    double time = 0.0;
};

struct BuiltinsOptions {
    bool json = false;
    bool markdown = false; // the reference page docs/builtins.md is this output
};

// `gale sample` (cli/commands/sample_command.cpp).
struct SampleOptions {
    SourceOptions source;   // FILE.se | -e EXPR | SCENE.toml, --set
    std::string bounds;     // x0,y0,z0,x1,y1,z1
    std::string res;        // N (cubic voxels, N along the longest side) or NX,NY,NZ
    double voxel = 0.0;     // cubic voxel size (instead of --res)
    double time = 0.0;      // seconds
    std::string frames;     // A:B (t = (frame − time_zero) / fps), OUT has '#'
    double fps = 0.0;       // 0: the scene's, else 24
    int threads = 0;        // 0: all hardware threads
    std::string output;     // -o OUT ("-" or empty: stdout)
    std::string format;     // vdb | npy | csv (empty: from -o, else csv)
    bool resume = false;    // --frames: skip frames whose file is already on disk
};

// `gale viz` (cli/commands/viz_command.cpp).
struct VizOptions {
    SourceOptions source;
    std::string plane = "z=0";       // x=C | y=C | z=C
    std::string bounds;              // u0,v0,u1,v1 in the plane's axes
    double time = 0.0;
    double fps = 0.0;                // 0: the scene's, else 24
    std::string size = "1024x1024";  // WxH pixels
    std::string output;              // -o slice.(png|svg)
    std::string style = "arrows";    // arrows | streamlines | none
    double speedMax = 0.0;           // colour scale top in m/s (0: from the slice)
    double arrowSpacing = 0.0;       // pixels between arrows (0: about 22 across)
    int threads = 0;
    // Preview renders (cli/commands/preview.cpp): frames of a simulation, contact sheets of wedges.
    std::string frames;              // A:B (per-frame pictures; OUT has '#'), or a list for sheets
    std::string sim;                 // the gale sim output folder (default "sim")
    std::string contactSheet;        // a gale wedge output folder
    bool noField = false;            // a plain backdrop instead of the field slice
    bool strain = false;             // cloth and hair coloured by rest-relative strain
    std::string cell = "240x240";    // contact sheet thumbnail size
};

int runCheck(const CheckOptions& options);
int runEval(const EvalOptions& options);
int runBench(const BenchOptions& options);
int runBuiltins(const BuiltinsOptions& options);

int runSample(const SampleOptions& options);
int runViz(const VizOptions& options);

Command addCheckCommand(CLI::App& app);
Command addEvalCommand(CLI::App& app);
Command addBenchCommand(CLI::App& app);
Command addBuiltinsCommand(CLI::App& app);
Command addSampleCommand(CLI::App& app);
Command addVizCommand(CLI::App& app);

// `gale sim SCENE.toml`: cloth and hair driven by the scene's wind (cli/commands/sim_command.cpp).
struct SimOptions {
    std::string scene;
    std::string output = "sim";    // OUTDIR
    std::string frames;            // A:B (empty: the scene's frames)
    std::vector<std::string> sets; // --set KEY=VALUE by dotted scene path
    bool resume = false;
    int threads = 1;               // 0: all hardware threads; results do not depend on it
    bool json = false;             // print run.json's content to stdout at the end
    std::vector<std::string> allowPaths; // --allow-path DIR (files named by expressions)
    std::string cache;             // --cache mdd: OUTDIR/<object>.mdd point caches too
    bool strict = false;           // exit 4 at the first frame that ends in trouble
};
int runSim(const SimOptions& options);
Command addSimCommand(CLI::App& app);

// `gale wedge SCENE.toml --vary KEY=V1,V2,... -o OUTDIR` (cli/wedge/wedge_command.cpp).
struct WedgeOptions {
    std::string scene;
    std::vector<std::string> vary; // KEY=V1,V2,...
    std::vector<std::string> sets; // --set KEY=VALUE in every variant
    std::string frames;            // A:B in every variant (empty: the scene's)
    std::string output;            // OUTDIR
    int jobs = 1;                  // variants run at once locally
    bool emitOnly = false;
    int threads = 1;               // each simulation's --threads
    std::vector<std::string> allowPaths; // --allow-path DIR, passed on to every variant's sim
    std::string farm;              // --farm slurm: also OUTDIR/submit.sbatch, run nothing locally
    bool submit = false;           // --submit: sbatch it, print the job id
    std::string partition;         // --partition P of the Slurm array
    std::string status;            // --status OUTDIR: report progress instead
    std::string cache;             // --cache mdd, passed on to every variant's sim
};
int runWedge(const WedgeOptions& options);
Command addWedgeCommand(CLI::App& app);

// `gale live SCENE.toml | FILE.se`: the field in a browser, updated as files change
// (cli/commands/live_command.cpp; the server is live/).
Command addLiveCommand(CLI::App& app);

} // namespace gale::cli
