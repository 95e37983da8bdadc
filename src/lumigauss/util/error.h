#pragma once
// Errors the user can act on: every failure that comes from input names the file (and record or line)
// and says what is wrong. Thrown by the library, caught once in the CLI, which prints it and exits non-zero.
#include <stdexcept>
#include <string>

namespace lumigauss {

class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// "FILE: what is wrong" -- the one message shape for input errors.
[[noreturn]] inline void fail_in_file(const std::string& file, const std::string& what) {
    throw Error(file + ": " + what);
}

}  // namespace lumigauss
