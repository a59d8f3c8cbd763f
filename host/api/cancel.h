// RunOptions::cancel for the length of one run: the device's context polls it before each
// submission (vk::Context::SetCancel), and a cancelled run ends in one kind of error
// however the method below handled the failed submission (auto leaves a candidate out).
#pragma once

#include <functional>
#include <utility>

#include "host/vk/context.h"
#include "mcdenoise/error.h"

namespace mcd::api {

class CancelScope {
  public:
    CancelScope(vk::Context &context, std::function<bool()> poll) : context(context) {
        if (!poll) return;
        // Once cancelled, every later submission of the run fails too.
        context.SetCancel([this, poll = std::move(poll)] {
            if (!cancelled && poll()) cancelled = true;
            return cancelled;
        });
    }
    ~CancelScope() { context.SetCancel(nullptr); }
    CancelScope(const CancelScope &) = delete;
    CancelScope &operator=(const CancelScope &) = delete;

    void ThrowIfCancelled() const {
        if (cancelled)
            throw Error(
                "the run was cancelled (its cancel or progress function asked to stop); "
                "nothing was written",
                ErrorKind::Cancelled);
    }

  private:
    vk::Context &context;
    bool cancelled = false;
};

}  // namespace mcd::api
