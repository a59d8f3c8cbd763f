// How the command line talks to its user: help wrapped for a terminal, numeric ranges
// written as a reader says them, and a wrong command line turned into one
// "mcdenoise: error: ..." message that names the command and, for a typo, the nearest
// valid name.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace mcd::tool {

// CLI11's layout with descriptions wrapped to 100 columns (CLI11 leaves each on one line,
// which a terminal then breaks at its edge, through the option column). A command's list
// shows the first line of each subcommand's description; the subcommand's own help shows
// the whole.
class HelpFormatter : public CLI::Formatter {
  public:
    HelpFormatter();
    std::string make_subcommand(const CLI::App *sub) const override;
    std::string make_option_desc(const CLI::Option *option) const override;
    std::string make_description(const CLI::App *app) const override;
    std::string make_footer(const CLI::App *app) const override;
    // One blank line between the description, the usage line and each group (CLI11 puts
    // none after the description and two between groups).
    std::string make_usage(const CLI::App *app, std::string name) const override;
    std::string make_group(std::string group, bool positional,
                           std::vector<const CLI::Option *> options) const override;
    std::string make_positionals(const CLI::App *app) const override;
};

// `text` broken into lines of at most `width` characters at spaces; its own line breaks
// are kept.
std::string WrapText(const std::string &text, size_t width);

// The closed range [min, max] as a reader says it: "1 to 8", "at least 0" (a bound of
// 1e29 or more is no bound to a user).
std::string RangeText(double min, double max);

// Check that `option`'s value is a number (an integer with `integer`) in [min, max], and
// say the range at the end of its help. The message for a bad value names the value and
// the range: "--kappa: -1 is out of range (at least 0)"; past an unbounded maximum (or NaN)
// it says so: "--kappa: 1e40 is out of range (a finite number, at least 0)".
CLI::Option *CheckRange(CLI::Option *option, double min, double max, bool integer);

// Check a text option's value against the values it takes: a command line error (status 2)
// like a number out of range, "--non-finite: 'maybe' is none of its choices (refuse or zero)".
CLI::Option *CheckChoice(CLI::Option *option, const std::vector<std::string> &choices);

// How much faster one thing is than another, given their times' ratio (the other's over
// this one's): "2.40x faster", or below 1 "1.11x slower", never "0.90x faster".
std::string SpeedText(double ratio);

// The edit distance of a typo: insertions, deletions, substitutions and swaps of two
// neighbours each count 1 (the optimal string alignment distance).
int EditDistance(const std::string &a, const std::string &b);

// The name in `names` that `word` is most likely a typo of: the only name it begins, else
// the nearest within an edit distance of a third of its length (at least 2); "" if none.
std::string NearestName(const std::string &word, const std::vector<std::string> &names);

// The command that a parse of `app` stopped in: the last subcommand given, or `app`.
CLI::App *CommandParsed(CLI::App &app);

// The user's message for a parse error of `app` (after the parse, which knows which command
// got what): an unknown option or command first, with the nearest valid one, then CLI11's
// own complaint; each followed by where to find the options.
std::string UsageMessage(CLI::App &app, const CLI::ParseError &error);

}  // namespace mcd::tool
