// The C API's handles and error plumbing (include/mcdenoise/mcdenoise_c.h), shared by the
// core's functions (c_api.cpp) and the I/O library's (host/io/c_api_io.cpp).
#pragma once

#include <mutex>
#include <new>
#include <set>
#include <string>
#include <vector>

#include "mcdenoise/mcdenoise.h"
#include "mcdenoise/mcdenoise_c.h"

struct MCDDeviceImpl {
    mcd::Device device;
    std::string name;
};

// The strings a handle handed out, each kept until the handle is released (the header's
// promise): a set's elements never move, and a string asked for again is not stored twice
// (so the set grows by the distinct texts read). Locked: getters on one handle may overlap.
struct HandedStrings {
    const char *Keep(const std::string &text) {
        std::lock_guard<std::mutex> lock(mutex);
        return kept.insert(text).first->c_str();
    }
    std::set<std::string> kept;
    std::mutex mutex;
};

struct MCDFrameImpl {
    mcd::Frame frame;
    HandedStrings handed;  // mcdGetFrameLayerName's strings
};

struct MCDMethodImpl {
    mcd::Method method;
    std::string summary;
    HandedStrings handed;  // mcdGetMethodParamText's strings
    MCDProgressFunction progress = nullptr;
    void *progressUser = nullptr;
};

struct MCDResultImpl {
    mcd::Result result;
};

namespace mcd::api {

// Record an error for the calling thread (mcdGetError).
void SetLastError(MCDError code, const std::string &message);
MCDError ErrorCode(ErrorKind kind);

// Run `body`, turning an exception into the thread's error and `failure`.
template <class R, class Body>
R Guarded(R failure, Body &&body) {
    try {
        return body();
    } catch (const Error &e) {
        SetLastError(ErrorCode(e.Kind()), e.what());
    } catch (const std::bad_alloc &) {
        SetLastError(MCD_ERROR_OUT_OF_MEMORY, "out of host memory");
    } catch (const std::exception &e) {
        SetLastError(MCD_ERROR_INTERNAL, e.what());
    } catch (...) {
        SetLastError(MCD_ERROR_INTERNAL, "an unknown exception");
    }
    return failure;
}

// Throw mcd::Error (invalid argument) naming `what` when `pointer` is null.
void Require(const void *pointer, const char *what);

// A C view as the C++ one (its format checked).
LayerView LayerViewOf(const MCDView &view);
OutputView OutputViewOf(const MCDView &view);

}  // namespace mcd::api
