// The project's exception: every user-facing failure (bad input, missing layer, Vulkan
// error) is an mcd::Error whose message says what and where.
#pragma once

#include <stdexcept>
#include <string>

namespace mcd {

class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace mcd
