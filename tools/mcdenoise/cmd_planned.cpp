// Subcommands whose work lands with later issues. They exist so `--help` shows the whole
// tool, and they say plainly that they are not available yet.
#include "host/error.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {
namespace {

void AddPlanned(CLI::App &app, const char *name, const char *what, const char *when) {
    CLI::App *cmd = app.add_subcommand(name, std::string(what) + " [not available yet]");
    cmd->allow_extras();
    std::string message = std::string("'") + name + "' is not available yet: " + when;
    cmd->callback([message] { throw Error(message); });
}

}  // namespace

void AddPlannedCommands(CLI::App &app) {
    AddPlanned(app, "diff", "Run a method on the GPU and on the CPU reference and compare",
               "it lands with issue #8, once the methods exist");
}

}  // namespace mcd::tool
