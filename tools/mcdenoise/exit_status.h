// What mcdenoise's exit status says, as git and cargo use theirs, and the one place where
// a failure becomes the status and the line the user reads.
#pragma once

#include <exception>
#include <string>

namespace mcd::tool {

enum class ExitStatus : int {
    Success = 0,
    Failure = 1,   // the work failed: bad input, a device or I/O error
    Usage = 2,     // the command line is wrong
    Internal = 3,  // a bug: an exception the tool did not expect
};

struct Failure {
    ExitStatus status = ExitStatus::Failure;
    std::string message;  // what follows "mcdenoise: error: "
};

// The status and message of an exception a command threw. The library's error kinds map to
// statuses here, and only here.
Failure DescribeFailure(const std::exception &error);

// Print "mcdenoise: error: <message>" on stderr and return the status as main returns it.
int ReportFailure(const Failure &failure);

}  // namespace mcd::tool
