// A well-formed frame that yields no usable point (no valid depth, everything in ignored
// classes): for odometry a lost frame, unlike malformed input (std::invalid_argument), which is
// skipped.
#pragma once

#include <stdexcept>
#include <string>

namespace cvo {

class EmptyFrameError : public std::invalid_argument {
 public:
  explicit EmptyFrameError(const std::string& what) : std::invalid_argument(what) {}
};

}  // namespace cvo
