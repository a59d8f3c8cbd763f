// Sequences for `mcdenoise denoise`: frame-number patterns (frame.####.exr, frame.%04d.exr),
// frame ranges (--frames 1-100, one per farm task), and the plan that pairs each frame's
// input with its outputs. Plain C++ (no CLI11), so the tests call it directly.
#pragma once

#include <string>
#include <vector>

namespace mcd::tool {

// Whether `pattern` holds a frame-number placeholder: a run of '#' (padded to the run's
// length) or printf's %d / %0Nd.
bool HasFramePlaceholder(const std::string &pattern);

// The pattern with its placeholder replaced by `number`, zero-padded to the placeholder's
// width (wider numbers are written whole). Throws mcd::Error when the pattern has no
// placeholder or more than one.
std::string ExpandFramePattern(const std::string &pattern, int number);

// The frame numbers of "--frames": "A", "A-B" or a comma-separated list of those, as a
// sorted list without repeats. Throws mcd::Error naming the bad part.
std::vector<int> ParseFrameRange(const std::string &text);

// The files that exist for a pattern whose placeholder is in the file name (not in a
// directory), as (number, path), sorted by number. A name matches when the pattern
// expanded with its number gives that name back (so #### matches 0007, not 7 or 00007).
std::vector<std::pair<int, std::string>> FindPatternFiles(const std::string &pattern);

// The numbers of a list of input files: the last run of digits in each file name; where
// a name has none, or two names share one, the positions in the list from 1.
std::vector<int> ListFrameNumbers(const std::vector<std::string> &inputs);

// One frame of a sequence: its number and the paths it reads and writes ("" for an
// option not given).
struct SequenceFrame {
    int number = 0;
    std::string input, reference, output, preview;
    std::string map;  // --auto-map
};

// What the command line gave.
struct SequenceSpec {
    std::vector<std::string> inputs;  // files, or one pattern
    std::string output;               // a pattern, or a directory (ends in '/' or exists)
    std::string preview;              // "", a pattern or a directory
    std::string reference;            // "", a pattern or one file for every frame
    std::string frames;               // "" or ParseFrameRange's text
    std::string map;                  // --auto-map: "", a pattern or a directory
};

// Whether the inputs make a sequence: more than one, or one pattern that is not the name
// of an existing file. One plain file is the single-frame command, as it always was.
bool IsSequence(const std::vector<std::string> &inputs);

// Each frame with its paths. An input pattern with --frames gives every number in the
// range (a missing file fails that frame at run time); without, the files that exist.
// A list with --frames keeps the files whose numbers are in the range. Throws mcd::Error
// when no frame is left or an output is neither a pattern nor a directory.
std::vector<SequenceFrame> PlanSequence(const SequenceSpec &spec);

}  // namespace mcd::tool
