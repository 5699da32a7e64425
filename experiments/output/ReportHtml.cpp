#include "experiments/output/ReportHtml.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "scenes/input/MessageText.h"

namespace experiments {

using nlohmann::json;

namespace {

// Records script errors and images that fail to load into #page-check once the page has
// loaded: "PAGE-CHECK: OK (N images)" or "PAGE-CHECK: FAILED" and one problem per line. Runs
// in <head>, before any <img>, so that no load error is missed.
constexpr const char* kPageCheckScript = R"(<script>
(function () {
  var problems = [];
  window.addEventListener('error', function (e) {
    var t = e.target;
    if (t && t.tagName === 'IMG') problems.push('image failed to load: ' + t.getAttribute('src'));
    else problems.push('script error: ' + (e.message || e));
  }, true);
  window.addEventListener('load', function () {
    var images = document.images;
    for (var i = 0; i < images.length; ++i) {
      if (!images[i].complete || images[i].naturalWidth === 0)
        problems.push('image not loaded: ' + images[i].getAttribute('src'));
    }
    var check = document.getElementById('page-check');
    check.textContent = problems.length === 0 ? 'PAGE-CHECK: OK (' + images.length + ' images)'
                                              : 'PAGE-CHECK: FAILED\n' + problems.join('\n');
    check.setAttribute('data-status', problems.length === 0 ? 'ok' : 'failed');
  });
})();
</script>
)";

constexpr const char* kStyle = R"(<style>
body { font-family: DejaVu Sans, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.25em; margin-top: 2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; font-size: 0.8em; margin: 0.5em 0; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; white-space: nowrap; }
th { background: #eee; position: sticky; top: 0; }
td.text, th.text { text-align: left; }
tr.failed td { background: #fdd; }
td.error { color: #a00; text-align: left; white-space: normal; min-width: 20em; }
.scroll { overflow: auto; max-height: 40em; border: 1px solid #ddd; }
figure { display: inline-block; margin: 0.5em; vertical-align: top; }
figure img { max-width: 640px; border: 1px solid #ddd; }
figcaption { font-size: 0.8em; max-width: 640px; }
.note { color: #666; font-style: italic; }
.finding { background: #f6f6e8; border-left: 4px solid #cc9; padding: 0.5em; max-width: 60em; }
.thumbs td { vertical-align: top; text-align: left; white-space: normal; }
.thumbs img { display: block; }
.missing { color: #999; font-style: italic; }
#page-check { font-size: 0.7em; color: #888; }
table.results.compact .extra { display: none; }
section.group { border-left: 4px solid #9bd; padding-left: 0.8em; margin: 1.5em 0; }
details.per-view { margin: 0.3em 0 1em 0; } details.per-view summary { cursor: pointer; }
section.view-family { border-left: 4px solid #bd9; padding-left: 0.8em; margin: 1.5em 0; }
.flip-note, .counts-note { background: #fff4e0; border-left: 4px solid #e90; padding: 0.5em;
  max-width: 60em; }
</style>
<script>
function toggleColumns(button) {
  var table = document.getElementById('results-table');
  var compact = table.classList.toggle('compact');
  button.textContent = compact ? 'Show all columns' : 'Show the main columns only';
}
// Clicking a results-table header sorts the rows by that column: numbers numerically (missing
// values last), text alphabetically; a second click reverses the order.
function sortResults(header) {
  var table = document.getElementById('results-table');
  var index = Array.prototype.indexOf.call(header.parentNode.children, header);
  var rows = Array.prototype.slice.call(table.rows, 1);
  var descending = header.getAttribute('data-sorted') === 'ascending';
  var key = function (row) {
    var text = row.cells[index] ? row.cells[index].textContent : '';
    var number = parseFloat(text);
    return isNaN(number) ? text : number;
  };
  rows.sort(function (a, b) {
    var x = key(a), y = key(b);
    if (typeof x !== typeof y) return typeof x === 'number' ? -1 : 1;
    var order = x < y ? -1 : x > y ? 1 : 0;
    return descending ? -order : order;
  });
  rows.forEach(function (row) { table.tBodies[0].appendChild(row); });
  header.setAttribute('data-sorted', descending ? 'descending' : 'ascending');
}
</script>
)";

} // namespace

// A relative path as a URL: every byte outside the unreserved set and '/' percent-encoded.
std::string urlPath(const std::string& path) {
    static const char* kHex = "0123456789ABCDEF";
    std::string out;
    for (unsigned char c : path) {
        if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~' || c == '/') {
            out += char(c);
        } else {
            out += '%';
            out += kHex[c >> 4];
            out += kHex[c & 15];
        }
    }
    return out;
}

// Integers without a fraction, everything else with 4 significant digits.
std::string formatTableNumber(double value) {
    return displayNumber(value, 4, true);
}

std::string formatCell(const json& value) {
    if (value.is_null())
        return "&mdash;";
    if (value.is_number())
        return formatTableNumber(value.get<double>());
    if (value.is_boolean())
        return value.get<bool>() ? "true" : "false";
    if (value.is_string())
        return htmlEscape(value.get<std::string>());
    return htmlEscape(value.dump());
}

std::string formatOptional(const json& value, const char* suffix) {
    if (value.is_null())
        return "&mdash;";
    return formatCell(value) + suffix;
}

std::string metricLabel(const json& metric) {
    if (metric.is_string())
        return metric.get<std::string>();
    std::string label;
    for (const json& part : metric)
        label += (label.empty() ? "" : " + ") + part.get<std::string>();
    return label;
}

std::string stringField(const json& object, const char* key) {
    const auto it = object.find(key);
    return it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string htmlEscape(const std::string& text) {
    // Control characters and invalid UTF-8 from a results file become visible escapes first
    // (scenes/input/MessageText.h): the page stays valid UTF-8 and shows what the file holds.
    const std::string visible = scenes::escapeControlCharacters(text, scenes::LineBreaks::Keep);
    std::string out;
    out.reserve(visible.size());
    for (char c : visible) {
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
        case '\'':
            out += "&#39;";
            break;
        default:
            out += c;
        }
    }
    return out;
}

const char* pageCheckScript() {
    return kPageCheckScript;
}

std::string displayNumber(double value, int significantDigits, bool wholeIntegers) {
    if (std::isnan(value))
        return "NaN";
    if (std::isinf(value))
        return value > 0 ? "inf" : "-inf";
    char buffer[64];
    if (wholeIntegers && value == std::floor(value) && std::fabs(value) < 1e15)
        std::snprintf(buffer, sizeof buffer, "%.0f", value);
    else
        std::snprintf(buffer, sizeof buffer, "%.*g", significantDigits, value);
    return buffer;
}

const char* reportStyle() {
    return kStyle;
}

} // namespace experiments
