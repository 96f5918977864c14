// Typed errors thrown by the planeloc library and caught at the CLI boundary (apps/main.cc).
//
// InputError: the user's input is wrong (missing file, bad number, corrupt image, wrong
// calibration, empty map, ...). It names the file, the 1-based line when there is one, what is
// wrong and how to fix it. The CLI prints it as one message and exits with code 2. Anything else
// (std::logic_error, std::runtime_error) is an internal error: exit code 1. The library never calls
// exit().
#pragma once

#include <stdexcept>
#include <string>

namespace planeloc {

class InputError : public std::runtime_error {
 public:
  // `path` may be empty when the error is not about one file (e.g. a bad CLI value);
  // `line` is 1-based, 0 when not applicable; `fix` tells the user what to do.
  InputError(std::string path, int line, std::string what, std::string fix);
  InputError(std::string path, std::string what, std::string fix)
      : InputError(std::move(path), 0, std::move(what), std::move(fix)) {}

  const std::string& path() const { return path_; }
  int line() const { return line_; }
  const std::string& problem() const { return problem_; }
  const std::string& fix() const { return fix_; }

 private:
  std::string path_;
  int line_ = 0;
  std::string problem_;
  std::string fix_;
};

// Throws InputError(path, line, what, fix) when `condition` is false.
inline void CheckInput(bool condition, const std::string& path, int line, const std::string& what,
                       const std::string& fix) {
  if (!condition) throw InputError(path, line, what, fix);
}

// Thrown by an `Options::Check()`-style validation; names the offending field.
class OptionsError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace planeloc
