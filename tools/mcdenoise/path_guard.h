// The rule that no command writes over a file it reads: one check every writing command
// calls with its inputs and outputs before any work, so a typo (`denoise f.exr -o f.exr`)
// or an output pattern that matches the inputs cannot destroy a frame.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace mcd::tool {

// A path a command reads or writes, with how the command line names it ("input", "-o",
// "--preview", "--dump"), for the messages. An empty path is an option not given.
struct RolePath {
    std::string role;
    std::string path;
    std::string hint;  // for an input: what to do instead, appended to the message
};

// The extension of `path` in lower case (".EXR" -> ".exr"): file formats by their name,
// whatever its case.
std::string LowerExtension(const std::string &path);

// Whether a and b name one file: through symbolic or hard links when both exist, else
// by their canonical spellings (so "./a/../f.exr" matches "f.exr").
bool SameFile(const std::string &a, const std::string &b);

// Throw mcd::Error naming both paths when an output is one of the inputs or two outputs
// are one file.
void RefuseOverwritingInputs(const std::vector<RolePath> &inputs,
                             const std::vector<RolePath> &outputs);

// For an output directory whose file names are known only by their pattern until the
// work is done (diff's <stage>.gpu.exr): throw when an input lies in `dir`, as given or
// where its links lead, under a name `writes` says the command may write there.
void RefuseInputsInDirectory(const std::vector<RolePath> &inputs, const RolePath &dir,
                             const std::function<bool(const std::string &name)> &writes);

}  // namespace mcd::tool
