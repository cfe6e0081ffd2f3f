// The one exception type Tilth throws: its message says what went wrong, where, and
// what was expected.
#pragma once

#include <stdexcept>

namespace tilth {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tilth
