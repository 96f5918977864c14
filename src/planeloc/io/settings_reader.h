// Reader of OpenCV FileStorage settings files (the YAML dialect of ORB-SLAM2/ORB-SLAM3 settings).
//
// The dialect is not strict YAML 1.2: a `%YAML:1.0` header, `key:value` without a space, quoted
// strings (`Camera.type: "PinHole"`), `!!opencv-matrix` maps and `data:[...]` sequences. The file
// is parsed by cv::FileStorage itself (the parser ORB-SLAM uses); a syntax error becomes an
// InputError naming the file and the line OpenCV reports. Nested maps (`Camera: {fx: 1}`) are
// flattened to dotted keys (`Camera.fx`); an `!!opencv-matrix` (a map with `dt` and `data`) is one
// value. Keys get the 1-based line where they appear in the text (0 when not found).
//
// Typed getters record a problem (line, key, value, expected form) instead of throwing, so that
// every mistyped key of a file is reported in one error by ThrowIfErrors(). Every key that was
// read is marked used; Unused() lists the rest.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace planeloc {

// cv::FileStorage detects YAML by a `%YAML` header at the very first byte. Text without it
// (planeloc's own key lists, EuRoC's sensor.yaml, which starts with a comment) gets one; a header
// after leading blank lines or comments is blanked (the line stays, so line numbers do not move).
// Returns the number of lines added in front (0 or 1).
int NormalizeYamlHeader(std::string& text);
// OpenCV 4.6's YAML parser never returns on some inputs with a "---" document marker that has
// text after it on the same line, followed by more lines (fuzz finding: "---C: 0\n----\n1").
// Returns the 1-based line of the first line starting with "---" that is not a bare marker (or
// one before a comment), 0 if none: check it before handing text to cv::FileStorage.
int LineOfBadYamlDocumentMarker(const std::string& text);

class SettingsReader {
 public:
  struct Entry {
    std::string key;  // dotted
    cv::FileNode node;
    int line = 0;  // 1-based line of the key in the file, 0 when not found
    bool used = false;
  };

  // Reads and parses `path`. Throws InputError when the file cannot be read, is not valid
  // FileStorage YAML, or its top level is not a map.
  explicit SettingsReader(const std::filesystem::path& path);
  SettingsReader(const SettingsReader&) = delete;
  SettingsReader& operator=(const SettingsReader&) = delete;

  const std::filesystem::path& path() const { return path_; }
  const std::vector<Entry>& entries() const { return entries_; }
  bool Has(const std::string& key) const { return Find(key) != nullptr; }
  // True when some key starts with `prefix` (e.g. "LEFT.").
  bool HasPrefix(const std::string& prefix) const;
  // Line of `key` (its last occurrence), 0 when absent or not found in the text.
  int LineOf(const std::string& key) const;

  // The value of `key` (last occurrence wins), nullopt when absent. A value of the wrong type is
  // recorded as an error and returns nullopt. All of them mark the key used.
  std::optional<double> Number(const std::string& key);  // int or real
  // An int, or a real with an integral value (8.0).
  std::optional<int> Integer(const std::string& key);
  // 0/1, or the strings true/false (any case).
  std::optional<bool> Flag(const std::string& key);
  std::optional<std::string> String(const std::string& key);
  // An `!!opencv-matrix` of rows x cols (as CV_64F); -1 accepts any count.
  std::optional<cv::Mat> Matrix(const std::string& key, int rows, int cols);

  void MarkUsed(const std::string& key);
  // Records a problem with `key`: "line N: key = value: expected <expected>".
  void AddError(const std::string& key, const std::string& expected);
  // Records a problem not bound to one value (e.g. an inconsistent combination of keys).
  void AddProblem(int line, const std::string& message);
  bool HasErrors() const { return !errors_.empty(); }
  // Throws one InputError listing every recorded problem in line order (the first's line), if any.
  void ThrowIfErrors(const std::string& fix) const;

  // Entries never read, in file order.
  std::vector<const Entry*> Unused() const;

  // `node` as text for messages: numbers, "quoted strings", [a, b], a matrix's size.
  static std::string Describe(const cv::FileNode& node);

 private:
  Entry* Find(const std::string& key);
  const Entry* Find(const std::string& key) const;
  void Flatten(const cv::FileNode& node, const std::string& prefix);
  void FindLines(const std::string& text);

  std::filesystem::path path_;
  cv::FileStorage storage_;
  std::vector<Entry> entries_;
  std::vector<std::pair<int, std::string>> errors_;  // line (0: none), message
};

}  // namespace planeloc
