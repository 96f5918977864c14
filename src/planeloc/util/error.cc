#include "planeloc/util/error.h"

#include <fmt/format.h>

namespace planeloc {
namespace {

std::string FormatInputError(const std::string& path, int line, const std::string& what,
                             const std::string& fix) {
  std::string where;
  if (!path.empty()) where = line > 0 ? fmt::format("{}:{}: ", path, line) : path + ": ";
  std::string message = where + what;
  if (!fix.empty()) message += fmt::format(" (fix: {})", fix);
  return message;
}

}  // namespace

InputError::InputError(std::string path, int line, std::string what, std::string fix)
    : std::runtime_error(FormatInputError(path, line, what, fix)),
      path_(std::move(path)),
      line_(line),
      problem_(std::move(what)),
      fix_(std::move(fix)) {}

}  // namespace planeloc
