#include "planeloc/io/settings_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <exception>
#include <fstream>
#include <regex>
#include <sstream>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr const char* kSyntaxFix =
    "write OpenCV FileStorage YAML as ORB-SLAM settings files do: `Key: value` lines, strings in "
    "quotes, matrices as !!opencv-matrix";

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  CheckInput(in.good() && !std::filesystem::is_directory(path), path.string(), 0,
             "cannot open the settings file", "check the path given to --config");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// OpenCV 4.6 reports parse errors as "...(LINE): message..." (the line 1-based).
InputError SyntaxError(const std::filesystem::path& path, const cv::Exception& e, int added_lines) {
  static const std::regex kLine(R"(\((\d+)\): ([^'\n]*))");
  std::smatch match;
  const std::string what = e.what();
  if (std::regex_search(what, match, kLine)) {
    const int line = std::max(0, std::stoi(match[1].str()) - added_lines);
    return InputError(path.string(), line, "not a valid settings file: " + match[2].str(),
                      kSyntaxFix);
  }
  return InputError(path.string(), 0, "not a valid settings file: " + e.err, kSyntaxFix);
}

bool IsMatrixNode(const cv::FileNode& node) {
  return node.isMap() && !node["dt"].empty() && !node["data"].empty();
}

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

int NormalizeYamlHeader(std::string& text) {
  const bool starts_with_header = text.rfind("%YAML", 0) == 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    if (!(starts_with_header && start == 0) && text.compare(start, 5, "%YAML") == 0) {
      text.replace(start, end - start, "");
      end = start;
    }
    start = end + 1;
  }
  if (starts_with_header) return 0;
  text.insert(0, "%YAML:1.0\n");
  return 1;
}

int LineOfBadYamlDocumentMarker(const std::string& text) {
  int line = 1;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    if (text.compare(start, 3, "---") == 0) {
      const std::size_t rest = text.find_first_not_of(" \t\r", start + 3);
      if (rest < end && text[rest] != '#') return line;
    }
    start = end + 1;
    ++line;
  }
  return 0;
}

SettingsReader::SettingsReader(const std::filesystem::path& path) : path_(path) {
  std::string text = ReadText(path);
  const std::string original = text;
  if (const int line = LineOfBadYamlDocumentMarker(text)) {
    throw InputError(path.string(), line,
                     "not a valid settings file: a line starting with `---` that is not a "
                     "document marker",
                     "write `---` alone on its line (or remove it); comments start with `#`");
  }
  const int added_lines = NormalizeYamlHeader(text);
  try {
    storage_.open(text,
                  cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    throw SyntaxError(path, e, added_lines);
  } catch (const std::exception&) {
    // OpenCV's parser lets std::length_error escape on some malformed YAML (fuzz finding,
    // docs/reliability.md): bad input, not a crash.
    CheckInput(false, path.string(), 0, "not a valid settings file", kSyntaxFix);
  }
  CheckInput(storage_.isOpened(), path.string(), 0, "not a valid settings file", kSyntaxFix);
  const cv::FileNode root = storage_.root();
  if (root.empty() || root.isNone()) return;  // an empty file: every key has its default
  CheckInput(root.isMap(), path.string(), 0, "the settings file is not a map of keys",
             "write one `Key: value` line per setting");
  Flatten(root, "");
  FindLines(original);
}

void SettingsReader::Flatten(const cv::FileNode& node, const std::string& prefix) {
  for (auto it = node.begin(); it != node.end(); ++it) {
    const cv::FileNode child = *it;
    const std::string key = prefix + child.name();
    if (child.isMap() && !IsMatrixNode(child)) {
      Flatten(child, key + ".");
    } else {
      entries_.push_back({key, child, 0, false});
    }
  }
}

void SettingsReader::FindLines(const std::string& text) {
  // The key token at the start of each line ("  fx: 1" -> "fx"), empty when none.
  std::vector<std::string> tokens;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const std::string trimmed = Trim(line);
    const auto colon = trimmed.find(':');
    tokens.push_back(trimmed.empty() || trimmed[0] == '#' || trimmed[0] == '%' ||
                             colon == std::string::npos
                         ? ""
                         : Trim(trimmed.substr(0, colon)));
  }
  // Entries are in file order: search forward from the previous key's line first.
  std::size_t cursor = 0;
  for (Entry& entry : entries_) {
    const std::string last = entry.key.substr(entry.key.rfind('.') + 1);
    auto matches = [&](std::size_t i) { return tokens[i] == entry.key || tokens[i] == last; };
    std::size_t found = tokens.size();
    for (std::size_t i = cursor; i < tokens.size() && found == tokens.size(); ++i) {
      if (matches(i)) found = i;
    }
    for (std::size_t i = 0; i < cursor && found == tokens.size(); ++i) {
      if (matches(i)) found = i;
    }
    if (found == tokens.size()) continue;
    entry.line = static_cast<int>(found) + 1;
    cursor = found + 1;
  }
}

SettingsReader::Entry* SettingsReader::Find(const std::string& key) {
  for (auto it = entries_.rbegin(); it != entries_.rend(); ++it) {
    if (it->key == key) return &*it;
  }
  return nullptr;
}

const SettingsReader::Entry* SettingsReader::Find(const std::string& key) const {
  return const_cast<SettingsReader*>(this)->Find(key);
}

bool SettingsReader::HasPrefix(const std::string& prefix) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const Entry& e) { return e.key.rfind(prefix, 0) == 0; });
}

int SettingsReader::LineOf(const std::string& key) const {
  const Entry* entry = Find(key);
  return entry ? entry->line : 0;
}

void SettingsReader::MarkUsed(const std::string& key) {
  for (Entry& entry : entries_) {
    if (entry.key == key) entry.used = true;
  }
}

void SettingsReader::AddProblem(int line, const std::string& message) {
  errors_.emplace_back(line, line > 0 ? fmt::format("line {}: {}", line, message) : message);
}

void SettingsReader::AddError(const std::string& key, const std::string& expected) {
  const Entry* entry = Find(key);
  const std::string value = entry ? Describe(entry->node) : "(absent)";
  AddProblem(entry ? entry->line : 0,
             fmt::format("{} = {}: expected {}", key, value.empty() ? "(empty)" : value, expected));
}

std::optional<double> SettingsReader::Number(const std::string& key) {
  MarkUsed(key);
  const Entry* entry = Find(key);
  if (!entry) return std::nullopt;
  if (entry->node.isInt() || entry->node.isReal()) {
    const double value = static_cast<double>(entry->node);
    if (std::isfinite(value)) return value;
  }
  AddError(key, "a number");
  return std::nullopt;
}

std::optional<int> SettingsReader::Integer(const std::string& key) {
  MarkUsed(key);
  const Entry* entry = Find(key);
  if (!entry) return std::nullopt;
  if (entry->node.isInt()) return static_cast<int>(entry->node);
  if (entry->node.isReal()) {
    const double value = static_cast<double>(entry->node);
    if (value == std::floor(value) && std::abs(value) <= INT_MAX) return static_cast<int>(value);
  }
  AddError(key, "an integer");
  return std::nullopt;
}

std::optional<bool> SettingsReader::Flag(const std::string& key) {
  MarkUsed(key);
  const Entry* entry = Find(key);
  if (!entry) return std::nullopt;
  if (entry->node.isInt()) {
    const int value = static_cast<int>(entry->node);
    if (value == 0 || value == 1) return value == 1;
  }
  if (entry->node.isString()) {
    const std::string value = Lower(entry->node.string());
    if (value == "true" || value == "false") return value == "true";
  }
  AddError(key, "0, 1, true or false");
  return std::nullopt;
}

std::optional<std::string> SettingsReader::String(const std::string& key) {
  MarkUsed(key);
  const Entry* entry = Find(key);
  if (!entry) return std::nullopt;
  if (entry->node.isString()) return entry->node.string();
  AddError(key, "a string in quotes");
  return std::nullopt;
}

std::optional<cv::Mat> SettingsReader::Matrix(const std::string& key, int rows, int cols) {
  MarkUsed(key);
  const Entry* entry = Find(key);
  if (!entry) return std::nullopt;
  const std::string expected =
      fmt::format("a {}x{} !!opencv-matrix (rows, cols, dt, data)",
                  rows < 0 ? "N" : std::to_string(rows), cols < 0 ? "N" : std::to_string(cols));
  if (!IsMatrixNode(entry->node)) {
    AddError(key, expected);
    return std::nullopt;
  }
  // The size the node claims, checked against its data before OpenCV allocates it: a file that
  // claims 100000 x 100000 with four numbers would otherwise allocate 80 GB (fuzzing finding).
  const cv::FileNode rows_node = entry->node["rows"], cols_node = entry->node["cols"];
  const int claimed_rows = rows_node.isInt() ? static_cast<int>(rows_node) : -1;
  const int claimed_cols = cols_node.isInt() ? static_cast<int>(cols_node) : -1;
  constexpr int kMaxSide = 64;  // settings matrices are at most 4 x 4 (D: 1 x 14)
  if (claimed_rows < 1 || claimed_cols < 1 || claimed_rows > kMaxSide || claimed_cols > kMaxSide ||
      (rows >= 0 && claimed_rows != rows) || (cols >= 0 && claimed_cols != cols) ||
      entry->node["data"].size() != static_cast<std::size_t>(claimed_rows * claimed_cols)) {
    AddError(key, expected);
    return std::nullopt;
  }
  cv::Mat matrix;
  try {
    entry->node >> matrix;
  } catch (const cv::Exception&) {
    matrix.release();
  }
  if (matrix.empty() || (rows >= 0 && matrix.rows != rows) || (cols >= 0 && matrix.cols != cols) ||
      matrix.channels() != 1) {
    AddError(key, expected);
    return std::nullopt;
  }
  cv::Mat as_double;
  matrix.convertTo(as_double, CV_64F);
  if (!cv::checkRange(as_double)) {
    AddError(key, expected + " of finite numbers");
    return std::nullopt;
  }
  return as_double;
}

void SettingsReader::ThrowIfErrors(const std::string& fix) const {
  if (errors_.empty()) return;
  std::vector<std::pair<int, std::string>> sorted = errors_;
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
    return (a.first == 0 ? INT_MAX : a.first) < (b.first == 0 ? INT_MAX : b.first);
  });
  std::string all;
  for (const auto& e : sorted) all.append(all.empty() ? "" : "; ").append(e.second);
  throw InputError(path_.string(), sorted.front().first, "invalid settings: " + all, fix);
}

std::vector<const SettingsReader::Entry*> SettingsReader::Unused() const {
  std::vector<const Entry*> unused;
  for (const Entry& entry : entries_) {
    if (!entry.used) unused.push_back(&entry);
  }
  return unused;
}

std::string SettingsReader::Describe(const cv::FileNode& node) {
  if (node.isInt()) return std::to_string(static_cast<int>(node));
  if (node.isReal()) return fmt::format("{}", static_cast<double>(node));
  if (node.isString()) return fmt::format("\"{}\"", node.string());
  if (IsMatrixNode(node)) {
    return fmt::format("!!opencv-matrix {}x{}", Describe(node["rows"]), Describe(node["cols"]));
  }
  if (node.isSeq()) {
    std::string items;
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (items.size() > 60) {
        items += ", ...";
        break;
      }
      items.append(items.empty() ? "" : ", ").append(Describe(*it));
    }
    return fmt::format("[{}]", items);
  }
  if (node.isMap()) return "a map";
  return "";
}

}  // namespace planeloc
