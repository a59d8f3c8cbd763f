#include "tools/mcdenoise/sequence.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <set>
#include <system_error>

#include "host/error.h"
#include "tools/mcdenoise/path_guard.h"

namespace mcd::tool {

namespace {

namespace fs = std::filesystem;

// More frames than any shot has: a typo such as 1-10000000 is refused, not allocated.
constexpr long kMaxFrames = 1000000;

struct Placeholder {
    size_t pos = 0, length = 0;
    int width = 0;
};

// Every placeholder in `text`: runs of '#', %d and %0Nd (N one or two digits).
std::vector<Placeholder> FindPlaceholders(const std::string &text) {
    std::vector<Placeholder> found;
    for (size_t i = 0; i < text.size();) {
        if (text[i] == '#') {
            size_t end = text.find_first_not_of('#', i);
            if (end == std::string::npos) end = text.size();
            found.push_back({i, end - i, int(end - i)});
            i = end;
            continue;
        }
        if (text[i] == '%') {
            size_t j = i + 1;
            int width = 0;
            if (j < text.size() && text[j] == '0') {
                ++j;
                size_t digits = 0;
                while (j < text.size() && std::isdigit((unsigned char)text[j]) && digits < 2)
                    width = width * 10 + (text[j++] - '0'), ++digits;
                if (digits == 0) width = -1;
            }
            if (width >= 0 && j < text.size() && text[j] == 'd') {
                found.push_back({i, j + 1 - i, width});
                i = j + 1;
                continue;
            }
        }
        ++i;
    }
    return found;
}

Placeholder OnePlaceholder(const std::string &pattern) {
    std::vector<Placeholder> found = FindPlaceholders(pattern);
    if (found.empty())
        throw Error(fmt::format("'{}' has no frame number placeholder (#### or %04d) for the "
                                "frames of a sequence",
                                pattern),
                    ErrorKind::InvalidArgument);
    if (found.size() > 1)
        throw Error(fmt::format("'{}' has {} frame number placeholders; a pattern takes one",
                                pattern, found.size()),
                    ErrorKind::InvalidArgument);
    return found.front();
}

// A number from digits alone, without sign or overflow; -1 when it is not one.
long ParseNumber(const std::string &text) {
    if (text.empty() || text.size() > 9) return -1;
    long value = 0;
    for (char c : text) {
        if (!std::isdigit((unsigned char)c)) return -1;
        value = value * 10 + (c - '0');
    }
    return value;
}

// An output given as a directory: ends in a separator or names an existing directory.
bool IsDirectory(const std::string &path) {
    std::error_code ec;
    return !path.empty() && (path.back() == '/' || fs::is_directory(path, ec));
}

// Where a frame's output goes under an output option: the pattern expanded, or the
// input's file name in the directory (with `extension` when the input's is not one the
// option writes).
std::string OutputPath(const std::string &role, const std::string &option,
                       const SequenceFrame &frame, const std::vector<std::string> &extensions) {
    if (HasFramePlaceholder(option)) return ExpandFramePattern(option, frame.number);
    if (!IsDirectory(option))
        throw Error(
            fmt::format(
                "{} '{}': a sequence needs an output pattern with the frame number (such as "
                "out.####.exr) or a directory (out/), so that frames do not write over each "
                "other",
                role, option),
            ErrorKind::InvalidArgument);
    fs::path name = fs::path(frame.input).filename();
    if (std::find(extensions.begin(), extensions.end(), LowerExtension(name.string())) ==
        extensions.end())
        name.replace_extension(extensions.front());
    return (fs::path(option) / name).string();
}

}  // namespace

bool HasFramePlaceholder(const std::string &pattern) {
    return !FindPlaceholders(pattern).empty();
}

std::string ExpandFramePattern(const std::string &pattern, int number) {
    Placeholder p = OnePlaceholder(pattern);
    std::string text = pattern;
    text.replace(p.pos, p.length, fmt::format("{:0{}d}", number, p.width));
    return text;
}

std::vector<int> ParseFrameRange(const std::string &text) {
    std::set<int> numbers;
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find(',', start);
        if (end == std::string::npos) end = text.size();
        std::string part = text.substr(start, end - start);
        size_t dash = part.find('-');
        long first = ParseNumber(part.substr(0, dash));
        long last = dash == std::string::npos ? first : ParseNumber(part.substr(dash + 1));
        if (first < 0 || last < 0)
            throw Error(
                fmt::format(
                    "--frames '{}': '{}' is not a frame number or a range FIRST-LAST of "
                    "non-negative numbers",
                    text, part),
                ErrorKind::InvalidArgument);
        if (last < first)
            throw Error(
                fmt::format("--frames '{}': range '{}' ends before it starts", text, part),
                ErrorKind::InvalidArgument);
        if (last - first + 1 + long(numbers.size()) > kMaxFrames)
            throw Error(fmt::format("--frames '{}': more than {} frames", text, kMaxFrames),
                        ErrorKind::InvalidArgument);
        for (long n = first; n <= last; ++n) numbers.insert(int(n));
        start = end + 1;
    }
    return {numbers.begin(), numbers.end()};
}

std::vector<std::pair<int, std::string>> FindPatternFiles(const std::string &pattern) {
    fs::path path(pattern);
    std::string name = path.filename().string();
    if (FindPlaceholders(path.parent_path().string()).size() > 0)
        throw Error(
            fmt::format(
                "'{}': the frame number placeholder must be in the file name, not a directory",
                pattern),
            ErrorKind::InvalidArgument);
    Placeholder p = OnePlaceholder(name);
    std::string prefix = name.substr(0, p.pos), suffix = name.substr(p.pos + p.length);
    fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code ec;
    fs::directory_iterator it(dir, ec);
    if (ec)
        throw Error(fmt::format("'{}': cannot list directory '{}': {}", pattern, dir.string(),
                                ec.message()),
                    ErrorKind::Io);
    std::vector<std::pair<int, std::string>> files;
    for (const fs::directory_entry &entry : it) {
        std::string file = entry.path().filename().string();
        if (file.size() <= prefix.size() + suffix.size() || !file.starts_with(prefix) ||
            !file.ends_with(suffix))
            continue;
        long number = ParseNumber(
            file.substr(prefix.size(), file.size() - prefix.size() - suffix.size()));
        if (number < 0 || ExpandFramePattern(name, int(number)) != file) continue;
        files.push_back({int(number), (path.parent_path() / file).string()});
    }
    std::sort(files.begin(), files.end());
    return files;
}

std::vector<int> ListFrameNumbers(const std::vector<std::string> &inputs) {
    std::vector<int> numbers;
    std::set<int> seen;
    for (const std::string &input : inputs) {
        std::string name = fs::path(input).filename().string();
        size_t last = name.find_last_of("0123456789");
        long number = -1;
        if (last != std::string::npos) {
            size_t first = last;
            while (first > 0 && std::isdigit((unsigned char)name[first - 1])) --first;
            number = ParseNumber(name.substr(first, last + 1 - first));
        }
        if (number < 0 || !seen.insert(int(number)).second) {
            // No number, or one twice: the positions are the only numbering that holds.
            numbers.clear();
            for (size_t i = 0; i < inputs.size(); ++i) numbers.push_back(int(i) + 1);
            return numbers;
        }
        numbers.push_back(int(number));
    }
    return numbers;
}

bool IsSequence(const std::vector<std::string> &inputs) {
    if (inputs.size() != 1) return inputs.size() > 1;
    std::error_code ec;
    return HasFramePlaceholder(inputs.front()) && !fs::exists(inputs.front(), ec);
}

std::vector<SequenceFrame> PlanSequence(const SequenceSpec &spec) {
    std::vector<SequenceFrame> frames;
    std::vector<int> range;
    if (!spec.frames.empty()) range = ParseFrameRange(spec.frames);
    if (spec.inputs.size() == 1 && HasFramePlaceholder(spec.inputs.front())) {
        const std::string &pattern = spec.inputs.front();
        if (!spec.frames.empty()) {
            OnePlaceholder(pattern);
            for (int number : range)
                frames.push_back({number, ExpandFramePattern(pattern, number)});
        } else {
            for (const auto &[number, path] : FindPatternFiles(pattern))
                frames.push_back({number, path});
            if (frames.empty())
                throw Error(fmt::format("input pattern '{}': no file matches it", pattern),
                            ErrorKind::Io);
        }
    } else {
        std::vector<int> numbers = ListFrameNumbers(spec.inputs);
        std::set<int> wanted(range.begin(), range.end());
        for (size_t i = 0; i < spec.inputs.size(); ++i)
            if (spec.frames.empty() || wanted.count(numbers[i]))
                frames.push_back({numbers[i], spec.inputs[i]});
        if (frames.empty())
            throw Error(fmt::format("--frames '{}' selects none of the {} input files (their "
                                    "numbers run {} to {})",
                                    spec.frames, spec.inputs.size(),
                                    *std::min_element(numbers.begin(), numbers.end()),
                                    *std::max_element(numbers.begin(), numbers.end())),
                        ErrorKind::InvalidArgument);
    }
    for (SequenceFrame &frame : frames) {
        frame.output = OutputPath("-o", spec.output, frame, {".exr", ".png"});
        if (!spec.preview.empty())
            frame.preview = OutputPath("--preview", spec.preview, frame, {".png"});
        if (!spec.map.empty()) frame.map = OutputPath("--auto-map", spec.map, frame, {".png"});
        if (!spec.reference.empty())
            frame.reference = HasFramePlaceholder(spec.reference)
                                  ? ExpandFramePattern(spec.reference, frame.number)
                                  : spec.reference;
    }
    return frames;
}

}  // namespace mcd::tool
