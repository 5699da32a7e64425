#include "experiments/sweep/ResultsTable.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include "experiments/output/AtomicFile.h"
#include "experiments/render/RunMetrics.h"
#include "experiments/sweep/CsvTable.h"
#include "experiments/sweep/SweepFile.h"
#include "lighting/passes/PassNames.h"
#include "scenes/input/DuplicateKeys.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/input/WholeFile.h"

namespace experiments {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

const std::string kTimePrefix = "time_";
const std::string kMedianSuffix = "_median_ms";

// Pipeline order of the passes stages report, then the stage's sum; anything else goes after
// them by name, and the total last.
std::vector<std::string> passOrder() {
    std::vector<std::string> order(lighting::pass::kPipelineOrder.begin(),
                                   lighting::pass::kPipelineOrder.end());
    order.push_back(pass::kStage);
    return order;
}

bool endsWith(const std::string& text, const std::string& suffix) {
    return text.size() >= suffix.size() &&
           text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A JSON value as a CSV cell: null empty, strings as they are, numbers as JSON writes them.
std::string cellText(const Json& value) {
    if (value.is_null())
        return "";
    return value.is_string() ? value.get<std::string>() : value.dump();
}

// A regular file within scenes::limits::kMaxFileBytes (scenes/input/WholeFile.h): a FIFO or
// /dev/zero in an output folder is refused at once instead of hanging or filling memory.
std::string readText(const fs::path& path) {
    std::string text;
    if (const std::string problem = scenes::readWholeFile(path, &text); !problem.empty())
        throw SweepError(path.string() + ": " + problem);
    return text;
}

// Results and markers are ours but may have been edited: nesting past scenes::limits and a key
// given twice (which the parser would silently resolve) are refused before parsing (values are
// copied recursively afterwards).
Json parseBounded(const std::string& text, const fs::path& path) {
    scenes::NestingViolation violation;
    if (scenes::jsonNestsDeeperThan(text, scenes::limits::kMaxNestingDepth, &violation))
        throw SweepError(path.string() + ":" + std::to_string(violation.line) +
                         ": nests deeper than " + std::to_string(scenes::limits::kMaxNestingDepth) +
                         " levels");
    if (const std::string problem = scenes::jsonDuplicateKeyProblem(text); !problem.empty())
        throw SweepError(path.string() + ": " + problem);
    return Json::parse(text);
}

// Hard link when the file system allows it (no copy of EXRs), else a copy.
void linkOrCopy(const fs::path& from, const fs::path& to) {
    std::error_code error;
    fs::remove(to, error);
    fs::create_hard_link(from, to, error);
    if (error)
        fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

bool samePath(const fs::path& a, const fs::path& b) {
    std::error_code error;
    return fs::exists(a) && fs::exists(b) && fs::equivalent(a, b, error);
}

} // namespace

std::vector<std::string> metricColumns(const std::vector<Json>& rows) {
    std::set<std::string> passes;
    for (const Json& row : rows)
        for (const auto& [key, value] : row.items())
            if (!value.is_null() && key.rfind(kTimePrefix, 0) == 0 && endsWith(key, kMedianSuffix))
                passes.insert(key.substr(kTimePrefix.size(),
                                         key.size() - kTimePrefix.size() - kMedianSuffix.size()));
    const std::vector<std::string> order = passOrder();
    std::vector<std::string> ordered;
    for (const std::string& name : order)
        if (passes.count(name))
            ordered.push_back(name);
    for (const std::string& name : passes) // std::set: by name
        if (std::find(order.begin(), order.end(), name) == order.end() && name != pass::kTotal)
            ordered.push_back(name);
    if (passes.count(pass::kTotal))
        ordered.push_back(pass::kTotal);
    std::vector<std::string> columns;
    for (const std::string& name : ordered)
        for (const char* statistic : {"median", "min", "max"})
            columns.push_back(kTimePrefix + name + "_" + statistic + "_ms");
    const std::vector<std::string> figures = runFigureColumns();
    columns.insert(columns.end(), figures.begin(), figures.end());
    return columns;
}

Json resultsJson(const Json& sweep, const std::string& sweepFile, bool quick,
                 const std::vector<std::string>& axisColumns, std::vector<Json> rows) {
    std::vector<std::string> columns = {"job_id", "status", "error"};
    columns.insert(columns.end(), axisColumns.begin(), axisColumns.end());
    const std::vector<std::string> metrics = metricColumns(rows);
    columns.insert(columns.end(), metrics.begin(), metrics.end());
    std::sort(rows.begin(), rows.end(), [](const Json& a, const Json& b) {
        return a.value("job_id", "") < b.value("job_id", "");
    });
    Json jobs = Json::array();
    for (const Json& row : rows) {
        Json complete = Json::object();
        for (const std::string& column : columns)
            complete[column] = row.contains(column) ? row[column] : Json(nullptr);
        jobs.push_back(std::move(complete));
    }
    Json results = Json::object();
    results["sweep"] = sweep;
    results["sweep_file"] = sweepFile;
    results["quick"] = quick;
    results["columns"] = columns;
    results["axis_columns"] = axisColumns;
    results["jobs"] = std::move(jobs);
    return results;
}

std::string resultsCsv(const Json& results) {
    std::vector<std::string> columns;
    for (const Json& column : results.at("columns"))
        columns.push_back(cellText(column));
    CsvTable table(columns);
    for (const Json& job : results.at("jobs")) {
        std::vector<std::string> cells;
        for (const std::string& name : columns)
            cells.push_back(cellText(job.contains(name) ? job[name] : Json(nullptr)));
        table.addRow(std::move(cells));
    }
    return table.text();
}

void writeResults(const fs::path& dir, const Json& results) {
    writeTextAtomically(dir / "results.json", results.dump(2) + "\n");
    writeTextAtomically(dir / "results.csv", resultsCsv(results));
}

Json readResults(const fs::path& dir) {
    const fs::path file = dir / "results.json";
    std::error_code error;
    if (!fs::exists(file, error))
        throw SweepError(file.string() + ": not found (is " + dir.string() +
                         " a sweep output folder?)");
    Json results;
    try {
        results = parseBounded(readText(file), file);
    } catch (const nlohmann::json::exception& e) {
        throw SweepError(file.string() + ": not valid JSON: " + e.what());
    }
    for (const char* key : {"sweep", "sweep_file", "quick", "columns", "axis_columns", "jobs"})
        if (!results.contains(key))
            throw SweepError(file.string() + ": lacks '" + key + "'");
    return results;
}

size_t mergeSweepOutputs(const std::vector<fs::path>& inputs, const fs::path& out) {
    if (inputs.empty())
        throw SweepError("merge: no input folders");
    std::vector<Json> results;
    for (const fs::path& input : inputs)
        results.push_back(readResults(input));
    const Json& first = results.front();
    for (size_t i = 1; i < results.size(); ++i)
        for (const char* key : {"sweep", "quick", "axis_columns"})
            if (results[i][key] != first[key])
                throw SweepError("merge: " + inputs[i].string() + " and " + inputs[0].string() +
                                 " are not outputs of the same sweep: their '" + key + "' differ");

    struct Source {
        fs::path folder;
        Json row;
    };
    std::map<std::string, Source> jobs; // by job_id
    for (size_t i = 0; i < results.size(); ++i)
        for (const Json& listed : results[i]["jobs"]) {
            const std::string id = listed.at("job_id").get<std::string>();
            const fs::path folder = inputs[i] / "jobs" / id;
            if (!fs::is_regular_file(folder / kDoneMarker))
                throw SweepError("merge: " + (folder / kDoneMarker).string() +
                                 " missing although results.json lists the job");
            // The marker's row, not the table's (which is padded with the table's columns).
            Json marker;
            try {
                marker = parseBounded(readText(folder / kDoneMarker), folder / kDoneMarker);
            } catch (const nlohmann::json::exception& e) {
                throw SweepError("merge: " + (folder / kDoneMarker).string() + ": " + e.what());
            }
            if (!marker.contains("row") || marker["row"].value("job_id", "") != id)
                throw SweepError("merge: " + (folder / kDoneMarker).string() + " is not job " + id +
                                 "'s marker");
            const auto [it, inserted] = jobs.emplace(id, Source{folder, marker["row"]});
            if (!inserted && it->second.row != marker["row"])
                throw SweepError("merge: job " + id + " differs between " +
                                 it->second.folder.string() + " and " + folder.string() +
                                 "; refusing to pick one");
        }

    ensureWritableDirectory(out);
    std::vector<Json> rows;
    for (const auto& [id, source] : jobs) {
        const fs::path target = out / "jobs" / id;
        if (!samePath(source.folder, target)) {
            fs::create_directories(target);
            fs::remove(target / kDoneMarker); // unfinished until its marker is copied, last
            for (const fs::directory_entry& entry : fs::directory_iterator(source.folder)) {
                const std::string name = entry.path().filename().string();
                if (!entry.is_regular_file() || name == kDoneMarker || name.front() == '.')
                    continue;
                linkOrCopy(entry.path(), target / name);
            }
            // An explicit capture: clang 14 (sanitizer builds) cannot capture a structured binding.
            const fs::path marker = source.folder / kDoneMarker;
            writeFileAtomically(target / kDoneMarker, [&](const fs::path& temporary) {
                fs::copy_file(marker, temporary, fs::copy_options::overwrite_existing);
            });
        }
        rows.push_back(source.row);
    }
    std::vector<std::string> axis;
    for (const Json& column : first["axis_columns"])
        axis.push_back(column.get<std::string>());
    writeResults(out, resultsJson(first["sweep"], first["sweep_file"].get<std::string>(),
                                  first["quick"].get<bool>(), axis, std::move(rows)));
    return jobs.size();
}

} // namespace experiments
