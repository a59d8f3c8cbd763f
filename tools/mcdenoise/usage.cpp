#include "tools/mcdenoise/usage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "host/api/front_end.h"

namespace mcd::tool {
namespace {

constexpr size_t kHelpWidth = 100;

// "mcdenoise bench quality": the command's name with its parents'.
std::string CommandPath(const CLI::App *command) {
    std::string path;
    for (const CLI::App *a = command; a; a = a->get_parent())
        path = a->get_name() + (path.empty() ? "" : " ") + path;
    return path;
}

// Every name `command` takes in place of `arg`: its options (for an argument starting with
// '-') or its subcommands.
std::vector<std::string> NamesFor(const CLI::App *command, const std::string &arg) {
    std::vector<std::string> names;
    if (arg.rfind("-", 0) == 0) {
        for (const CLI::Option *option : command->get_options()) {
            for (const std::string &name : option->get_lnames()) names.push_back("--" + name);
            for (const std::string &name : option->get_snames()) names.push_back("-" + name);
        }
    } else {
        for (const CLI::App *sub : command->get_subcommands({}))
            names.push_back(sub->get_name());
    }
    return names;
}

// The first argument a command on the parse's chain did not take, innermost command first,
// as "unknown option ...; did you mean ...?"; "" when every argument was taken.
std::string UnknownArgument(CLI::App *command) {
    for (CLI::App *a = command; a; a = a->get_parent()) {
        std::vector<std::string> left = a->remaining();
        if (left.empty()) continue;
        const std::string &arg = left.front();
        bool option = arg.rfind("-", 0) == 0;
        bool commands = !a->get_subcommands({}).empty();
        std::string what = option     ? "unknown option"
                           : commands ? "unknown command"
                                      : "unexpected argument";
        std::string text = fmt::format("{} '{}'", what, arg);
        if (a->get_parent()) text += fmt::format(" for '{}'", CommandPath(a));
        std::string nearest = NearestName(arg, NamesFor(a, arg));
        if (!nearest.empty()) text += fmt::format("; did you mean '{}'?", nearest);
        return text;
    }
    return "";
}

}  // namespace

HelpFormatter::HelpFormatter() {
    column_width(30);
    label("SUBCOMMAND", "COMMAND");
    label("SUBCOMMANDS", "COMMANDS");
    label("Positionals", "Arguments");
}

std::string HelpFormatter::make_subcommand(const CLI::App *sub) const {
    std::string summary = sub->get_description();
    std::stringstream out;
    // Command names are short: a narrower column than the options' leaves the line room.
    CLI::detail::format_help(out, sub->get_name(), summary.substr(0, summary.find('\n')), 16);
    return out.str();
}

std::string HelpFormatter::make_option_desc(const CLI::Option *option) const {
    return WrapText(option->get_description(), kHelpWidth - get_column_width());
}

std::string HelpFormatter::make_description(const CLI::App *app) const {
    std::string text = WrapText(CLI::Formatter::make_description(app), kHelpWidth);
    return text.empty() ? text : text + "\n";
}

std::string HelpFormatter::make_usage(const CLI::App *app, std::string name) const {
    return CLI::Formatter::make_usage(app, std::move(name)) + "\n";
}

std::string HelpFormatter::make_group(std::string group, bool positional,
                                      std::vector<const CLI::Option *> options) const {
    std::string text = group + ":\n";
    for (const CLI::Option *option : options) text += make_option(option, positional);
    return text;
}

std::string HelpFormatter::make_positionals(const CLI::App *app) const {
    std::string text = CLI::Formatter::make_positionals(app);
    return text.empty() ? text : text + "\n";
}

std::string HelpFormatter::make_footer(const CLI::App *app) const {
    return WrapText(CLI::Formatter::make_footer(app), kHelpWidth);
}

std::string WrapText(const std::string &text, size_t width) {
    std::string out;
    std::istringstream lines(text);
    bool first = true;
    for (std::string line; std::getline(lines, line); first = false) {
        if (!first) out += '\n';
        // Continuation lines of an indented line (a list item) hang under its text.
        size_t indent = line.find_first_not_of(' ');
        if (indent == std::string::npos) continue;
        std::string hang(indent ? indent + 2 : 0, ' ');
        size_t column = 0;
        std::istringstream words(line.substr(indent));
        out += std::string(indent, ' ');
        column = indent;
        bool lineStart = true;
        for (std::string word; words >> word;) {
            if (!lineStart && column + 1 + word.size() > width) {
                out += '\n' + hang;
                column = hang.size();
                lineStart = true;
            }
            if (!lineStart) out += ' ', ++column;
            out += word;
            column += word.size();
            lineStart = false;
        }
    }
    if (!text.empty() && text.back() == '\n') out += '\n';
    return out;
}

std::string RangeText(double min, double max) {
    bool noMin = min <= -1e29, noMax = max >= 1e29;
    if (noMin && noMax) return "any number";
    if (noMax) return fmt::format("at least {:g}", min);
    if (noMin) return fmt::format("at most {:g}", max);
    return fmt::format("{:g} to {:g}", min, max);
}

CLI::Option *CheckRange(CLI::Option *option, double min, double max, bool integer) {
    std::string range = RangeText(min, max);
    option->description(option->get_description() + " (" + range + ")");
    option->check(CLI::Validator(
        [=](std::string &value) -> std::string {
            char *end = nullptr;
            double v = std::strtod(value.c_str(), &end);
            if (value.empty() || *end != '\0' || (integer && v != std::floor(v)))
                return fmt::format("'{}' is not {}", value,
                                   integer ? "an integer" : "a number");
            // Past a bound no user meets (1e29 and up), or not a number: say it must be finite.
            bool unbounded = max >= 1e29 && !(v <= max);
            if (unbounded)
                return fmt::format("{} is out of range (a finite number{}{})", value,
                                   min <= -1e29 ? "" : ", ", min <= -1e29 ? "" : range);
            if (!(v >= min && v <= max))
                return fmt::format("{} is out of range ({})", value, range);
            return "";
        },
        ""));
    return option;
}

CLI::Option *CheckChoice(CLI::Option *option, const std::vector<std::string> &choices) {
    option->check(CLI::Validator(
        [=](std::string &value) -> std::string {
            if (std::find(choices.begin(), choices.end(), value) != choices.end()) return "";
            return fmt::format("'{}' is none of its choices ({})", value, api::OrList(choices));
        },
        ""));
    return option;
}

std::string SpeedText(double ratio) {
    return ratio >= 1 ? fmt::format("{:.2f}x faster", ratio)
                      : fmt::format("{:.2f}x slower", 1 / ratio);
}

int EditDistance(const std::string &a, const std::string &b) {
    // d[i][j]: the distance between a's first i characters and b's first j.
    std::vector<std::vector<int>> d(a.size() + 1, std::vector<int>(b.size() + 1));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = int(i);
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = int(j);
    for (size_t i = 1; i <= a.size(); ++i)
        for (size_t j = 1; j <= b.size(); ++j) {
            int substitute = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, substitute});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

std::string NearestName(const std::string &word, const std::vector<std::string> &names) {
    // "--kapa=1": the name is what comes before the value.
    std::string name = word;
    if (name.rfind("-", 0) == 0) name = name.substr(0, name.find('='));
    size_t letters = name.size() - std::min(name.find_first_not_of('-'), name.size());
    if (letters == 0) return "";
    std::vector<std::string> starting;
    for (const std::string &candidate : names)
        if (letters >= 3 && candidate.rfind(name, 0) == 0) starting.push_back(candidate);
    if (starting.size() == 1) return starting.front();
    std::string best;
    int bestDistance = std::max(2, int(letters) / 3) + 1;
    for (const std::string &candidate : names) {
        int distance = EditDistance(name, candidate);
        if (distance < bestDistance) best = candidate, bestDistance = distance;
    }
    return best;
}

CLI::App *CommandParsed(CLI::App &app) {
    CLI::App *command = &app;
    for (std::vector<CLI::App *> subs = app.get_subcommands(); !subs.empty();
         subs = command->get_subcommands())
        command = subs.front();
    return command;
}

std::string UsageMessage(CLI::App &app, const CLI::ParseError &error) {
    CLI::App *command = CommandParsed(app);
    std::string text = UnknownArgument(command);
    if (text.empty()) text = error.what();
    std::string path = CommandPath(command);
    bool commands = !command->get_subcommands({}).empty();
    return fmt::format("{}\nRun '{} --help' for {}.", text, path,
                       !command->get_parent() ? "the commands"
                       : commands             ? "its commands"
                                              : "its options");
}

}  // namespace mcd::tool
