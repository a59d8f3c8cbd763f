// The project's exception: every user-facing failure (bad input, missing layer, Vulkan
// error) is an mcd::Error whose message says what and where, and whose kind says which
// sort of failure it is (the C API's MCDError codes, one to one).
#pragma once

#include <stdexcept>
#include <string>

namespace mcd {

// What went wrong, for a caller that reacts per kind (the command line's exit codes, the
// C API's codes, the Python module's exception classes).
enum class ErrorKind {
    InvalidArgument = 1,  // a parameter, view or option the call cannot take
    MissingLayer,         // the frame lacks a layer the method or the caller asked for
    NonFiniteInput,       // NaN/Inf in an input layer under the refuse policy
    OutOfMemory,          // host or device memory exhausted, or the work beyond the
                          // device's memory or one buffer binding (split it, or tile)
    Device,               // no usable Vulkan device, or the device or driver failed
    Io,                   // a file could not be read or written
    Internal,             // a failure of the library itself (a bug)
    Cancelled,            // RunOptions::cancel stopped the run
};

// The kind's name in words ("invalid argument", "missing layer", ...).
inline const char *ErrorKindName(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::InvalidArgument:
            return "invalid argument";
        case ErrorKind::MissingLayer:
            return "missing layer";
        case ErrorKind::NonFiniteInput:
            return "non-finite input";
        case ErrorKind::OutOfMemory:
            return "out of memory";
        case ErrorKind::Device:
            return "device";
        case ErrorKind::Io:
            return "I/O";
        case ErrorKind::Internal:
            return "internal";
        case ErrorKind::Cancelled:
            return "cancelled";
    }
    return "unknown";
}

class Error : public std::runtime_error {
  public:
    // A throw site that names no kind is Internal until it is given one.
    explicit Error(const std::string &message, ErrorKind kind = ErrorKind::Internal)
        : std::runtime_error(message), kind(kind) {}
    explicit Error(const char *message, ErrorKind kind = ErrorKind::Internal)
        : std::runtime_error(message), kind(kind) {}
    Error(ErrorKind kind, const std::string &message) : Error(message, kind) {}

    ErrorKind Kind() const noexcept { return kind; }

  private:
    ErrorKind kind;
};

}  // namespace mcd
