#include "tools/mcdenoise/method_options.h"

#include <fmt/format.h>

namespace mcd::tool {

void MethodOptions::Add(CLI::App *command, const std::string &method) {
    Method params(method);  // named: a temporary's Params() would dangle in the loop
    for (const ParamInfo &info : params.Params()) {
        auto b = std::make_shared<Bound>();
        b->info = info;
        std::string flag = "--" + info.name;
        std::string help = info.method.empty() ? info.help : info.method + ": " + info.help;
        switch (info.type) {
            case ParamType::Bool:
                b->option = command->add_flag(flag, b->flag, help);
                break;
            case ParamType::Int:
                b->integer = std::get<int>(info.defaultValue);
                b->option = command->add_option(flag, b->integer, help)
                                ->capture_default_str()
                                ->check(CLI::Range(int(info.min), int(info.max)));
                break;
            case ParamType::Float:
                b->number = std::get<float>(info.defaultValue);
                b->option = command->add_option(flag, b->number, help)
                                ->capture_default_str()
                                ->check(CLI::Range(float(info.min), float(info.max)));
                break;
            case ParamType::String:
                b->text = std::get<std::string>(info.defaultValue);
                b->option = command->add_option(flag, b->text, help);
                if (!b->text.empty()) b->option->capture_default_str();
                break;
        }
        bound.push_back(b);
    }
}

Method MethodOptions::Make(const std::string &name) const {
    Method method(name);
    for (const auto &b : bound) {
        if (b->option->count() == 0 || !method.HasParam(b->info.name)) continue;
        switch (b->info.type) {
            case ParamType::Bool:
                method.Set(b->info.name, b->flag);
                break;
            case ParamType::Int:
                method.Set(b->info.name, b->integer);
                break;
            case ParamType::Float:
                method.Set(b->info.name, b->number);
                break;
            case ParamType::String:
                method.Set(b->info.name, b->text);
                break;
        }
    }
    return method;
}

std::string MethodOptions::Names() {
    std::string names;
    for (const std::string &m : MethodNames()) names += (names.empty() ? "" : ", ") + m;
    return names;
}

std::string MethodOptions::Summaries() {
    std::string text;
    for (const std::string &m : MethodNames())
        text += fmt::format("\n  {}: {}", m, Method(m).Summary());
    return text;
}

}  // namespace mcd::tool
