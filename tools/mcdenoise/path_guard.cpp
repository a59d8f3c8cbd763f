#include "tools/mcdenoise/path_guard.h"

#include <fmt/format.h>

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <map>
#include <system_error>

#include "host/error.h"

namespace mcd::tool {

namespace {

namespace fs = std::filesystem;

// The path with every existing part resolved (links, "..", "."), absolute.
fs::path Canonical(const std::string &path) {
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(fs::absolute(path, ec), ec);
    if (ec) canonical = fs::absolute(path, ec).lexically_normal();
    return canonical;
}

// What SameFile compares: an existing file by its device and inode (links and hard links
// alike), any other path by its canonical spelling.
std::string FileKey(const std::string &path) {
    struct stat info;
    if (::stat(path.c_str(), &info) == 0)
        return fmt::format("inode {}:{}", uint64_t(info.st_dev), uint64_t(info.st_ino));
    return "path " + Canonical(path).string();
}

std::string Describe(const RolePath &p) {
    return fmt::format("{} '{}'", p.role, p.path);
}

}  // namespace

std::string LowerExtension(const std::string &path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

bool SameFile(const std::string &a, const std::string &b) {
    std::error_code ec;
    // Hard links and symbolic links to one file: only the file system knows.
    if (fs::exists(a, ec) && fs::exists(b, ec)) {
        bool same = fs::equivalent(a, b, ec);
        if (!ec) return same;
    }
    return Canonical(a) == Canonical(b);
}

void RefuseOverwritingInputs(const std::vector<RolePath> &inputs,
                             const std::vector<RolePath> &outputs) {
    // One key per path, so a sequence's thousands of frames are checked in one pass:
    // SameFile(a, b) exactly when FileKey(a) == FileKey(b).
    std::map<std::string, size_t> inputByKey, outputByKey;
    for (size_t i = 0; i < inputs.size(); ++i)
        if (!inputs[i].path.empty()) inputByKey.emplace(FileKey(inputs[i].path), i);
    for (size_t o = 0; o < outputs.size(); ++o) {
        const RolePath &out = outputs[o];
        if (out.path.empty()) continue;
        std::string key = FileKey(out.path);
        if (auto it = inputByKey.find(key); it != inputByKey.end()) {
            const RolePath &in = inputs[it->second];
            throw Error(
                fmt::format(
                    "{} would overwrite {}: they are the same file{}; nothing was written{}",
                    Describe(out), Describe(in),
                    out.path == in.path ? ""
                                        : fmt::format(" ({})", Canonical(in.path).string()),
                    in.hint.empty() ? "" : "; " + in.hint),
                ErrorKind::InvalidArgument);
        }
        // Two outputs on one file: the second would silently replace the first.
        if (auto [it, added] = outputByKey.emplace(key, o); !added)
            throw Error(fmt::format("{} and {} are the same file; nothing was written",
                                    Describe(outputs[it->second]), Describe(out)),
                        ErrorKind::InvalidArgument);
    }
}

void RefuseInputsInDirectory(const std::vector<RolePath> &inputs, const RolePath &dir,
                             const std::function<bool(const std::string &name)> &writes) {
    if (dir.path.empty()) return;
    fs::path canonicalDir = Canonical(dir.path);
    for (const RolePath &in : inputs) {
        if (in.path.empty()) continue;
        // The input's own entry (a link in dir is replaced) and the file it leads to.
        fs::path given = Canonical(fs::path(in.path).parent_path().empty()
                                       ? "."
                                       : fs::path(in.path).parent_path().string()) /
                         fs::path(in.path).filename();
        for (const fs::path &p : {given, Canonical(in.path)})
            if (p.parent_path() == canonicalDir && writes(p.filename().string()))
                throw Error(
                    fmt::format("{} '{}' would write over {} ({}); nothing was written{}",
                                dir.role, dir.path, Describe(in), p.string(),
                                in.hint.empty() ? "" : "; " + in.hint),
                    ErrorKind::InvalidArgument);
    }
}

}  // namespace mcd::tool
