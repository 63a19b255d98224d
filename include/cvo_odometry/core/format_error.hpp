#pragma once

#include <stdexcept>
#include <string>

namespace cvo {

// A malformed input file or value: the message names the file, the line and what was expected.
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace cvo
