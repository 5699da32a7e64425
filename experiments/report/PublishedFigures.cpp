#include "experiments/report/PublishedFigures.h"

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

#include "experiments/output/ReportHtml.h"
#include "experiments/sweep/ResultGroups.h"

namespace experiments {

using nlohmann::json;

namespace {

// ", median over different X, Y" when the matched jobs of a cell differ in some axis columns.
std::string differNote(const json& cell) {
    if (!cell.contains("differ_in") || cell["differ_in"].empty())
        return "";
    std::string columns;
    for (const json& column : cell["differ_in"])
        columns += (columns.empty() ? "" : ", ") + htmlEscape(column.get<std::string>());
    return "<br><small>median over different " + columns + "</small>";
}
} // namespace

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
         << "&rdquo; of the same row. Measured values are medians over the matching ok jobs; "
            "a cell whose jobs differ in a setting says which.";
    const bool modelled = table.value("modelled", json()).is_string();
    if (modelled)
        html << " Modelled ratios are those of <code>"
             << htmlEscape(table["modelled"].get<std::string>())
             << "</code> over the same jobs: what the cost model (for simt_lane_slots, a SIMT GPU "
                "whose warp pays for a light when any lane evaluates it) predicts for the "
                "published ratio.";
    html << "</p>\n";
    const int cellColumns = modelled ? 6 : 5;
    html << "<div class=\"scroll\"><table class=\"published\">\n<tr><th class=\"text\" "
            "rowspan=\"2\">row</th>";
    for (const json& column : columns)
        html << "<th colspan=\"" << cellColumns << "\">" << htmlEscape(column.get<std::string>())
             << "</th>";
    html << "</tr>\n<tr>";
    for (size_t c = 0; c < columns.size(); ++c)
        html << "<th>published</th><th>measured</th><th>published ratio</th>"
             << (modelled ? "<th>modelled ratio</th>" : "")
             << "<th>measured ratio</th><th>jobs</th>";
    html << "</tr>\n";
    for (const json& row : table["rows"]) {
        html << "<tr><td class=\"text\">" << htmlEscape(row["label"].get<std::string>()) << "</td>";
        for (const json& cell : row["cells"])
            html << "<td>" << formatOptional(cell["published"]) << "</td><td>"
                 << formatOptional(cell["measured"]) << "</td><td>"
                 << formatOptional(cell["published_ratio"], "&times;") << "</td><td>"
                 << (modelled ? formatOptional(cell.value("modelled_ratio", json()), "&times;") +
                                    "</td><td>"
                              : "")
                 << formatOptional(cell["measured_ratio"], "&times;") << "</td><td>"
                 << cell["matched_jobs"].get<int>() << differNote(cell) << "</td>";
        html << "</tr>\n";
    }
    html << "</table></div>\n";
    const std::string finding = stringField(table, "finding");
    if (!finding.empty())
        html << "<p class=\"finding\"><b>Published finding:</b> " << htmlEscape(finding)
             << "</p>\n";
}

json comparePublished(const json& published, const json& jobs,
                      const std::vector<std::string>& axisColumns) {
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
    // The column of a cost model whose ratios predict the metric's (the reproductions name
    // simt_lane_slots, what a SIMT GPU would pay): shown beside published and measured.
    const json modelled = published.value("modelled", json());
    if (!modelled.is_null() && !modelled.is_string())
        throw fail("\"modelled\" must be a column name");

    json table = {{"title", title},
                  {"source", stringField(published, "source")},
                  {"metric", metric},
                  {"metric_label", metricLabel(metric)},
                  {"finding", stringField(published, "finding")},
                  {"ratio_to", ratioTo},
                  {"modelled", modelled},
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
        std::vector<std::optional<double>> publishedValues, measuredValues, modelledValues;
        std::vector<int> matchCounts;
        std::vector<json> differIn;
        for (size_t c = 0; c < columns.size(); ++c) {
            if (!values[c].is_null() && !values[c].is_number())
                throw fail(where + ".values[" + std::to_string(c) + "] must be a number or null");
            publishedValues.push_back(values[c].is_null() ? std::nullopt
                                                          : std::optional(values[c].get<double>()));
            std::vector<double> measured, model;
            int matched = 0;
            std::map<std::string, std::set<std::string>> values; // per axis column
            for (const json& job : jobs) {
                if (!jobOk(job) || !jobMatchesSelect(job, row.value("select", json::object())) ||
                    !jobMatchesSelect(job, columns[c].value("select", json::object())))
                    continue;
                ++matched;
                if (const auto value = jobMetric(job, metric))
                    measured.push_back(*value);
                if (!modelled.is_null())
                    if (const auto value = jobMetric(job, modelled))
                        model.push_back(*value);
                for (const std::string& column : axisColumns)
                    values[column].insert(normalisedSelectValue(job.value(column, json())));
            }
            measuredValues.push_back(median(measured));
            modelledValues.push_back(median(model));
            matchCounts.push_back(matched);
            json differ = json::array();
            for (const std::string& column : axisColumns)
                if (values[column].size() > 1)
                    differ.push_back(column);
            differIn.push_back(differ);
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
                             {"modelled", toJson(modelledValues[c])},
                             {"modelled_ratio", ratio(modelledValues, c)},
                             {"matched_jobs", matchCounts[c]},
                             {"differ_in", differIn[c]}});
        table["rows"].push_back(
            {{"label", row.value("label", "row " + std::to_string(r))}, {"cells", cells}});
    }
    return table;
}

} // namespace experiments
