#include "experiments/ReportCommand.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "experiments/AtomicFile.h"
#include "experiments/CommandErrors.h"
#include "experiments/ImageOutput.h"
#include "scenes/Limits.h"
#include "scenes/NestingDepth.h"

namespace experiments {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The job images the report shows as thumbnails, in column order.
constexpr const char* kJobImages[] = {"preview", "heatmap", "error"};
// Axis columns named in a thumbnail's caption, when the results have them.
constexpr const char* kCaptionColumns[] = {"scene",  "stage",  "lights",  "width",
                                           "height", "layout", "normals", "depth"};

// Results are ours but may have been edited: the nesting is bounded before parsing, as for every
// JSON input (scenes/Limits.h), since the report copies values recursively.
json readJsonFile(const fs::path& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file)
        throw std::runtime_error("cannot read " + path.string() + ": " + std::strerror(errno));
    const std::string text{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
    scenes::NestingViolation violation;
    if (scenes::jsonNestsDeeperThan(text, scenes::limits::kMaxNestingDepth, &violation))
        throw std::runtime_error("cannot parse " + path.string() + ": line " +
                                 std::to_string(violation.line) + " nests deeper than " +
                                 std::to_string(scenes::limits::kMaxNestingDepth) + " levels");
    try {
        return json::parse(text);
    } catch (const json::exception& e) {
        throw std::runtime_error("cannot parse " + path.string() + ": " + e.what());
    }
}

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
std::string formatNumber(double value) {
    return displayNumber(value, 4, true);
}

std::string formatCell(const json& value) {
    if (value.is_null())
        return "&mdash;";
    if (value.is_number())
        return formatNumber(value.get<double>());
    if (value.is_boolean())
        return value.get<bool>() ? "true" : "false";
    if (value.is_string())
        return htmlEscape(value.get<std::string>());
    return htmlEscape(value.dump());
}

std::string formatOptional(const json& value, const char* suffix = "") {
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

// The columns of the results table: "columns" when present, else every key of the jobs in
// first-seen order.
std::vector<std::string> resultColumns(const json& results) {
    std::vector<std::string> columns;
    if (results.contains("columns") && results["columns"].is_array()) {
        for (const json& column : results["columns"])
            if (column.is_string())
                columns.push_back(column.get<std::string>());
        return columns;
    }
    std::set<std::string> seen;
    for (const json& job : results["jobs"])
        for (const auto& [key, value] : job.items())
            if (seen.insert(key).second)
                columns.push_back(key);
    return columns;
}

bool jobOk(const json& job) {
    return stringField(job, "status") == "ok";
}

// Writes a thumbnail of source (at most width pixels wide, aspect kept) unless an up-to-date
// one exists. Returns false when source is missing or unreadable (the page then says so).
bool makeThumbnail(const fs::path& source, const fs::path& thumbnail, int width) {
    std::error_code error;
    if (!fs::is_regular_file(source, error))
        return false;
    if (fs::exists(thumbnail, error) &&
        fs::last_write_time(thumbnail, error) >= fs::last_write_time(source, error) && !error)
        return true;
    OIIO::ImageBuf image(source.string());
    if (!image.read(0, 0, true, OIIO::TypeDesc::FLOAT))
        return false;
    const OIIO::ImageSpec& spec = image.spec();
    const int thumbWidth = std::min(width, spec.width);
    const int thumbHeight =
        std::max(1, int(std::lround(double(spec.height) * thumbWidth / spec.width)));
    OIIO::ImageBuf small(
        OIIO::ImageSpec(thumbWidth, thumbHeight, spec.nchannels, OIIO::TypeDesc::FLOAT));
    if (!OIIO::ImageBufAlgo::resize(small, image))
        throw std::runtime_error("cannot make a thumbnail of " + source.string() + ": " +
                                 small.geterror());
    writeImageAtomically(thumbnail, small, OIIO::TypeDesc::UINT8, "png");
    return true;
}

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
</style>
)";

void appendPublishedSection(std::ostringstream& html, const json& table, int index) {
    html << "<h3 id=\"published-" << index << "\">" << htmlEscape(stringField(table, "title"))
         << "</h3>\n";
    const std::string source = stringField(table, "source");
    if (!source.empty())
        html << "<p>Source: " << htmlEscape(source) << "</p>\n";
    html << "<p>Metric: <code>" << htmlEscape(stringField(table, "metric_label")) << "</code>";
    const json& ratioTo = table["ratio_to"];
    const json& columns = table["columns"];
    html << "; ratios are value / value of column &ldquo;"
         << htmlEscape(columns[ratioTo.get<size_t>()].get<std::string>())
         << "&rdquo; of the same row. Measured values are medians over the matching jobs.</p>\n";
    html << "<div class=\"scroll\"><table class=\"published\">\n<tr><th class=\"text\" "
            "rowspan=\"2\">row</th>";
    for (const json& column : columns)
        html << "<th colspan=\"5\">" << htmlEscape(column.get<std::string>()) << "</th>";
    html << "</tr>\n<tr>";
    for (size_t c = 0; c < columns.size(); ++c)
        html << "<th>published</th><th>measured</th><th>published ratio</th>"
                "<th>measured ratio</th><th>jobs</th>";
    html << "</tr>\n";
    for (const json& row : table["rows"]) {
        html << "<tr><td class=\"text\">" << htmlEscape(row["label"].get<std::string>()) << "</td>";
        for (const json& cell : row["cells"])
            html << "<td>" << formatOptional(cell["published"]) << "</td><td>"
                 << formatOptional(cell["measured"]) << "</td><td>"
                 << formatOptional(cell["published_ratio"], "&times;") << "</td><td>"
                 << formatOptional(cell["measured_ratio"], "&times;") << "</td><td>"
                 << cell["matched_jobs"].get<int>() << "</td>";
        html << "</tr>\n";
    }
    html << "</table></div>\n";
    const std::string finding = stringField(table, "finding");
    if (!finding.empty())
        html << "<p class=\"finding\"><b>Published finding:</b> " << htmlEscape(finding)
             << "</p>\n";
}

void appendPlots(std::ostringstream& html, const json& manifest) {
    if (manifest.contains("plots"))
        for (const json& plot : manifest["plots"]) {
            const std::string file = "report/" + plot["file"].get<std::string>();
            html << "<figure><a href=\"" << urlPath(file) << "\"><img class=\"plot\" src=\""
                 << urlPath(file) << "\" alt=\"" << htmlEscape(stringField(plot, "title"))
                 << "\"></a><figcaption><b>" << htmlEscape(stringField(plot, "title")) << "</b> "
                 << htmlEscape(stringField(plot, "caption")) << "</figcaption></figure>\n";
        }
    if (manifest.contains("skipped") && !manifest["skipped"].empty()) {
        html << "<ul>\n";
        for (const json& skipped : manifest["skipped"])
            html << "<li class=\"note\">" << htmlEscape(stringField(skipped, "title"))
                 << ": not enough data (" << htmlEscape(stringField(skipped, "reason"))
                 << ")</li>\n";
        html << "</ul>\n";
    }
}

void appendResultsTable(std::ostringstream& html, const json& jobs,
                        const std::vector<std::string>& columns) {
    html << "<div class=\"scroll\"><table class=\"results\">\n<tr>";
    for (const std::string& column : columns)
        html << "<th>" << htmlEscape(column) << "</th>";
    html << "</tr>\n";
    for (const json& job : jobs) {
        html << "<tr" << (jobOk(job) ? "" : " class=\"failed\"") << ">";
        for (const std::string& column : columns) {
            const auto it = job.find(column);
            const json value = it == job.end() ? json() : *it;
            const char* cls = column == "error"   ? " class=\"error\""
                              : value.is_string() ? " class=\"text\""
                                                  : "";
            html << "<td" << cls << ">"
                 << (column == "error" && value.is_string() && value.get<std::string>().empty()
                         ? std::string()
                         : formatCell(value))
                 << "</td>";
        }
        html << "</tr>\n";
    }
    html << "</table></div>\n";
}

void appendThumbnails(std::ostringstream& html, const fs::path& dir, const json& jobs, int width) {
    html << "<table class=\"thumbs\">\n<tr><th class=\"text\">job</th>";
    for (const char* image : kJobImages)
        html << "<th class=\"text\">" << image << ".png</th>";
    html << "</tr>\n";
    fs::create_directories(dir / "report" / "thumbs");
    for (const json& job : jobs) {
        const std::string id = stringField(job, "job_id");
        if (id.empty())
            continue;
        html << "<tr" << (jobOk(job) ? "" : " class=\"failed\"") << "><td><b>" << htmlEscape(id)
             << "</b>";
        for (const char* column : kCaptionColumns)
            if (job.contains(column) && !job[column].is_null())
                html << "<br>" << column << " " << formatCell(job[column]);
        if (!jobOk(job))
            html << "<br><span class=\"error\">" << htmlEscape(stringField(job, "error"))
                 << "</span>";
        html << "</td>";
        for (const char* image : kJobImages) {
            const std::string full = "jobs/" + id + "/" + image + ".png";
            const std::string thumb = "report/thumbs/" + id + "-" + image + ".png";
            if (makeThumbnail(dir / full, dir / thumb, width))
                html << "<td><a href=\"" << urlPath(full) << "\"><img src=\"" << urlPath(thumb)
                     << "\" alt=\"" << image << " of " << htmlEscape(id) << "\"></a></td>";
            else
                html << "<td class=\"missing\">no " << image << ".png</td>";
        }
        html << "</tr>\n";
    }
    html << "</table>\n";
}

std::string shellQuote(const std::string& text) {
    std::string out = "'";
    for (char c : text)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

} // namespace

std::string htmlEscape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
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

std::string normalisedSelectValue(const json& value) {
    auto number = [](double x) {
        char buffer[64];
        if (x == std::floor(x) && std::fabs(x) < 1e15) {
            std::snprintf(buffer, sizeof buffer, "%.0f", x);
            return std::string(buffer);
        }
        const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
        return std::string(buffer, result.ptr);
    };
    if (value.is_null())
        return "";
    if (value.is_boolean())
        return value.get<bool>() ? "true" : "false";
    if (value.is_number())
        return number(value.get<double>());
    if (value.is_string()) {
        const std::string text = value.get<std::string>();
        double x = 0.0;
        const char* end = text.data() + text.size();
        const auto result = std::from_chars(text.data(), end, x);
        if (!text.empty() && result.ec == std::errc() && result.ptr == end && std::isfinite(x))
            return number(x);
        return text;
    }
    return value.dump();
}

bool jobMatchesSelect(const json& job, const json& select) {
    if (select.is_null())
        return true;
    for (const auto& [key, wanted] : select.items()) {
        const auto it = job.find(key);
        if (it == job.end() || normalisedSelectValue(*it) != normalisedSelectValue(wanted))
            return false;
    }
    return true;
}

std::optional<double> jobMetric(const json& job, const json& metric) {
    const std::vector<json> names =
        metric.is_array() ? metric.get<std::vector<json>>() : std::vector<json>{metric};
    double sum = 0.0;
    for (const json& name : names) {
        if (!name.is_string())
            return std::nullopt;
        const auto it = job.find(name.get<std::string>());
        if (it == job.end() || !it->is_number())
            return std::nullopt;
        const double value = it->get<double>();
        if (!std::isfinite(value))
            return std::nullopt;
        sum += value;
    }
    return sum;
}

std::optional<double> median(std::vector<double> values) {
    if (values.empty())
        return std::nullopt;
    std::sort(values.begin(), values.end());
    const size_t middle = values.size() / 2;
    return values.size() % 2 ? values[middle] : 0.5 * (values[middle - 1] + values[middle]);
}

json comparePublished(const json& published, const json& jobs) {
    const std::string title = published.is_object() ? stringField(published, "title") : "";
    auto fail = [&](const std::string& what) -> std::runtime_error {
        return std::runtime_error("published entry '" + title + "': " + what);
    };
    if (!published.is_object())
        throw fail("expected an object");
    const json metric = published.value("metric", json());
    if (!(metric.is_string() ||
          (metric.is_array() && !metric.empty() &&
           std::all_of(metric.begin(), metric.end(), [](const json& m) { return m.is_string(); }))))
        throw fail("\"metric\" must be a column name or a non-empty list of column names");
    const json columns = published.value("columns", json());
    const json rows = published.value("rows", json());
    if (!columns.is_array() || columns.empty())
        throw fail("\"columns\" must be a non-empty list");
    if (!rows.is_array())
        throw fail("\"rows\" must be a list");
    const json ratioToValue = published.value("ratio_to", json(0));
    if (!ratioToValue.is_number_integer() || ratioToValue.get<long>() < 0 ||
        ratioToValue.get<size_t>() >= columns.size())
        throw fail("\"ratio_to\" must be a column index from 0 to " +
                   std::to_string(columns.size() - 1));
    const size_t ratioTo = ratioToValue.get<size_t>();

    json table = {{"title", title},
                  {"source", stringField(published, "source")},
                  {"metric", metric},
                  {"metric_label", metricLabel(metric)},
                  {"finding", stringField(published, "finding")},
                  {"ratio_to", ratioTo},
                  {"columns", json::array()},
                  {"rows", json::array()}};
    for (size_t c = 0; c < columns.size(); ++c) {
        if (!columns[c].is_object())
            throw fail("columns[" + std::to_string(c) + "] must be an object");
        table["columns"].push_back(columns[c].value("label", "column " + std::to_string(c)));
    }
    for (size_t r = 0; r < rows.size(); ++r) {
        const json& row = rows[r];
        const std::string where = "rows[" + std::to_string(r) + "]";
        if (!row.is_object())
            throw fail(where + " must be an object");
        const json values = row.value("values", json::array());
        if (!values.is_array() || values.size() != columns.size())
            throw fail(where + ".values must have one entry per column (" +
                       std::to_string(columns.size()) + ")");
        std::vector<std::optional<double>> publishedValues, measuredValues;
        std::vector<int> matchCounts;
        for (size_t c = 0; c < columns.size(); ++c) {
            if (!values[c].is_null() && !values[c].is_number())
                throw fail(where + ".values[" + std::to_string(c) + "] must be a number or null");
            publishedValues.push_back(values[c].is_null() ? std::nullopt
                                                          : std::optional(values[c].get<double>()));
            std::vector<double> measured;
            int matched = 0;
            for (const json& job : jobs) {
                if (!jobOk(job) || !jobMatchesSelect(job, row.value("select", json::object())) ||
                    !jobMatchesSelect(job, columns[c].value("select", json::object())))
                    continue;
                ++matched;
                if (const auto value = jobMetric(job, metric))
                    measured.push_back(*value);
            }
            measuredValues.push_back(median(measured));
            matchCounts.push_back(matched);
        }
        auto ratio = [&](const std::vector<std::optional<double>>& v, size_t c) -> json {
            if (!v[c] || !v[ratioTo] || *v[ratioTo] == 0.0)
                return json();
            return *v[c] / *v[ratioTo];
        };
        auto toJson = [](const std::optional<double>& v) { return v ? json(*v) : json(); };
        json cells = json::array();
        for (size_t c = 0; c < columns.size(); ++c)
            cells.push_back({{"published", toJson(publishedValues[c])},
                             {"measured", toJson(measuredValues[c])},
                             {"published_ratio", ratio(publishedValues, c)},
                             {"measured_ratio", ratio(measuredValues, c)},
                             {"matched_jobs", matchCounts[c]}});
        table["rows"].push_back(
            {{"label", row.value("label", "row " + std::to_string(r))}, {"cells", cells}});
    }
    return table;
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

fs::path defaultPlotsScript() {
    return plotScriptPath("report.py");
}

int runReportCommand(const ReportCommandOptions& options) {
    try {
        const fs::path& dir = options.dir;
        const json results = readJsonFile(dir / "results.json");
        if (!results.is_object() || !results.contains("jobs") || !results["jobs"].is_array())
            throw std::runtime_error((dir / "results.json").string() +
                                     ": expected an object with a \"jobs\" list");
        if (options.thumbnailWidth < 16 || options.thumbnailWidth > 4096)
            throw std::runtime_error("thumbnail width must be from 16 to 4096 pixels");
        const json& jobs = results["jobs"];
        const json sweep = results.value("sweep", json::object());
        const fs::path reportDir = dir / "report";
        ensureWritableDirectory(reportDir);

        json publishedTables = json::array();
        if (sweep.is_object() && sweep.contains("published")) {
            if (!sweep["published"].is_array())
                throw std::runtime_error((dir / "results.json").string() +
                                         ": sweep.published must be a list");
            for (const json& entry : sweep["published"])
                publishedTables.push_back(comparePublished(entry, jobs));
        }
        writeTextAtomically(reportDir / "published.json", publishedTables.dump(2) + "\n");

        const fs::path script = requirePlotScript(options.plotsScript, "report.py");
        const std::string python = requirePythonWithMatplotlib(options.python);
        const int status = runProcess(
            {python, script.string(), "results", "--results", (dir / "results.json").string(),
             "--published", (reportDir / "published.json").string(), "--out", reportDir.string()});
        if (status != 0)
            throw std::runtime_error("plot script failed (exit status " + std::to_string(status) +
                                     "): " + shellQuote(python) + " " +
                                     shellQuote(script.string()));
        const json manifest = readJsonFile(reportDir / "plots.json");

        const std::vector<std::string> columns = resultColumns(results);
        const size_t failed = size_t(
            std::count_if(jobs.begin(), jobs.end(), [](const json& j) { return !jobOk(j); }));
        const std::string name = sweep.is_object() ? stringField(sweep, "name") : "";
        const std::string title =
            "testbed report: " + (name.empty() ? dir.filename().string() : name);

        std::ostringstream html;
        html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
             << htmlEscape(title) << "</title>\n"
             << kPageCheckScript << kStyle << "</head>\n<body>\n";
        html << "<h1>" << htmlEscape(title) << "</h1>\n<p>";
        const std::string sweepFile = stringField(results, "sweep_file");
        if (!sweepFile.empty())
            html << "Sweep file <code>" << htmlEscape(sweepFile) << "</code>";
        if (results.value("quick", false))
            html << " (quick size)";
        html << (sweepFile.empty() ? "" : ": ") << jobs.size() << " jobs, " << jobs.size() - failed
             << " ok, " << failed << " failed.";
        const std::string description = sweep.is_object() ? stringField(sweep, "description") : "";
        if (!description.empty())
            html << " " << htmlEscape(description);
        html << "</p>\n<p>Contents: ";
        if (!publishedTables.empty())
            html << "<a href=\"#published\">published vs measured</a> &middot; ";
        html << "<a href=\"#plots\">plots</a> &middot; <a href=\"#results\">results table</a> "
                "&middot; "
                "<a href=\"#images\">images</a></p>\n";
        if (!publishedTables.empty()) {
            html << "<h2 id=\"published\">Published vs measured</h2>\n";
            for (size_t i = 0; i < publishedTables.size(); ++i)
                appendPublishedSection(html, publishedTables[i], int(i));
        }
        html << "<h2 id=\"plots\">Plots</h2>\n";
        appendPlots(html, manifest);
        html << "<h2 id=\"results\">Results (" << jobs.size() << " jobs)</h2>\n"
             << "<p>Times in ms (median, min, max over the repetitions); error against the "
                "reference "
                "render; &mdash; = not measured. Failed jobs in red with their error.</p>\n";
        appendResultsTable(html, jobs, columns);
        html << "<h2 id=\"images\">Images</h2>\n<p>Tone-mapped render, lights evaluated per pixel, "
                "and "
                "|render &minus; reference| per job; click for the full-size image.</p>\n";
        appendThumbnails(html, dir, jobs, options.thumbnailWidth);
        html << "<pre id=\"page-check\" data-status=\"pending\">PAGE-CHECK: "
                "PENDING</pre>\n</body>\n</html>\n";
        writeTextAtomically(dir / "report.html", html.str());
        std::cout << "testbed: report written to " << (dir / "report.html").string() << "\n";
        return 0;
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

} // namespace experiments
