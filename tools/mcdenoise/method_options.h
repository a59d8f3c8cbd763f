// Every method's parameters (mcd::Method::Params) as options of a command: --<name>, the
// help prefixed with the method's name, the library's default shown.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

#include "mcdenoise/mcdenoise.h"

namespace mcd::tool {

class MethodOptions {
  public:
    // Add the options of `method` ("auto": every method) and those all methods share to
    // `command`.
    void Add(CLI::App *command, const std::string &method = "auto");
    // The method `name` with the parameters given on the command line set; given options
    // of other methods are ignored, as they always were.
    Method Make(const std::string &name) const;
    // "awr, bayes, pivot, rhf"; auto (the default) and each method with its summary, one a
    // line.
    static std::string Names();
    static std::string Summaries();

  private:
    struct Bound {
        ParamInfo info;
        CLI::Option *option = nullptr;
        bool flag = false;
        int integer = 0;
        float number = 0;
        std::string text;
    };
    std::vector<std::shared_ptr<Bound>> bound;
};

}  // namespace mcd::tool
