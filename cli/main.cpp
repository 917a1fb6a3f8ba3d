// The `gale` command: wires the subcommands into CLI11, parses argv and returns the chosen
// command's exit code. Usage errors exit 2 (see cli/commands.h for every exit code).
#include "cli/commands.h"
#include "cli/common.h"

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <vector>

#ifndef GALE_VERSION
#define GALE_VERSION "unknown"
#endif

// Word-wraps every description (CLI11 2.1 prints them on one line) and ends footers with a
// newline.
static void wrapAllHelp(CLI::App& app, bool root = true) {
    if (!root) app.description(gale::cli::wrapHelp(app.get_description()));
    if (!app.get_footer().empty() && app.get_footer().back() != '\n')
        app.footer(app.get_footer() + "\n");
    for (CLI::Option* opt : app.get_options(std::function<bool(CLI::Option*)>()))
        opt->description(gale::cli::wrapHelp(opt->get_description()));
    for (CLI::App* sub :
         app.get_subcommands(std::function<bool(CLI::App*)>([](CLI::App*) { return true; })))
        wrapAllHelp(*sub, false);
}

int main(int argc, char** argv) {
    using namespace gale::cli;
    CLI::App app("gale " GALE_VERSION ": SeExpr2-compatible wind expressions for cloth and hair",
                 "gale");
    app.set_version_flag("--version", "gale " GALE_VERSION);
    app.require_subcommand(1);
    app.footer("Data goes to stdout (or -o), messages to stderr; '-' means stdin or stdout.\n"
               "Exit codes: 0 ok; 1 the input was read but is wrong (diagnostics printed);\n"
               "2 usage error; 3 I/O error (missing file, unwritable output); 4 numerical\n"
               "failure (non-finite results with eval --checked).\n"
               "Run 'gale COMMAND --help' for a command's options.");

    // One line per subcommand: each lives in its own cli/*_command.cpp.
    std::vector<Command> commands = {
        addCheckCommand(app),
        addEvalCommand(app),
        addBenchCommand(app),
        addBuiltinsCommand(app),
        addSampleCommand(app),
        addVizCommand(app),
        addSimCommand(app),
        addWedgeCommand(app),
        addLiveCommand(app),
    };

    wrapAllHelp(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int code = app.exit(e); // prints help/version to stdout, errors to stderr
        return code == 0 ? kExitOk : kExitUsage;
    }
    try {
        for (const Command& c : commands)
            if (c.app->parsed()) return c.run();
    } catch (const std::bad_alloc&) {
        std::cerr << "gale: out of memory\n";
        return kExitInput;
    } catch (const std::exception& e) {
        std::cerr << "gale: internal error: " << e.what() << '\n';
        return kExitInput;
    }
    return kExitUsage;
}
