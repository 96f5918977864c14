#include "planeloc/eval/html_page_kit.h"

#include <fstream>
#include <optional>
#include <sstream>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

#include "planeloc/eval/html_page_kit.inc"

std::optional<std::string> ReadIfExists(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

const char* PageKitHead() { return kKitHead; }
const char* PageKitStyle() { return kKitStyle; }
const char* PageKitScript() { return kKitScript; }

std::string ThreeJsScripts(const std::filesystem::path& three_js_dir) {
  const std::filesystem::path three = three_js_dir / "three.min.js";
  const std::optional<std::string> three_js = ReadIfExists(three);
  if (!three_js) {
    throw InputError(three.string(), "cannot read the file",
                     "install Debian's libjs-three (./scripts/setup.sh) or set "
                     "PLANELOC_THREE_JS_DIR to a folder with three.min.js");
  }
  // Debian's libjs-three (r111) ships OrbitControls as a classic script; without it the pages
  // fall back to their own orbit/zoom handling (simpleOrbit).
  const std::string orbit =
      ReadIfExists(three_js_dir / "examples/js/controls/OrbitControls.js").value_or("");
  std::string scripts = "<script>\n" + ScriptSafe(*three_js) + "\n</script>\n";
  if (!orbit.empty()) scripts += "<script>\n" + ScriptSafe(orbit) + "\n</script>\n";
  return scripts;
}

// In a classic <script>, only "</script" ends the element and "<!--" changes how it is parsed;
// both can appear in JavaScript only inside strings, regexes or comments, where "<\/" and "<\!"
// mean the same.
std::string ScriptSafe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] != '<') continue;
    if (text.compare(i + 1, 7, "/script") == 0 || text.compare(i + 1, 7, "/SCRIPT") == 0) {
      out += '\\';
    } else if (text.compare(i + 1, 3, "!--") == 0) {
      out += '\\';
    }
  }
  return out;
}

// '<' only occurs inside JSON strings, where \u003c is the same character.
std::string JsonScriptSafe(const std::string& json_text) {
  std::string out;
  out.reserve(json_text.size());
  for (char c : json_text) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace planeloc
