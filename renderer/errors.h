// The two ways rayaudit stops early, mapped to exit codes by the CLI:
// InputError (bad input or usage: exit 2) and CheckFailed (exit 1).
// Messages are one line, "FILE:LINE: what is wrong" where a file is involved.
#pragma once
#include <stdexcept>
#include <string>

namespace ra {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct CheckFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "FILE:LINE: message" (LINE omitted when 0).
std::string located(const std::string& file, long line, const std::string& message);

}  // namespace ra
