// The built mcdenoise tool (MCD_TOOL_PATH) run as a subprocess in a temporary directory of
// its own, for the command-line tests.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace mcd::test {

struct ToolResult {
    int code = -1;  // exit status; 128 + signal when killed
    std::string out, err;
    std::string All() const { return out + err; }
};

// A fresh directory under the system's temporary directory, removed with the object.
class ToolDir {
  public:
    explicit ToolDir(const std::string &prefix);
    ~ToolDir();
    ToolDir(const ToolDir &) = delete;
    ToolDir &operator=(const ToolDir &) = delete;

    // Run the tool with `args` (shell words) in the directory; `env` is prepended to the
    // command (e.g. "VAR=value "). Stdout and stderr are captured apart.
    ToolResult Run(const std::string &args, const std::string &env = "") const;
    std::filesystem::path Path(const std::string &name) const { return dir / name; }
    const std::filesystem::path &Dir() const { return dir; }

  private:
    std::filesystem::path dir, errFile;
};

// A test that runs inside its own fresh directory (the working directory while it runs),
// with Touch to make placeholder files there.
class InToolDir : public ::testing::Test {
  protected:
    explicit InToolDir(const std::string &prefix) : dir(prefix) {}
    void SetUp() override {
        old = std::filesystem::current_path();
        std::filesystem::current_path(dir.Dir());
    }
    void TearDown() override { std::filesystem::current_path(old); }
    void Touch(const std::string &name) { std::ofstream(dir.Path(name)) << "frame"; }

    ToolDir dir;
    std::filesystem::path old;
};

// One row of `mcdenoise diff`'s table: the stage (its name may hold spaces), its NMSE and
// its largest relative error; ParseDiffTable gives them in the table's order.
struct DiffRow {
    std::string stage;
    double nmse = 0, maxRel = 0;
};
std::vector<DiffRow> ParseDiffTable(const std::string &out);

}  // namespace mcd::test
