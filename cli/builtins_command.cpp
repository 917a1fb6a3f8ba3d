// `gale builtins`: every built-in function with its signature and one-line doc, printed from
// the same table the compiler type-checks against (aligned text, or JSON).
#include "cli/commands.h"
#include "cli/common.h"
#include "runtime/builtins.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <memory>

namespace gale::cli {

int runBuiltins(const BuiltinsOptions& o) {
    std::shared_ptr<const runtime::FunctionTable> table = runtime::FunctionTable::standard();
    const std::vector<runtime::Builtin>& all = table->all();
    std::string out;
    if (o.json) {
        out = "[\n";
        for (size_t i = 0; i < all.size(); ++i) {
            const lang::FunctionInfo& f = all[i].info;
            out += "  {\"name\": " + jsonString(std::string(f.name)) +
                   ", \"signature\": " + jsonString(std::string(f.signature)) +
                   ", \"doc\": " + jsonString(std::string(f.doc)) +
                   ", \"foldable\": " + (f.foldable ? "true" : "false") + "}";
            out += i + 1 < all.size() ? ",\n" : "\n";
        }
        out += "]\n";
    } else {
        // Signatures in one column (capped so one very long signature does not push every doc
        // far right), docs in the next.
        size_t column = 0;
        for (const runtime::Builtin& b : all) column = std::max(column, b.info.signature.size());
        column = std::min<size_t>(column, 56);
        for (const runtime::Builtin& b : all) {
            std::string sig(b.info.signature);
            out += sig;
            if (!b.info.doc.empty()) {
                if (sig.size() >= column)
                    out += "\n" + std::string(column, ' ');
                else
                    out += std::string(column - sig.size(), ' ');
                out += "  ";
                out += b.info.doc;
            }
            out += '\n';
        }
    }
    std::cout << out << std::flush;
    return std::cout ? kExitOk : kExitIo;
}

Command addBuiltinsCommand(CLI::App& app) {
    auto o = std::make_shared<BuiltinsOptions>();
    CLI::App* sub = app.add_subcommand(
        "builtins", "List every built-in function with its signature and one-line doc (the "
                    "table the compiler uses).");
    sub->add_flag("--json", o->json, "Print a JSON array of {name, signature, doc, foldable}");
    return {sub, [o] { return runBuiltins(*o); }};
}

} // namespace gale::cli
