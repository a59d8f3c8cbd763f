// Every method's parameters (mcd::Method::Params) as options of a command: --<name>, the
// help prefixed with the method's name, the library's default shown.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
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
    // Add these parameters (another object's, such as mcd::Temporal's) to `command`.
    void AddParams(CLI::App *command, std::vector<ParamInfo> infos);
    // The method `name` with the parameters given on the command line set; given options
    // of other methods are ignored, as they always were.
    Method Make(const std::string &name) const;
    // Whether the command line gave the parameter `name`.
    bool Given(const std::string &name) const;
    // The parameters the command line gave whose name `takes` refuses: those of a method
    // that does not run.
    std::vector<ParamInfo> GivenNotTaken(
        const std::function<bool(const std::string &)> &takes) const;
    // Set on `target` (a Method or a Temporal) the given options it has.
    template <class Target>
    void Apply(Target &target) const;
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

template <class Target>
void MethodOptions::Apply(Target &target) const {
    for (const auto &b : bound) {
        if (b->option->count() == 0 || !target.HasParam(b->info.name)) continue;
        switch (b->info.type) {
            case ParamType::Bool:
                target.Set(b->info.name, b->flag);
                break;
            case ParamType::Int:
                target.Set(b->info.name, b->integer);
                break;
            case ParamType::Float:
                target.Set(b->info.name, b->number);
                break;
            case ParamType::String:
                target.Set(b->info.name, b->text);
                break;
        }
    }
}

}  // namespace mcd::tool
