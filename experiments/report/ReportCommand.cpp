#include "experiments/report/ReportCommand.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "experiments/CommandErrors.h"
#include "experiments/advise/Advisor.h"
#include "experiments/compare/FlipMetric.h"
#include "experiments/output/AtomicFile.h"
#include "experiments/output/ImageOutput.h"
#include "experiments/render/RenderCommand.h"
#include "experiments/render/RunMetrics.h"
#include "scenes/input/DuplicateKeys.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/input/WholeFile.h"

namespace experiments {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The job images the report shows as thumbnails, in column order; all but the preview are
// redrawn at their group's scale from render.exr when it is there.
constexpr const char* kJobImages[] = {"preview", "heatmap", "error", "flip"};
// The columns of the results table a reader compares first, after the method columns; the rest
// are behind the "all columns" toggle.
constexpr const char* kMainMetricColumns[] = {"time_total_median_ms", "relative_rmse", "flip",
                                              "culling_efficiency", "simt_efficiency"};
// Results are ours but may have been edited: read as every input file is
// (scenes/input/WholeFile.h), the nesting bounded before parsing (scenes/input/Limits.h, since the
// report copies values recursively) and a key given twice refused, as for every JSON input.
json readJsonFile(const fs::path& path) {
    std::string text;
    if (const std::string problem = scenes::readWholeFile(path, &text); !problem.empty())
        throw std::runtime_error("cannot read " + path.string() + ": " + problem);
    scenes::NestingViolation violation;
    if (scenes::jsonNestsDeeperThan(text, scenes::limits::kMaxNestingDepth, &violation))
        throw std::runtime_error("cannot parse " + path.string() + ": line " +
                                 std::to_string(violation.line) + " nests deeper than " +
                                 std::to_string(scenes::limits::kMaxNestingDepth) + " levels");
    if (const std::string problem = scenes::jsonDuplicateKeyProblem(text); !problem.empty())
        throw std::runtime_error("cannot parse " + path.string() + ": " + problem);
    try {
        return json::parse(text);
    } catch (const json::exception& e) {
        throw std::runtime_error("cannot parse " + path.string() + ": " + e.what());
    }
}

// Writes a thumbnail of source (at most width pixels wide, aspect kept) unless an up-to-date
// one exists. Returns false when source is missing or unreadable (the page then says so).
bool makeThumbnail(const fs::path& source, const fs::path& thumbnail, int width) {
    runImageLibraryOnTheCallingThread();
    std::error_code error;
    if (!fs::is_regular_file(source, error))
        return false;
    if (fs::exists(thumbnail, error) &&
        fs::last_write_time(thumbnail, error) >= fs::last_write_time(source, error) && !error)
        return true;
    OIIO::ImageBuf image;
    if (!readFloatImage(source, image))
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

bool isMainColumn(const std::string& column, const std::vector<std::string>& varyingMethods,
                  const std::string& errorMetric, bool anyFailed) {
    if (column == "job_id" || column == "status" || column == "stage" || column == errorMetric ||
        (column == "error" && anyFailed))
        return true;
    if (std::find(varyingMethods.begin(), varyingMethods.end(), column) != varyingMethods.end())
        return true;
    for (const char* main : kMainMetricColumns)
        if (column == main)
            return true;
    return false;
}

// The plots of one group ("" = across groups) and kind filter, then the skipped ones.
void appendPlots(std::ostringstream& html, const json& manifest, const std::string& group,
                 const std::function<bool(const std::string&)>& kindWanted) {
    if (manifest.contains("plots"))
        for (const json& plot : manifest["plots"]) {
            if (stringField(plot, "group") != group || !kindWanted(stringField(plot, "kind")))
                continue;
            const std::string file = "report/" + plot["file"].get<std::string>();
            html << "<figure><a href=\"" << urlPath(file) << "\"><img class=\"plot\" data-kind=\""
                 << htmlEscape(stringField(plot, "kind")) << "\" src=\"" << urlPath(file)
                 << "\" alt=\"" << htmlEscape(stringField(plot, "title"))
                 << "\"></a><figcaption><b>" << htmlEscape(stringField(plot, "title")) << "</b> "
                 << htmlEscape(stringField(plot, "caption")) << "</figcaption></figure>\n";
        }
    std::ostringstream skipped;
    if (manifest.contains("skipped"))
        for (const json& item : manifest["skipped"])
            if (stringField(item, "group") == group && kindWanted(stringField(item, "kind")))
                skipped << "<li class=\"note\" data-kind=\""
                        << htmlEscape(stringField(item, "kind")) << "-skipped\">"
                        << htmlEscape(stringField(item, "title")) << ": not enough data ("
                        << htmlEscape(stringField(item, "reason")) << ")</li>\n";
    if (!skipped.str().empty())
        html << "<ul>\n" << skipped.str() << "</ul>\n";
}

void appendResultsTable(std::ostringstream& html, const json& jobs,
                        const std::vector<std::string>& columns,
                        const std::vector<std::string>& varyingMethods,
                        const std::vector<JobGroup>& groups, const std::string& errorMetric) {
    std::vector<std::string> groupOf(jobs.size());
    for (const JobGroup& group : groups)
        for (size_t job : group.jobs)
            groupOf[job] = group.id;
    const bool anyFailed =
        std::any_of(jobs.begin(), jobs.end(), [](const json& j) { return !jobOk(j); });
    // Main columns first (in table order, the group after the job id), then the others.
    std::vector<std::string> ordered, extra;
    for (const std::string& column : columns)
        (isMainColumn(column, varyingMethods, errorMetric, anyFailed) ? ordered : extra)
            .push_back(column);
    const size_t mainCount = ordered.size() + 1; // + group
    ordered.insert(ordered.end(), extra.begin(), extra.end());
    std::string mainNames = "group";
    for (size_t i = 0; i + 1 < mainCount; ++i)
        mainNames += " " + ordered[i];
    html << "<p><button type=\"button\" id=\"toggle-columns\" onclick=\"toggleColumns(this)\">"
            "Show all "
         << columns.size() + 1 << " columns</button> The table shows the " << mainCount
         << " columns a reader compares (method, time, error, ꟻLIP, culling efficiency); "
            "the button shows the other "
         << extra.size() << ".</p>\n";
    html << "<div class=\"scroll\"><table class=\"results compact\" id=\"results-table\" "
            "data-main-columns=\""
         << htmlEscape(mainNames) << "\">\n<tr>";
    auto cellClass = [&](size_t index) { return index < mainCount - 1 ? "" : " extra"; };
    for (size_t i = 0; i < ordered.size(); ++i) {
        html << "<th class=\"col" << cellClass(i) << "\" data-column=\"" << htmlEscape(ordered[i])
             << "\" onclick=\"sortResults(this)\" title=\"sort by this column\">"
             << htmlEscape(ordered[i]) << "</th>";
        if (ordered[i] == "job_id")
            html << "<th class=\"col\" data-column=\"group\">group</th>";
    }
    html << "</tr>\n";
    for (size_t j = 0; j < jobs.size(); ++j) {
        const json& job = jobs[j];
        html << "<tr" << (jobOk(job) ? "" : " class=\"failed\"") << ">";
        for (size_t i = 0; i < ordered.size(); ++i) {
            const std::string& column = ordered[i];
            const auto it = job.find(column);
            const json value = it == job.end() ? json() : *it;
            const std::string cls = std::string(column == "error"   ? "error"
                                                : value.is_string() ? "text"
                                                                    : "") +
                                    cellClass(i);
            html << "<td" << (cls.empty() ? "" : " class=\"" + cls + "\"") << ">"
                 << (column == "error" && value.is_string() && value.get<std::string>().empty()
                         ? std::string()
                         : formatCell(value))
                 << "</td>";
            if (column == "job_id")
                html << "<td class=\"text\"><a href=\"#group-" << groupOf[j] << "\">" << groupOf[j]
                     << "</a></td>";
        }
        html << "</tr>\n";
    }
    html << "</table></div>\n";
}

// One job's maps as its group draws them: read from render.exr, or empty (then the job's own
// PNGs are shown, at their own scale).
struct JobMaps {
    int width = 0, height = 0;
    std::vector<uint32_t> evaluated;
    std::vector<float> error; // largest channel |render - reference|; empty without a reference
    std::vector<float> flip;  // empty without ꟻLIP
};

std::optional<JobMaps> readJobMaps(const fs::path& exr) {
    runImageLibraryOnTheCallingThread();
    std::error_code missing;
    if (!fs::is_regular_file(exr, missing))
        return std::nullopt;
    OIIO::ImageBuf image;
    if (!readFloatImage(exr, image))
        return std::nullopt;
    const OIIO::ImageSpec& spec = image.spec();
    auto plane = [&](const char* name) -> std::vector<float> {
        const int channel = spec.channelindex(name);
        if (channel < 0)
            return {};
        std::vector<float> values(size_t(spec.width) * spec.height);
        OIIO::ROI roi = image.roi();
        roi.chbegin = channel;
        roi.chend = channel + 1;
        image.get_pixels(roi, OIIO::TypeDesc::FLOAT, values.data());
        return values;
    };
    JobMaps maps;
    maps.width = spec.width;
    maps.height = spec.height;
    const std::vector<float> evaluated = plane("lights.evaluated");
    if (evaluated.empty())
        return std::nullopt;
    maps.evaluated.assign(evaluated.begin(), evaluated.end());
    const std::vector<float> r = plane("error.R"), g = plane("error.G"), b = plane("error.B");
    if (!r.empty() && !g.empty() && !b.empty()) {
        maps.error.resize(r.size());
        for (size_t i = 0; i < r.size(); ++i)
            maps.error[i] = std::max({r[i], g[i], b[i]});
    }
    maps.flip = plane("flip");
    return maps;
}

// The label of a job inside its group: its method columns that vary, stage first.
std::string methodLabel(const json& job, const std::vector<std::string>& varyingMethods) {
    std::string label = formatCell(job.value("stage", json()));
    for (const std::string& column : varyingMethods)
        if (column != "stage")
            label += ", " + htmlEscape(column) + " " + formatCell(job.value(column, json()));
    return label;
}

// The group's section: its plots, then every job's preview and maps at the group's one scale.
void appendGroupSection(std::ostringstream& html, const fs::path& dir, const json& jobs,
                        const JobGroup& group, const json& manifest,
                        const std::vector<std::string>& varyingMethods,
                        const RenderOutputScales& scales, int thumbnailWidth) {
    size_t ok = 0;
    for (size_t j : group.jobs)
        ok += jobOk(jobs[j]);
    html << "<section class=\"group\" id=\"group-" << group.id << "\" data-group=\"" << group.id
         << "\" data-jobs=\"" << group.jobs.size() << "\" data-ok-jobs=\"" << ok
         << "\">\n<h3>Group " << group.id << ": " << htmlEscape(group.label) << "</h3>\n<p>"
         << group.jobs.size() << " jobs (" << ok << " ok) with the same";
    std::string fixed;
    for (const auto& [column, value] : group.fixed.items())
        fixed += (fixed.empty() ? " " : ", ") + htmlEscape(column) + " " + formatCell(value);
    html << (fixed.empty() ? " settings" : fixed) << ".</p>\n";
    appendPlots(html, manifest, group.id, [](const std::string&) { return true; });

    // Maps at the group's scale: read every job's EXR once, take the group's maxima (or the
    // sweep's fixed ones), draw.
    std::vector<std::optional<JobMaps>> maps(group.jobs.size());
    uint32_t heatmapMax = scales.heatmapMax;
    float errorMax = scales.errorMax;
    bool computeHeat = heatmapMax == 0, computeError = !(errorMax > 0.0f);
    uint32_t heatPeak = 1;
    float errorPeak = 0.0f;
    for (size_t k = 0; k < group.jobs.size(); ++k) {
        const json& job = jobs[group.jobs[k]];
        const std::string id = stringField(job, "job_id");
        if (!jobOk(job) || id.empty())
            continue;
        maps[k] = readJobMaps(dir / "jobs" / id / "render.exr");
        if (!maps[k])
            continue;
        heatPeak = std::max(heatPeak,
                            heatmapAutoScale(maps[k]->evaluated.data(), maps[k]->evaluated.size()));
        if (!maps[k]->error.empty())
            errorPeak = std::max(
                errorPeak, scalarMapRange(maps[k]->error.data(), maps[k]->error.size(), {}).second);
    }
    if (computeHeat)
        heatmapMax = heatPeak;
    if (computeError)
        errorMax = errorPeak;
    RenderOutputScales groupScales = scales;
    groupScales.heatmapMax = heatmapMax;
    groupScales.errorMax = errorMax;
    const bool anyMaps =
        std::any_of(maps.begin(), maps.end(), [](const auto& m) { return bool(m); });
    html << "<p>Previews, lights evaluated per pixel, |render &minus; reference| and ꟻLIP";
    if (anyMaps)
        html << " at <b>one scale for the whole group</b>: heatmaps 0.." << heatmapMax
             << " lights ("
             << (computeHeat ? "the group's largest count" : "the sweep's heatmap-max")
             << "), error maps " << mapScaleName(groupScales.errorScale) << " up to "
             << displayNumber(errorMax, 3) << " ("
             << (computeError ? "the group's largest error" : "the sweep's error-max")
             << "), ꟻLIP 0..1";
    else
        html << " (each image at its own scale: the jobs have no render.exr to redraw them from)";
    html << "; click for the full-size image.</p>\n";
    html << "<table class=\"thumbs\">\n<tr><th class=\"text\">job</th>";
    for (const char* image : kJobImages)
        html << "<th class=\"text\">" << image << "</th>";
    html << "</tr>\n";
    fs::create_directories(dir / "report" / "thumbs");
    fs::create_directories(dir / "report" / "maps");
    for (size_t k = 0; k < group.jobs.size(); ++k) {
        const json& job = jobs[group.jobs[k]];
        const std::string id = stringField(job, "job_id");
        if (id.empty())
            continue;
        html << "<tr" << (jobOk(job) ? "" : " class=\"failed\"") << "><td><b>" << htmlEscape(id)
             << "</b><br>" << methodLabel(job, varyingMethods);
        if (!jobOk(job))
            html << "<br><span class=\"error\">" << htmlEscape(stringField(job, "error"))
                 << "</span>";
        html << "</td>";
        for (const char* image : kJobImages) {
            std::string full = "jobs/" + id + "/" + image + ".png";
            if (maps[k] && std::string(image) != "preview") {
                const JobMaps& m = *maps[k];
                const std::string redrawn = "report/maps/" + id + "-" + image + ".png";
                if (std::string(image) == "heatmap")
                    writeHeatmapPng(dir / redrawn, m.width, m.height, m.evaluated.data(),
                                    heatmapMax);
                else if (std::string(image) == "error" && !m.error.empty())
                    writeScalarMapPng(dir / redrawn, m.width, m.height, m.error.data(),
                                      errorMapStyle(groupScales));
                else if (std::string(image) == "flip" && !m.flip.empty())
                    writeScalarMapPng(dir / redrawn, m.width, m.height, m.flip.data(),
                                      flipMapStyle());
                else
                    full.clear();
                if (!full.empty())
                    full = redrawn;
            }
            const std::string thumb = "report/thumbs/" + id + "-" + image + ".png";
            if (!full.empty() && makeThumbnail(dir / full, dir / thumb, thumbnailWidth))
                html << "<td><a href=\"" << urlPath(full) << "\"><img src=\"" << urlPath(thumb)
                     << "\" alt=\"" << image << " of " << htmlEscape(id) << "\"></a></td>";
            else
                html << "<td class=\"missing\">no " << image << ".png</td>";
        }
        html << "</tr>\n";
    }
    html << "</table>\n</section>\n";
}

std::string shellQuote(const std::string& text) {
    std::string out = "'";
    for (char c : text)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

} // namespace

fs::path defaultPlotsScript() {
    return plotScriptPath("report.py");
}

namespace {

// The method columns whose values differ among the jobs (stage always when present).
std::vector<std::string> varyingMethodColumns(const json& jobs,
                                              const std::vector<std::string>& axes) {
    std::vector<std::string> varying;
    for (const std::string& column : axes) {
        if (!isMethodColumn(column))
            continue;
        std::set<std::string> values;
        for (const json& job : jobs)
            values.insert(normalisedSelectValue(job.value(column, json())));
        if (column == "stage" || values.size() > 1)
            varying.push_back(column);
    }
    return varying;
}

// The scales of the report's maps: the sweep's heatmap-max, error-max, error-scale, with
// --error-scale overriding the last.
RenderOutputScales mapScales(const json& sweep, const ReportCommandOptions& options) {
    RenderOutputScales scales;
    if (sweep.is_object()) {
        const json heat = sweep.value("heatmap-max", json(0));
        if (heat.is_number_unsigned())
            scales.heatmapMax = heat.get<uint32_t>();
        const json errorMax = sweep.value("error-max", json(0.0));
        if (errorMax.is_number() && errorMax.get<double>() > 0.0)
            scales.errorMax = errorMax.get<float>();
        const json errorScale = sweep.value("error-scale", json("linear"));
        if (errorScale.is_string())
            scales.errorScale =
                usageErrorFrom([&] { return parseMapScale(errorScale.get<std::string>()); });
    }
    if (options.errorScale)
        scales.errorScale = *options.errorScale;
    return scales;
}

// "median (min–max)" of one aggregate, or a dash when no view has the figure.
std::string aggregateCell(const json& aggregate) {
    if (!aggregate.is_object())
        return "&mdash;";
    return formatTableNumber(aggregate["median"].get<double>()) + " (" +
           formatTableNumber(aggregate["min"].get<double>()) + "&ndash;" +
           formatTableNumber(aggregate["max"].get<double>()) + ")";
}

// The "Across views" section: per view family, the aggregate per method, then the per-view rows
// behind a toggle (a closed <details>).
void appendViewsSection(std::ostringstream& html, const json& aggregates,
                        const std::string& errorMetric) {
    const json& families = aggregates["families"];
    const auto metrics = aggregates["metrics"].get<std::vector<std::string>>();
    auto metricHeader = [&](const std::string& m) {
        return m == "time_total_median_ms" ? std::string("total time (ms)")
               : m == metric::kFlip        ? std::string("ꟻLIP")
                                           : "<code>" + htmlEscape(m) + "</code>";
    };
    html << "<h2 id=\"views\">Across views</h2>\n<p>Each view is its own comparable group above: "
            "a camera changes the image, the light counts and the error, so no Pareto plot "
            "pools views. Here the views are aggregated <b>explicitly</b>: for each family of "
            "groups that differ only in the view, and each method, the <b>median and the "
            "min&ndash;max over the views</b> (one job per view) of the job's median total time "
            "over its repetitions, of <code>"
         << htmlEscape(errorMetric)
         << "</code> and of ꟻLIP. &ldquo;views&rdquo; counts the views whose job is ok and has "
            "the figure; failed views are named. The rows behind each aggregate are under "
            "&ldquo;per-view rows&rdquo;.</p>\n";
    for (const json& family : families) {
        const std::string id = family["id"].get<std::string>();
        const size_t viewCount = family["views"].size();
        std::string viewNames;
        for (const json& view : family["views"])
            viewNames += (viewNames.empty() ? "" : ", ") + htmlEscape(view.get<std::string>());
        std::string groupLinks;
        for (const json& group : family["groups"])
            groupLinks += (groupLinks.empty() ? "" : " ") + std::string("<a href=\"#group-") +
                          group.get<std::string>() + "\">" + group.get<std::string>() + "</a>";
        size_t rowCount = 0;
        for (const json& method : family["methods"])
            rowCount += method["rows"].size();
        html << "<section class=\"view-family\" id=\"views-" << id << "\" data-family=\"" << id
             << "\" data-views=\"" << viewCount << "\" data-methods=\"" << family["methods"].size()
             << "\">\n<h3>" << id << ": " << htmlEscape(family["label"].get<std::string>())
             << ", over " << viewCount << " views</h3>\n<p>Views: " << viewNames << " (groups "
             << groupLinks
             << ").</p>\n<table class=\"views-aggregate\">\n<tr><th class=\"text\">method</th>"
             << "<th>views</th>";
        for (const std::string& m : metrics)
            html << "<th data-metric=\"" << htmlEscape(m) << "\">" << metricHeader(m)
                 << "<br>median (min&ndash;max) over views</th>";
        html << "</tr>\n";
        for (const json& method : family["methods"]) {
            const int ok = method["views_ok"].get<int>(),
                      failed = method["views_failed"].get<int>();
            html << "<tr data-method=\"" << htmlEscape(method["label"].get<std::string>())
                 << "\"><td class=\"text\">" << htmlEscape(method["label"].get<std::string>())
                 << "</td><td>" << ok << " of " << ok + failed;
            if (failed > 0) {
                std::string names;
                for (const json& row : method["rows"])
                    if (row["status"] != "ok")
                        names += (names.empty() ? "" : ", ") + formatCell(row["view"]);
                html << " <span class=\"error\">(failed: " << names << ")</span>";
            }
            html << "</td>";
            for (const std::string& m : metrics) {
                const json& aggregate = method[m];
                html << "<td>" << aggregateCell(aggregate);
                if (aggregate.is_object() && aggregate["count"].get<int>() < ok)
                    html << " <span class=\"note\">(" << aggregate["count"].get<int>()
                         << " views)</span>";
                html << "</td>";
            }
            html << "</tr>\n";
        }
        html << "</table>\n<details class=\"per-view\" id=\"per-view-" << id
             << "\"><summary>Per-view rows (" << rowCount
             << " jobs)</summary>\n<table class=\"per-view-rows\">\n<tr><th class=\"text\">"
                "method</th><th class=\"text\">view</th><th class=\"text\">group</th><th "
                "class=\"text\">job</th>";
        for (const std::string& m : metrics)
            html << "<th>" << metricHeader(m) << "</th>";
        html << "</tr>\n";
        for (const json& method : family["methods"])
            for (const json& row : method["rows"]) {
                const std::string group = row["group"].get<std::string>();
                html << "<tr" << (row["status"] == "ok" ? "" : " class=\"failed\"")
                     << "><td class=\"text\">" << htmlEscape(method["label"].get<std::string>())
                     << "</td><td class=\"text\">" << formatCell(row["view"])
                     << "</td><td class=\"text\"><a href=\"#group-" << group << "\">" << group
                     << "</a></td><td class=\"text\">" << formatCell(row["job_id"]) << "</td>";
                for (const std::string& m : metrics)
                    html << "<td>" << formatCell(row[m]) << "</td>";
                html << "</tr>\n";
            }
        html << "</table></details>\n</section>\n";
    }
}

// A visible note when ꟻLIP is missing from some ok jobs: why (each distinct reason once).
void appendFlipNote(std::ostringstream& html, const json& jobs,
                    const std::vector<std::string>& columns) {
    if (std::find(columns.begin(), columns.end(), metric::kFlip) == columns.end()) {
        html << "<p class=\"flip-note\" id=\"flip-note\"><b>ꟻLIP not recorded:</b> these results "
                "were made before the testbed measured ꟻLIP; rerun the sweep to get it.</p>\n";
        return;
    }
    size_t ok = 0, missing = 0;
    std::set<std::string> reasons;
    for (const json& job : jobs) {
        if (!jobOk(job))
            continue;
        ++ok;
        if (!job.value(metric::kFlip, json()).is_number()) {
            ++missing;
            const std::string reason = stringField(job, metric::kFlipUnavailable);
            reasons.insert(reason.empty() ? "the job was not compared with the reference" : reason);
        }
    }
    if (missing == 0)
        return;
    html << "<p class=\"flip-note\" id=\"flip-note\"><b>ꟻLIP unavailable</b> for " << missing
         << " of " << ok << " ok jobs (the flip column is empty there):";
    for (const std::string& reason : reasons)
        html << "<br>&bull; " << htmlEscape(reason);
    html << "</p>\n";
}

// A note when some jobs counted lights over part of the image (reduced-resolution stages).
void appendCountsNote(std::ostringstream& html, const json& jobs) {
    std::set<std::string> stages;
    for (const json& job : jobs) {
        const json counted = job.value(metric::kCountedPixels, json());
        const json width = job.value("width", json()), height = job.value("height", json());
        if (counted.is_number() && width.is_number() && height.is_number() &&
            counted.get<double>() < width.get<double>() * height.get<double>())
            stages.insert(normalisedSelectValue(job.value("stage", json())));
    }
    if (stages.empty())
        return;
    std::string names;
    for (const std::string& stage : stages)
        names += (names.empty() ? "" : ", ") + stage;
    html
        << "<p class=\"counts-note\" id=\"counts-note\"><b>Light counts at reduced resolution:</b> "
        << htmlEscape(names)
        << " light only part of the pixels (their low-resolution samples) and filter the rest. "
           "Their light_evaluations, oracle_light_evaluations and culling_efficiency are counted "
           "over the pixels they light (counted_pixels), so the efficiency compares the same "
           "samples; their evaluation totals are not comparable with full-resolution stages' "
           "as a cost per image pixel.</p>\n";
}

} // namespace

int runReportCommand(const ReportCommandOptions& options) {
    try {
        const fs::path& dir = options.dir;
        const json results = readJsonFile(dir / "results.json");
        if (!results.is_object() || !results.contains("jobs") || !results["jobs"].is_array())
            throw std::runtime_error((dir / "results.json").string() +
                                     ": expected an object with a \"jobs\" list");
        if (options.thumbnailWidth < 16 || options.thumbnailWidth > 4096)
            throw std::runtime_error("thumbnail width must be from 16 to 4096 pixels");
        const std::vector<std::string> metrics = reportErrorMetrics();
        if (std::find(metrics.begin(), metrics.end(), options.errorMetric) == metrics.end()) {
            std::string valid;
            for (const std::string& m : metrics)
                valid += (valid.empty() ? "" : ", ") + m;
            throw std::runtime_error("--error-metric '" + options.errorMetric +
                                     "' is not an error column; valid: " + valid);
        }
        const json& jobs = results["jobs"];
        const json sweep = results.value("sweep", json::object());
        const fs::path reportDir = dir / "report";
        ensureWritableDirectory(reportDir);
        const std::vector<std::string> columns = resultColumns(results);
        const std::vector<std::string> axes = axisColumnsOf(results);
        const std::vector<JobGroup> groups = comparableGroups(jobs, axes);
        const std::vector<std::string> varyingMethods = varyingMethodColumns(jobs, axes);
        const RenderOutputScales scales = mapScales(sweep, options);

        json publishedTables = json::array();
        if (sweep.is_object() && sweep.contains("published")) {
            if (!sweep["published"].is_array())
                throw std::runtime_error((dir / "results.json").string() +
                                         ": sweep.published must be a list");
            for (const json& entry : sweep["published"])
                publishedTables.push_back(comparePublished(entry, jobs, axes));
        }
        writeTextAtomically(reportDir / "published.json", publishedTables.dump(2) + "\n");
        json groupsJson = {
            {"method_columns", varyingMethods}, {"axis_columns", axes}, {"groups", json::array()}};
        for (const JobGroup& group : groups) {
            json ids = json::array();
            for (size_t j : group.jobs)
                ids.push_back(stringField(jobs[j], "job_id"));
            groupsJson["groups"].push_back(
                {{"id", group.id}, {"label", group.label}, {"fixed", group.fixed}, {"jobs", ids}});
        }
        writeTextAtomically(reportDir / "groups.json", groupsJson.dump(2) + "\n");
        const json viewAggregates = aggregateOverViews(jobs, groups, axes, options.errorMetric);
        writeTextAtomically(reportDir / "views.json", viewAggregates.dump(2) + "\n");
        const bool anyViewFamily = !viewAggregates["families"].empty();

        const fs::path script = requirePlotScript(options.plotsScript, "report.py");
        const std::string python = requirePythonWithMatplotlib(options.python);
        const int status = runProcess({python, script.string(), "results", "--results",
                                       (dir / "results.json").string(), "--published",
                                       (reportDir / "published.json").string(), "--groups",
                                       (reportDir / "groups.json").string(), "--error-metric",
                                       options.errorMetric, "--out", reportDir.string()});
        if (status != 0)
            throw std::runtime_error("plot script failed (exit status " + std::to_string(status) +
                                     "): " + shellQuote(python) + " " +
                                     shellQuote(script.string()));
        const json manifest = readJsonFile(reportDir / "plots.json");

        const size_t failed = size_t(
            std::count_if(jobs.begin(), jobs.end(), [](const json& j) { return !jobOk(j); }));
        const std::string name = sweep.is_object() ? stringField(sweep, "name") : "";
        const std::string title =
            "testbed report: " + (name.empty() ? dir.filename().string() : name);

        std::ostringstream html;
        html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
             << htmlEscape(title) << "</title>\n"
             << pageCheckScript() << reportStyle() << "</head>\n<body>\n";
        html << "<h1>" << htmlEscape(title) << "</h1>\n<p>";
        const std::string sweepFile = stringField(results, "sweep_file");
        if (!sweepFile.empty())
            html << "Sweep file <code>" << htmlEscape(sweepFile) << "</code>";
        if (results.value("quick", false))
            html << " (quick size)";
        html << (sweepFile.empty() ? "" : ": ") << jobs.size() << " jobs, " << jobs.size() - failed
             << " ok, " << failed << " failed, in " << groups.size() << " comparable group"
             << (groups.size() == 1 ? "" : "s") << ".";
        const std::string description = sweep.is_object() ? stringField(sweep, "description") : "";
        if (!description.empty())
            html << " " << htmlEscape(description);
        html << "</p>\n";
        appendFlipNote(html, jobs, columns);
        appendCountsNote(html, jobs);
        html
            << "<details class=\"metrics-note\"><summary>Relative RMSE and ꟻLIP: why they can "
               "disagree</summary><p>Relative RMSE weighs every sample by its squared radiance "
               "difference, so a few samples that are far off (a misplaced highlight, an emissive "
               "pixel) can dominate it however small they are on screen. HDR-ꟻLIP scores what a "
               "viewer sees when the two images alternate at 67 pixels per degree: its mean is the "
               "share of the picture that differs visibly, its percentiles where that error sits. "
               "Example: DamagedHelmet with <code>inferred</code> has relative RMSE 0.998 (99% of "
               "the samples within 0.0014 of the reference, a handful off by up to 1453) and ꟻLIP "
               "0.0043 (the visible error is on the panel outlines). Use relative RMSE for "
               "exactness and energy, ꟻLIP to rank what a person sees "
               "(<code>--error-metric flip</code>); experiments/README.md explains.</p>"
               "</details>\n";
        html << "<p>Contents: ";
        if (!publishedTables.empty())
            html << "<a href=\"#published\">published vs measured</a> &middot; ";
        html << "<a href=\"#groups\">comparable groups</a> &middot; ";
        if (anyViewFamily)
            html << "<a href=\"#views\">across views</a> &middot; ";
        html << "<a href=\"#across\">across groups</a> &middot; <a href=\"#results\">results "
                "table</a></p>\n";
        // The advisor's answer, when `testbed advise DIR` has written one.
        if (fs::is_regular_file(dir / "advice.json")) {
            html << adviceHtml(readJsonFile(dir / "advice.json"));
        } else {
            html << "<p class=\"note\">No advice yet: <code>testbed advise "
                 << htmlEscape(dir.string())
                 << " --budget-ms X [--max-flip Y]</code> writes advice.json, shown here.</p>\n";
        }
        if (!publishedTables.empty()) {
            html << "<h2 id=\"published\">Published vs measured</h2>\n";
            for (size_t i = 0; i < publishedTables.size(); ++i)
                appendPublishedSection(html, publishedTables[i], int(i));
            appendPlots(html, manifest, "",
                        [](const std::string& kind) { return kind == "published"; });
        }
        html << "<h2 id=\"groups\">Comparable groups</h2>\n<p>Jobs are compared only with jobs of "
                "their group: the same value of every setting but the method ("
             << "stage, layout, normals, normal-space, depth, position); jobs of different "
                "scenes, views, light counts, sizes or thread counts are never pooled"
             << (anyViewFamily ? " (the views are aggregated explicitly under <a "
                                 "href=\"#views\">across views</a>)"
                               : "")
             << ". Error axis: <code>" << htmlEscape(options.errorMetric)
             << "</code> against the double-precision reference (<code>testbed report "
                "--error-metric</code> chooses another).</p>\n";
        for (const JobGroup& group : groups)
            appendGroupSection(html, dir, jobs, group, manifest, varyingMethods, scales,
                               options.thumbnailWidth);
        if (anyViewFamily)
            appendViewsSection(html, viewAggregates, options.errorMetric);
        html << "<h2 id=\"across\">Across groups</h2>\n<p>One line per method; each plot holds "
                "the jobs that share every other setting, and its caption says what varies with "
                "the x axis.</p>\n";
        appendPlots(html, manifest, "",
                    [](const std::string& kind) { return kind != "published"; });
        html << "<h2 id=\"results\">Results (" << jobs.size() << " jobs)</h2>\n"
             << "<p>Times in ms (median, min, max over the repetitions); error against the "
                "reference render; &mdash; = not measured. Failed jobs in red with their "
                "error.</p>\n";
        appendResultsTable(html, jobs, columns, varyingMethods, groups, options.errorMetric);
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
