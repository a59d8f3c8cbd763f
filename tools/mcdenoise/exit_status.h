// What mcdenoise's exit status says, as git and cargo use theirs, and the one place where
// a failure becomes the status and the line the user reads.
#pragma once

#include <exception>
#include <string>

#include "host/error.h"

namespace mcd::tool {

// One status per mcd::ErrorKind, and 2 for a command line that does not parse. The table
// in docs/usage.md lists them; scripts may rely on them.
enum class ExitStatus : int {
    Success = 0,
    InvalidArgument = 1,  // a value or a combination of options the work cannot take
    Usage = 2,            // the command line is wrong
    Internal = 3,         // a bug: a failure of the tool itself
    MissingLayer = 4,     // the frame lacks a layer the method or an option needs
    NonFiniteInput = 5,   // NaN/Inf in an input that refuses them
    OutOfMemory = 6,      // host or device memory exhausted, or the work too large for it
    Device = 7,           // no usable Vulkan device, or the device or driver failed
    Io = 8,               // a file could not be read or written
    Cancelled = 9,        // the run was cancelled
};

struct Failure {
    ExitStatus status = ExitStatus::Internal;
    std::string message;  // what follows "mcdenoise: error: "
};

// The status of a library error kind.
ExitStatus StatusOf(ErrorKind kind);

// The kind of an exception a command threw: an mcd::Error's own; std::bad_alloc out of
// memory; a std::filesystem error I/O; anything else internal.
ErrorKind KindOf(const std::exception_ptr &error);

// The status and message of an exception a command threw. The library's error kinds map to
// statuses here, and only here.
Failure DescribeFailure(const std::exception_ptr &error);

// Print "mcdenoise: error: <message>" on stderr and return the status as main returns it.
int ReportFailure(const Failure &failure);

}  // namespace mcd::tool
