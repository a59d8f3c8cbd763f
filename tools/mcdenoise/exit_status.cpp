#include "tools/mcdenoise/exit_status.h"

#include <cstdio>
#include <filesystem>
#include <new>

#include "host/error.h"

namespace mcd::tool {

Failure DescribeFailure(const std::exception &error) {
    if (dynamic_cast<const Error *>(&error)) return {ExitStatus::Failure, error.what()};
    if (dynamic_cast<const std::bad_alloc *>(&error))
        return {ExitStatus::Failure, "out of memory"};
    if (dynamic_cast<const std::filesystem::filesystem_error *>(&error))
        return {ExitStatus::Failure, error.what()};
    return {ExitStatus::Internal, std::string("internal error: ") + error.what()};
}

int ReportFailure(const Failure &failure) {
    std::fprintf(stderr, "mcdenoise: error: %s\n", failure.message.c_str());
    return int(failure.status);
}

}  // namespace mcd::tool
