// Helpers for tests of error paths.
#pragma once

#include <exception>
#include <string>

#include "host/error.h"

namespace mcd::test {

// The message of the mcd::Error that f throws, or a marker saying it threw none (or
// something else).
template <typename F>
std::string ErrorOf(F &&f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    } catch (const std::exception &e) {
        return std::string("<not an mcd::Error: ") + e.what() + ">";
    }
    return "<no error>";
}

inline bool Contains(const std::string &text, const std::string &part) {
    return text.find(part) != std::string::npos;
}

}  // namespace mcd::test
