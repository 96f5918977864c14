#include "planeloc/io/json_text.h"

#include <fmt/format.h>

#include <algorithm>

#include "planeloc/util/error.h"

namespace planeloc {

int LineOfByte(const std::string& text, std::size_t byte) {
  const auto end = text.begin() + static_cast<std::ptrdiff_t>(std::min(byte, text.size()));
  return 1 + static_cast<int>(std::count(text.begin(), end, '\n'));
}

nlohmann::json ParseJsonText(const std::string& path, const std::string& text,
                             const std::string& fix) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& error) {
    throw InputError(path, LineOfByte(text, error.byte > 0 ? error.byte - 1 : 0),
                     fmt::format("invalid JSON: {}", error.what()), fix);
  } catch (const nlohmann::json::exception& error) {  // e.g. a number overflowing a double
    throw InputError(path, fmt::format("invalid JSON: {}", error.what()),
                     "fix the JSON; numbers must be finite doubles");
  }
}

}  // namespace planeloc
