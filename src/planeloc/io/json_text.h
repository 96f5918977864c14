// JSON documents read for the user (planes.json, map updates): parse errors as InputError naming
// the file and the line.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace planeloc {

// 1-based line of a byte offset of `text`.
int LineOfByte(const std::string& text, std::size_t byte);

// Parses `text`, the contents of `path`. A syntax error is an InputError naming the path and the
// line with `fix`; a value nlohmann cannot hold (a number overflowing a double) one naming the
// path, asking for finite numbers.
nlohmann::json ParseJsonText(const std::string& path, const std::string& text,
                             const std::string& fix);

}  // namespace planeloc
