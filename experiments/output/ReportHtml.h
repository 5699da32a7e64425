// ReportHtml: the HTML pieces shared by the report and the diff pages: escaping, number and cell
// formatting, URLs of relative paths, the page style and the page-check script that the headless
// Chromium test reads.
// Thread safety: pure functions.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace experiments {

// A number as the report and diff pages show it: `significantDigits` (%g), integers whole when
// wholeIntegers (below 1e15), "NaN", "inf", "-inf".
std::string displayNumber(double value, int significantDigits, bool wholeIntegers = false);

// HTML pieces shared by the report and the diff pages.
std::string htmlEscape(const std::string& text);
// An inline <script> for <head> that, once the page has loaded, writes "PAGE-CHECK: OK (N images)"
// or "PAGE-CHECK: FAILED" plus one line per script error or image that failed to load into the
// element with id "page-check" (which the page must contain).
const char* pageCheckScript();

// A relative path as a URL: every byte outside the unreserved set and '/' percent-encoded.
std::string urlPath(const std::string& path);

// Integers without a fraction, everything else with 4 significant digits.
std::string formatTableNumber(double value);

// A results cell as HTML: "&mdash;" for null, numbers by formatNumber, strings escaped.
std::string formatCell(const nlohmann::json& value);

// formatCell, with the suffix after a non-null value.
std::string formatOptional(const nlohmann::json& value, const char* suffix = "");

// A published metric (a column or a list of columns summed) as text: "a + b".
std::string metricLabel(const nlohmann::json& metric);

// object[key] when it is a string, else "".
std::string stringField(const nlohmann::json& object, const char* key);

// The report's <style> and its column-toggle <script>, for <head>.
const char* reportStyle();

} // namespace experiments
