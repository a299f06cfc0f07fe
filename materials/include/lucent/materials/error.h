// The one exception type lucent throws for bad input: its message is the single line a user sees.
#pragma once

#include <stdexcept>
#include <string>

namespace lucent {

/// Bad input or an unusable setting. The message names the file, field or option and what was
/// expected; the CLI prints it on one line and exits non-zero.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace lucent
