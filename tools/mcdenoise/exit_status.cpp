#include "tools/mcdenoise/exit_status.h"

#include <cstdio>
#include <filesystem>
#include <new>

namespace mcd::tool {
namespace {

// What the user reads: an mcd::Error's message as it is, the others' with what they are.
std::string MessageOf(const std::exception_ptr &error) {
    try {
        std::rethrow_exception(error);
    } catch (const Error &e) {
        return e.what();
    } catch (const std::bad_alloc &) {
        return "out of memory";
    } catch (const std::filesystem::filesystem_error &e) {
        return e.what();
    } catch (const std::exception &e) {
        return std::string("internal error: ") + e.what();
    } catch (...) {
        return "internal error: an exception of unknown type";
    }
}

}  // namespace

ExitStatus StatusOf(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::InvalidArgument:
            return ExitStatus::InvalidArgument;
        case ErrorKind::MissingLayer:
            return ExitStatus::MissingLayer;
        case ErrorKind::NonFiniteInput:
            return ExitStatus::NonFiniteInput;
        case ErrorKind::OutOfMemory:
            return ExitStatus::OutOfMemory;
        case ErrorKind::Device:
            return ExitStatus::Device;
        case ErrorKind::Io:
            return ExitStatus::Io;
        case ErrorKind::Internal:
            return ExitStatus::Internal;
        case ErrorKind::Cancelled:
            return ExitStatus::Cancelled;
    }
    return ExitStatus::Internal;
}

ErrorKind KindOf(const std::exception_ptr &error) {
    try {
        std::rethrow_exception(error);
    } catch (const Error &e) {
        return e.Kind();
    } catch (const std::bad_alloc &) {
        return ErrorKind::OutOfMemory;
    } catch (const std::filesystem::filesystem_error &) {
        return ErrorKind::Io;
    } catch (...) {
        return ErrorKind::Internal;
    }
}

Failure DescribeFailure(const std::exception_ptr &error) {
    return {StatusOf(KindOf(error)), MessageOf(error)};
}

int ReportFailure(const Failure &failure) {
    std::fprintf(stderr, "mcdenoise: error: %s\n", failure.message.c_str());
    return int(failure.status);
}

}  // namespace mcd::tool
