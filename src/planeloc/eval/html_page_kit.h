// What the pages of `planeloc report` and of the live view (`planeloc run --view`) share, so that
// both look the same and draw the 3-D scene with the same code: the head that records the page's
// own errors (window 'error' events and console.error into window.__reportErrors), the style, the
// script of helpers and 3-D scene functions (el, fmt, scaleColor, addPlanes, addTrack, frameView,
// attachOrbit, ...), three.js, and escaping for inlined text.
#pragma once

#include <filesystem>
#include <string>

namespace planeloc {

// "<!doctype html><html><head>..." up to and including the error-recording script; the caller
// adds <title>, PageKitStyle(), its own style and "</head>".
const char* PageKitHead();
// The <style> element of both pages.
const char* PageKitStyle();
// The shared JavaScript (no <script> tags); needs three.js loaded before it.
const char* PageKitScript();
// three.min.js and, when there, examples/js/controls/OrbitControls.js from `three_js_dir`, each
// in a <script> element. Throws InputError naming three.min.js when it is missing.
std::string ThreeJsScripts(const std::filesystem::path& three_js_dir);

// Text safe inside a classic <script> element ("</script" and "<!--" escaped).
std::string ScriptSafe(const std::string& text);
// JSON text safe inside <script type="application/json"> ('<' as \u003c).
std::string JsonScriptSafe(const std::string& json_text);
std::string HtmlEscape(const std::string& text);

}  // namespace planeloc
