// mcdenoise: a denoiser for Monte Carlo renders on Vulkan compute.
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>

#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/exit_status.h"
#include "tools/mcdenoise/heap.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::tool {
namespace {

// Every command, the main job first; the help lists them in this order.
void AddCommands(CLI::App &app) {
    app.formatter(std::make_shared<HelpFormatter>());
    app.require_subcommand(1);
    app.set_version_flag("--version", "mcdenoise 0.1.0");
    AddDenoiseCommand(app);
    AddAccumulateCommand(app);
    AddCompareCommand(app);
    AddInfoCommand(app);
    AddRenderCommand(app);
    AddDiffCommand(app);
    AddWaveletCommand(app);
    AddBenchCommand(app);
    // After the commands: a footer set before is every command's.
    app.footer(
        "Run 'mcdenoise COMMAND --help' for a command's options. Quick start: "
        "mcdenoise denoise frame.exr -o clean.exr (method auto, the default: nfor alone on a "
        "plain render; on a frame with statistics its candidates that the layers allow, "
        "combined per pixel).");
    // The help lists a command's subcommands under "Commands".
    std::function<void(CLI::App &)> group = [&](CLI::App &parent) {
        for (CLI::App *command : parent.get_subcommands({})) {
            command->group("Commands");
            group(*command);
        }
    };
    group(app);
}

// A wrong command line: its message and exit status 2. A command given without the
// subcommand it needs (mcdenoise alone, mcdenoise bench) prints its help on stdout and
// succeeds, as cargo, docker and gh do: asking a tool with no arguments is asking for help.
int UsageFailure(CLI::App &app, const CLI::ParseError &error) {
    CLI::App *command = CommandParsed(app);
    bool anyLeft = false;
    for (CLI::App *a = command; a; a = a->get_parent()) anyLeft |= !a->remaining().empty();
    if (dynamic_cast<const CLI::RequiredError *>(&error) && !anyLeft &&
        command->get_require_subcommand_min() > 0 && command->get_subcommands().empty()) {
        std::fputs(app.help().c_str(), stdout);
        return int(ExitStatus::Success);
    }
    return ReportFailure({ExitStatus::Usage, UsageMessage(app, error)});
}

int RunCommandLine(CLI::App &app, int argc, char **argv) {
    try {
        app.parse(argc, argv);
        return int(ExitStatus::Success);
    } catch (const CLI::Success &e) {  // --help, --version
        return app.exit(e);
    } catch (const CLI::ParseError &e) {
        return UsageFailure(app, e);
    } catch (...) {
        return ReportFailure(DescribeFailure(std::current_exception()));
    }
}

}  // namespace
}  // namespace mcd::tool

int main(int argc, char **argv) {
    mcd::tool::UseHugePages(argv);
    CLI::App app{"mcdenoise: denoise Monte Carlo renders with GLSL compute kernels on Vulkan",
                 "mcdenoise"};
    mcd::tool::AddCommands(app);
    return mcd::tool::RunCommandLine(app, argc, argv);
}
