#include "experiments/sweep/ResultGroups.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiments/output/ReportHtml.h"
#include "experiments/render/RunMetrics.h"

namespace experiments {

using nlohmann::json;

namespace {

// Method columns: what a group compares (everything else makes the group).
constexpr const char* kMethodColumns[] = {"stage", "layout",   "normals", "normal-space",
                                          "depth", "position", "post-aa"};
// The columns of the results table a reader compares first, after the method columns; the rest
// are behind the "all columns" toggle.
constexpr const char* kMainMetricColumns[] = {"time_total_median_ms", "relative_rmse", "flip",
                                              "culling_efficiency", "simt_efficiency"};
// Settings known to be axis columns, for results that do not list theirs.
constexpr const char* kKnownAxisColumns[] = {
    "scene",    "stage",   "lights", "seed",    "resolution",   "width",
    "height",   "threads", "layout", "normals", "normal-space", "depth",
    "position", "post-aa", "view",   "views",   "repetitions",  "warmup"};

} // namespace

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

std::vector<std::string> reportErrorMetrics() {
    return {"relative_rmse", "rmse", "flip", "psnr", "max_abs", "relative_mean", "p99_abs"};
}

bool isMethodColumn(const std::string& column) {
    for (const char* method : kMethodColumns)
        if (column == method)
            return true;
    return false;
}

std::vector<std::string> axisColumnsOf(const json& results) {
    std::vector<std::string> axes;
    if (results.contains("axis_columns") && results["axis_columns"].is_array()) {
        for (const json& column : results["axis_columns"])
            if (column.is_string())
                axes.push_back(column.get<std::string>());
        return axes;
    }
    for (const std::string& column : resultColumns(results)) {
        const bool known = std::any_of(std::begin(kKnownAxisColumns), std::end(kKnownAxisColumns),
                                       [&](const char* name) { return column == name; }) ||
                           column.rfind("scene-option.", 0) == 0;
        if (known)
            axes.push_back(column);
    }
    return axes;
}

std::vector<JobGroup> comparableGroups(const json& jobs, const std::vector<std::string>& axes) {
    std::vector<std::string> grouping;
    for (const std::string& column : axes)
        if (!isMethodColumn(column) && column != "resolution")
            grouping.push_back(column);
    // Which grouping columns vary: those are named in every label, with the always-named ones.
    std::vector<std::string> varying;
    for (const std::string& column : grouping) {
        std::set<std::string> values;
        for (const json& job : jobs)
            values.insert(normalisedSelectValue(job.value(column, json())));
        if (values.size() > 1)
            varying.push_back(column);
    }
    std::vector<JobGroup> groups;
    std::map<std::string, size_t> byKey;
    for (size_t j = 0; j < jobs.size(); ++j) {
        const json& job = jobs[j];
        std::string key;
        for (const std::string& column : grouping)
            key += column + "=" + normalisedSelectValue(job.value(column, json())) + "\n";
        auto [it, inserted] = byKey.emplace(key, groups.size());
        if (inserted) {
            JobGroup group;
            group.id = "g" + std::to_string(groups.size() + 1);
            group.fixed = nlohmann::ordered_json::object();
            std::string label;
            auto add = [&](const std::string& part) {
                label += (label.empty() ? "" : ", ") + part;
            };
            auto text = [&](const char* column) {
                return normalisedSelectValue(job.value(column, json()));
            };
            for (const std::string& column : grouping) {
                group.fixed[column] = job.value(column, json());
                const bool named =
                    std::find(varying.begin(), varying.end(), column) != varying.end();
                if (job.value(column, json()).is_null())
                    continue;
                if (column == "scene")
                    add(text("scene"));
                else if (column == "lights")
                    add(text("lights") + " lights");
                else if (column == "width")
                    add(text("width") + "x" + text("height"));
                else if (column == "threads")
                    add(text("threads") + " threads");
                else if (named && column != "height")
                    add(column + " " + normalisedSelectValue(job.value(column, json())));
            }
            group.label = label.empty() ? "all jobs" : label;
            groups.push_back(std::move(group));
        }
        groups[it->second].jobs.push_back(j);
    }
    return groups;
}

json aggregateOverViews(const json& jobs, const std::vector<JobGroup>& groups,
                        const std::vector<std::string>& axes, const std::string& errorMetric) {
    std::vector<std::string> metrics = {"time_total_median_ms", errorMetric};
    if (errorMetric != metric::kFlip)
        metrics.push_back(metric::kFlip);
    json result = {{"aggregated_over", "view"},
                   {"statistic", "median, min and max over the views"},
                   {"metrics", metrics},
                   {"families", json::array()}};
    if (std::find(axes.begin(), axes.end(), "view") == axes.end())
        return result;
    // Families: the comparable groups of the same jobs without the view as a grouping column.
    std::vector<std::string> withoutView;
    for (const std::string& column : axes)
        if (column != "view")
            withoutView.push_back(column);
    std::vector<std::string> groupOf(jobs.size());
    for (const JobGroup& group : groups)
        for (size_t j : group.jobs)
            groupOf[j] = group.id;
    std::vector<std::string> methodColumns;
    for (const std::string& column : axes)
        if (isMethodColumn(column))
            methodColumns.push_back(column);
    int familyNumber = 0;
    for (const JobGroup& family : comparableGroups(jobs, withoutView)) {
        std::vector<std::string> views, familyGroups;
        for (size_t j : family.jobs) {
            const std::string view = normalisedSelectValue(jobs[j].value("view", json()));
            if (std::find(views.begin(), views.end(), view) == views.end())
                views.push_back(view);
            if (std::find(familyGroups.begin(), familyGroups.end(), groupOf[j]) ==
                familyGroups.end())
                familyGroups.push_back(groupOf[j]);
        }
        if (views.size() < 2)
            continue; // one view: nothing to aggregate, the group says it all
        // Methods in order of first appearance; the label names the method columns that vary
        // in the family (stage always).
        std::vector<std::string> varying;
        for (const std::string& column : methodColumns) {
            std::set<std::string> values;
            for (size_t j : family.jobs)
                values.insert(normalisedSelectValue(jobs[j].value(column, json())));
            if (column == "stage" || values.size() > 1)
                varying.push_back(column);
        }
        std::vector<std::string> methodKeys;
        std::map<std::string, json> methods;
        for (size_t j : family.jobs) {
            const json& job = jobs[j];
            std::string key, label;
            json settings = json::object();
            for (const std::string& column : methodColumns) {
                key += column + "=" + normalisedSelectValue(job.value(column, json())) + "\n";
                settings[column] = job.value(column, json());
            }
            for (const std::string& column : varying)
                label += (label.empty() ? "" : ", ") + (column == "stage" ? "" : column + " ") +
                         normalisedSelectValue(job.value(column, json()));
            if (!methods.count(key)) {
                methodKeys.push_back(key);
                methods[key] = {{"label", label},
                                {"settings", settings},
                                {"views_ok", 0},
                                {"views_failed", 0},
                                {"rows", json::array()}};
            }
            json& method = methods[key];
            json row = {{"view", job.value("view", json())},
                        {"job_id", job.value("job_id", json())},
                        {"group", groupOf[j]},
                        {"status", job.value("status", json())}};
            for (const std::string& m : metrics) {
                const std::optional<double> value = jobMetric(job, json(m));
                row[m] = value && jobOk(job) ? json(*value) : json();
            }
            method[jobOk(job) ? "views_ok" : "views_failed"] =
                method[jobOk(job) ? "views_ok" : "views_failed"].get<int>() + 1;
            method["rows"].push_back(row);
        }
        json familyJson = {{"id", "v" + std::to_string(++familyNumber)},
                           {"label", family.label},
                           {"fixed", family.fixed},
                           {"views", views},
                           {"groups", familyGroups},
                           {"methods", json::array()}};
        for (const std::string& key : methodKeys) {
            json method = methods[key];
            for (const std::string& m : metrics) {
                std::vector<double> values;
                for (const json& row : method["rows"])
                    if (row[m].is_number())
                        values.push_back(row[m].get<double>());
                if (values.empty()) {
                    method[m] = nullptr;
                    continue;
                }
                method[m] = {{"median", *median(values)},
                             {"min", *std::min_element(values.begin(), values.end())},
                             {"max", *std::max_element(values.begin(), values.end())},
                             {"count", values.size()}};
            }
            familyJson["methods"].push_back(method);
        }
        result["families"].push_back(familyJson);
    }
    return result;
}

} // namespace experiments
