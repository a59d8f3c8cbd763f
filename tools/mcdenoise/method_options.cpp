#include "tools/mcdenoise/method_options.h"

#include <fmt/format.h>

#include <algorithm>

#include "tools/mcdenoise/usage.h"

namespace mcd::tool {

namespace {

// The help's order: the options of every method, then auto's, then each method's.
int GroupRank(const ParamInfo &info) {
    return info.method.empty() ? 0 : info.method == "auto" ? 1 : 2;
}

}  // namespace

void MethodOptions::Add(CLI::App *command, const std::string &method) {
    Method params(method);  // named: a temporary's Params() would dangle in the loop
    std::vector<ParamInfo> infos = params.Params();
    std::stable_sort(infos.begin(), infos.end(), [](const ParamInfo &a, const ParamInfo &b) {
        return GroupRank(a) < GroupRank(b);
    });
    AddParams(command, std::move(infos));
}

void MethodOptions::AddParams(CLI::App *command, std::vector<ParamInfo> infos) {
    for (const ParamInfo &info : infos) {
        auto b = std::make_shared<Bound>();
        b->info = info;
        std::string flag = "--" + info.name;
        switch (info.type) {
            case ParamType::Bool:
                b->option = command->add_flag(flag, b->flag, info.help);
                break;
            case ParamType::Int:
                b->integer = std::get<int>(info.defaultValue);
                b->option =
                    command->add_option(flag, b->integer, info.help)->capture_default_str();
                CheckRange(b->option, info.min, info.max, true);
                break;
            case ParamType::Float:
                b->number = std::get<float>(info.defaultValue);
                b->option =
                    command->add_option(flag, b->number, info.help)->capture_default_str();
                CheckRange(b->option, float(info.min), float(info.max), false);
                break;
            case ParamType::String:
                b->text = std::get<std::string>(info.defaultValue);
                b->option = command->add_option(flag, b->text, info.help);
                if (!b->text.empty()) b->option->capture_default_str();
                if (!info.choices.empty()) CheckChoice(b->option, info.choices);
                break;
        }
        b->option->group(info.method.empty()         ? "Every method"
                         : info.method == "temporal" ? "Sequences (temporal mode)"
                                                     : "Method " + info.method);
        bound.push_back(b);
    }
}

bool MethodOptions::Given(const std::string &name) const {
    for (const auto &b : bound)
        if (b->info.name == name && b->option->count() > 0) return true;
    return false;
}

std::vector<ParamInfo> MethodOptions::GivenNotTaken(
    const std::function<bool(const std::string &)> &takes) const {
    std::vector<ParamInfo> infos;
    for (const auto &b : bound)
        if (b->option->count() > 0 && !takes(b->info.name)) infos.push_back(b->info);
    return infos;
}

Method MethodOptions::Make(const std::string &name) const {
    Method method(name);
    Apply(method);
    return method;
}

std::string MethodOptions::Names() {
    std::string names;
    for (const std::string &m : MethodNames()) names += (names.empty() ? "" : ", ") + m;
    return names;
}

std::string MethodOptions::Summaries() {
    std::string text = fmt::format("\n  auto (the default): {}", Method("auto").Summary());
    for (const std::string &m : MethodNames())
        text += fmt::format("\n  {}: {}", m, Method(m).Summary());
    return text;
}

}  // namespace mcd::tool
