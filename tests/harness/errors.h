// Helpers for tests of error paths: which kind of mcd::Error a call throws, and its message
// where the wording itself is what a test checks (what and where).
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <optional>
#include <ostream>
#include <string>

#include "host/error.h"

namespace mcd {

// gtest prints a kind by its name.
inline void PrintTo(ErrorKind kind, std::ostream *os) {
    *os << ErrorKindName(kind);
}

namespace test {

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

// What f throws, caught from one call (for reads whose outcome the test cannot foresee):
// none, or an mcd::Error's kind and message; another exception is Internal, its message
// marked.
struct Thrown {
    ErrorKind kind;
    std::string message;
};

template <typename F>
std::optional<Thrown> ThrownBy(F &&f) {
    try {
        f();
    } catch (const Error &e) {
        return Thrown{e.Kind(), e.what()};
    } catch (const std::exception &e) {
        return Thrown{ErrorKind::Internal,
                      std::string("<not an mcd::Error: ") + e.what() + ">"};
    }
    return std::nullopt;
}

// Whether `text` holds `part`; a failure quotes both, so a test's message shows the text.
inline ::testing::AssertionResult Contains(const std::string &text, const std::string &part) {
    if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "'" << text << "' does not contain '" << part << "'";
}

// Whether f throws an mcd::Error of `kind` (whose message holds `part`, when one is given:
// for the tests of what a message names).
template <typename F>
::testing::AssertionResult ThrowsError(ErrorKind kind, F &&f, const std::string &part = "") {
    try {
        f();
    } catch (const Error &e) {
        if (e.Kind() != kind)
            return ::testing::AssertionFailure()
                   << "threw a " << ErrorKindName(e.Kind()) << " error, not "
                   << ErrorKindName(kind) << ": " << e.what();
        if (!Contains(e.what(), part))
            return ::testing::AssertionFailure()
                   << "'" << e.what() << "' does not contain '" << part << "'";
        return ::testing::AssertionSuccess() << e.what();
    } catch (const std::exception &e) {
        return ::testing::AssertionFailure()
               << "threw something else than an mcd::Error: " << e.what();
    }
    return ::testing::AssertionFailure()
           << "threw nothing, not a " << ErrorKindName(kind) << " error";
}

}  // namespace test
}  // namespace mcd
