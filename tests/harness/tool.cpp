#include "harness/tool.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

namespace fs = std::filesystem;

namespace mcd::test {

ToolDir::ToolDir(const std::string &prefix) {
    std::string name = prefix + "_" + std::to_string(::getpid()) + "_" +
                       std::to_string(std::random_device{}());
    dir = fs::temp_directory_path() / name;
    errFile = fs::temp_directory_path() / (name + ".stderr");
    fs::create_directories(dir);
}

ToolDir::~ToolDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
    fs::remove(errFile, ec);
}

// The tool of the build tree this test binary sits in (<build>/tests/<test> ->
// <build>/mcdenoise), so that a build tree copied elsewhere tests its own tool; else the
// path the build recorded.
static std::string ToolPath() {
    static const std::string path = [] {
        std::error_code ec;
        fs::path exe = fs::read_symlink("/proc/self/exe", ec);
        fs::path beside = exe.parent_path().parent_path() / "mcdenoise";
        return !ec && fs::is_regular_file(beside, ec) ? beside.string()
                                                      : std::string(MCD_TOOL_PATH);
    }();
    return path;
}

ToolResult ToolDir::Run(const std::string &args, const std::string &env) const {
    std::string command = "cd '" + dir.string() + "' && " + env + "'" + ToolPath() + "' " +
                          args + " 2>'" + errFile.string() + "'";
    ToolResult result;
    FILE *pipe = popen(command.c_str(), "r");
    if (!pipe) {
        ADD_FAILURE() << "popen failed for: " << command;
        return result;
    }
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.out.append(buffer, n);
    int status = pclose(pipe);
    if (WIFEXITED(status))
        result.code = WEXITSTATUS(status);
    else if (WIFSIGNALED(status))
        result.code = 128 + WTERMSIG(status);
    std::ifstream in(errFile, std::ios::binary);
    result.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return result;
}

std::vector<DiffRow> ParseDiffTable(const std::string &out) {
    std::vector<DiffRow> rows;
    std::istringstream lines(out);
    std::string line;
    std::getline(lines, line);  // title
    std::getline(lines, line);  // header
    while (std::getline(lines, line)) {
        // The last three fields are numbers (NMSE, max rel, parity); the rest is the name.
        std::istringstream fields(line);
        std::vector<std::string> words{std::istream_iterator<std::string>(fields), {}};
        if (words.size() < 4) continue;
        DiffRow row;
        for (size_t i = 0; i + 3 < words.size(); ++i) row.stage += (i ? " " : "") + words[i];
        row.nmse = std::stod(words[words.size() - 3]);
        row.maxRel = std::stod(words[words.size() - 2]);
        rows.push_back(row);
    }
    return rows;
}

}  // namespace mcd::test
