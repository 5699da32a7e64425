#include "experiments/advise/Advisor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "experiments/CommandErrors.h"
#include "experiments/compare/ImageMetrics.h"
#include "experiments/output/AtomicFile.h"
#include "experiments/output/ReportHtml.h"
#include "experiments/sweep/ResultGroups.h"
#include "experiments/sweep/ResultsTable.h"

namespace experiments {

using nlohmann::json;

namespace {

constexpr const char* kTimeMedian = "time_total_median_ms";
constexpr const char* kTimeMin = "time_total_min_ms";
constexpr const char* kTimeMax = "time_total_max_ms";

struct Candidate {
    std::string method;
    json settings = json::object();
    std::string jobId;
    double timeMs = 0.0, timeMinMs = 0.0, timeMaxMs = 0.0;
    double error = 0.0;
};

json candidateJson(const Candidate& c) {
    return {{"method", c.method},  {"settings", c.settings},     {"job_id", c.jobId},
            {"time_ms", c.timeMs}, {"time_min_ms", c.timeMinMs}, {"time_max_ms", c.timeMaxMs},
            {"error", c.error}};
}

// The method columns whose values differ among the group's jobs, stage always first when present.
std::vector<std::string> varyingMethods(const json& jobs, const JobGroup& group,
                                        const std::vector<std::string>& axes) {
    std::vector<std::string> varying;
    for (const std::string& column : axes) {
        if (!isMethodColumn(column))
            continue;
        std::string first;
        bool differs = false, seen = false;
        for (size_t index : group.jobs) {
            const std::string value = normalisedSelectValue(jobs[index].value(column, json()));
            if (!seen)
                first = value, seen = true;
            else if (value != first)
                differs = true;
        }
        if (differs || column == "stage")
            varying.push_back(column);
    }
    std::stable_partition(varying.begin(), varying.end(),
                          [](const std::string& c) { return c == "stage"; });
    return varying;
}

std::string methodName(const json& job, const std::vector<std::string>& varying) {
    std::string name;
    for (const std::string& column : varying) {
        const std::string value = normalisedSelectValue(job.value(column, json()));
        if (name.empty() && column == "stage")
            name = value;
        else
            name += (name.empty() ? "" : ", ") + column + " " + value;
    }
    return name.empty() ? job.value("job_id", std::string("?")) : name;
}

std::string number(double value, int digits = 3) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    return buffer;
}

bool timesOverlap(const Candidate& a, const Candidate& b) {
    return a.timeMinMs <= b.timeMaxMs && b.timeMinMs <= a.timeMaxMs;
}

// The best candidate of `pool` in the order `before`, the candidates `tied` with it (listed, not
// ranked), the first that is not (the runner-up) and margin(best, runner-up).
template <class Before, class Tied, class Margin>
json answer(std::vector<Candidate> pool, const std::string& whyNone, Before before, Tied tied,
            Margin margin) {
    json result = {{"best", nullptr},   {"tied", json::array()},    {"runner_up", nullptr},
                   {"margin", nullptr}, {"distinguishable", false}, {"why_none", ""}};
    if (pool.empty()) {
        result["why_none"] = whyNone;
        return result;
    }
    std::stable_sort(pool.begin(), pool.end(), before);
    const Candidate& best = pool.front();
    result["best"] = candidateJson(best);
    const Candidate* runnerUp = nullptr;
    for (size_t i = 1; i < pool.size(); ++i) {
        if (tied(best, pool[i]))
            result["tied"].push_back(candidateJson(pool[i]));
        else if (!runnerUp)
            runnerUp = &pool[i];
    }
    if (runnerUp) {
        result["runner_up"] = candidateJson(*runnerUp);
        result["margin"] = margin(best, *runnerUp);
    }
    result["distinguishable"] = result["tied"].empty();
    return result;
}

// The fastest candidate (median time); tied: overlapping repetition ranges; margin: how many
// times faster than the runner-up.
json fastestAnswer(std::vector<Candidate> pool, const std::string& whyNone) {
    return answer(
        std::move(pool), whyNone,
        [](const Candidate& a, const Candidate& b) {
            return a.timeMs < b.timeMs || (a.timeMs == b.timeMs && a.error < b.error);
        },
        timesOverlap,
        [](const Candidate& best, const Candidate& next) {
            return best.timeMs > 0.0 ? json(next.timeMs / best.timeMs) : json();
        });
}

// The least-error candidate; tied: exactly equal error; margin: runner-up error / best error.
json leastErrorAnswer(std::vector<Candidate> pool, const std::string& whyNone) {
    return answer(
        std::move(pool), whyNone,
        [](const Candidate& a, const Candidate& b) {
            return a.error < b.error || (a.error == b.error && a.timeMs < b.timeMs);
        },
        [](const Candidate& best, const Candidate& c) { return c.error == best.error; },
        [](const Candidate& best, const Candidate& next) {
            return best.error > 0.0 ? json(next.error / best.error) : json();
        });
}

// Candidates no other beats in both median time and error, fastest first.
json paretoFront(std::vector<Candidate> pool) {
    std::stable_sort(pool.begin(), pool.end(), [](const Candidate& a, const Candidate& b) {
        return a.timeMs < b.timeMs || (a.timeMs == b.timeMs && a.error < b.error);
    });
    json front = json::array();
    double bestError = INFINITY;
    for (const Candidate& c : pool)
        if (c.error < bestError) {
            front.push_back(candidateJson(c));
            bestError = c.error;
        }
    return front;
}

bool groupMatches(const JobGroup& group, const AdviceCriteria& criteria) {
    for (const auto& [key, value] : criteria.groupFilters) {
        const auto it = group.fixed.find(key);
        if (it == group.fixed.end() || normalisedSelectValue(*it) != normalisedSelectValue(value))
            return false;
    }
    return true;
}

} // namespace

json adviseOnResults(const json& results, const AdviceCriteria& criteria) {
    if (!(criteria.budgetMs > 0.0) || !std::isfinite(criteria.budgetMs))
        throw std::invalid_argument("--budget-ms must be a positive number of milliseconds");
    if (criteria.maxFlip && criteria.maxRelativeRmse)
        throw std::invalid_argument("give one error budget: --max-flip or --max-rmse, not both");
    for (const auto& budget : {criteria.maxFlip, criteria.maxRelativeRmse})
        if (budget && (!std::isfinite(*budget) || *budget < 0.0))
            throw std::invalid_argument("an error budget must be a finite number >= 0");
    if (!results.is_object() || !results.contains("jobs") || !results["jobs"].is_array())
        throw std::invalid_argument("the results have no jobs array");
    const json& jobs = results["jobs"];
    const std::vector<std::string> axes = axisColumnsOf(results);
    for (const auto& [key, value] : criteria.groupFilters)
        if (std::find(axes.begin(), axes.end(), key) == axes.end())
            throw std::invalid_argument("--group " + key + "=" + value +
                                        ": the sweep has no setting '" + key + "'");

    // The error metric: the budgeted one; else ꟻLIP when every ok job has it, else relative RMSE.
    std::string errorMetric = metric::kRelativeRmse;
    if (criteria.maxFlip) {
        errorMetric = metric::kFlip;
    } else if (!criteria.maxRelativeRmse) {
        bool allFlip = false;
        for (const json& job : jobs) {
            if (!jobOk(job))
                continue;
            allFlip = true;
            if (!jobMetric(job, metric::kFlip)) {
                allFlip = false;
                break;
            }
        }
        if (allFlip)
            errorMetric = metric::kFlip;
    }
    const std::optional<double> maxError =
        criteria.maxFlip ? criteria.maxFlip : criteria.maxRelativeRmse;

    json advice;
    advice["criteria"] = {
        {"budget_ms", criteria.budgetMs},
        {"max_flip", criteria.maxFlip ? json(*criteria.maxFlip) : json()},
        {"max_relative_rmse", criteria.maxRelativeRmse ? json(*criteria.maxRelativeRmse) : json()},
        {"group_filters", json::object()}};
    for (const auto& [key, value] : criteria.groupFilters)
        advice["criteria"]["group_filters"][key] = value;
    advice["error_metric"] = errorMetric;
    advice["time_metric"] = kTimeMedian;
    advice["groups"] = json::array();

    // Families: groups equal in everything but the view.
    std::map<std::string, json> families;
    std::vector<std::string> familyOrder;

    for (const JobGroup& group : comparableGroups(jobs, axes)) {
        if (!groupMatches(group, criteria))
            continue;
        const std::vector<std::string> varying = varyingMethods(jobs, group, axes);
        json groupJson = {{"id", group.id},
                          {"label", group.label},
                          {"fixed", group.fixed},
                          {"jobs", group.jobs.size()},
                          {"excluded", json::array()}};
        std::vector<Candidate> all;
        for (size_t index : group.jobs) {
            const json& job = jobs[index];
            const std::string id = job.value("job_id", std::string("?"));
            auto exclude = [&](const std::string& reason) {
                groupJson["excluded"].push_back({{"job_id", id}, {"reason", reason}});
            };
            if (!jobOk(job)) {
                exclude("failed: " + job.value("error", std::string()));
                continue;
            }
            const auto time = jobMetric(job, kTimeMedian);
            const auto error = jobMetric(job, errorMetric);
            if (!time) {
                exclude("no total time");
                continue;
            }
            if (!error) {
                exclude("no " + errorMetric + " (compared without a reference?)");
                continue;
            }
            Candidate c;
            c.method = methodName(job, varying);
            for (const std::string& column : varying)
                c.settings[column] = job.value(column, json());
            c.jobId = id;
            c.timeMs = *time;
            c.timeMinMs = jobMetric(job, kTimeMin).value_or(*time);
            c.timeMaxMs = jobMetric(job, kTimeMax).value_or(*time);
            c.error = *error;
            all.push_back(c);
        }

        std::vector<Candidate> withinError, withinTime;
        for (const Candidate& c : all) {
            if (!maxError || c.error <= *maxError)
                withinError.push_back(c);
            if (c.timeMs <= criteria.budgetMs)
                withinTime.push_back(c);
        }
        std::string noErrorFit, noTimeFit;
        if (!all.empty()) {
            const auto leastError = *std::min_element(
                all.begin(), all.end(), [](auto& a, auto& b) { return a.error < b.error; });
            const auto fastest = *std::min_element(
                all.begin(), all.end(), [](auto& a, auto& b) { return a.timeMs < b.timeMs; });
            if (maxError)
                noErrorFit = "no method within " + errorMetric + " <= " + number(*maxError) +
                             "; the least " + errorMetric + " is " + number(leastError.error, 4) +
                             " (" + leastError.method + ")";
            noTimeFit = "no method within " + number(criteria.budgetMs) +
                        " ms; the fastest takes " + number(fastest.timeMs, 4) + " ms (" +
                        fastest.method + ")";
        } else {
            noErrorFit = noTimeFit = "no job of the group has both a time and " + errorMetric;
        }
        groupJson["fastest"] = fastestAnswer(withinError, noErrorFit);
        groupJson["least_error"] = leastErrorAnswer(withinTime, noTimeFit);
        groupJson["pareto"] = paretoFront(all);

        // The family (same group but for the view) and its winners per view.
        json familyFixed = group.fixed;
        std::string view;
        if (familyFixed.contains("view")) {
            view = normalisedSelectValue(familyFixed["view"]);
            familyFixed.erase("view");
        }
        const std::string key = familyFixed.dump();
        if (!families.count(key)) {
            familyOrder.push_back(key);
            families[key] = {{"fixed", familyFixed},
                             {"views", json::array()},
                             {"fastest_wins", json::object()},
                             {"least_error_wins", json::object()}};
        }
        json& family = families[key];
        family["views"].push_back(view.empty() ? "default" : view);
        for (const char* answerKey : {"fastest", "least_error"}) {
            const json& best = groupJson[answerKey]["best"];
            if (best.is_null())
                continue;
            json& wins = family[std::string(answerKey) + "_wins"];
            const std::string method = best["method"].get<std::string>();
            wins[method] = wins.value(method, 0) + 1;
        }
        advice["groups"].push_back(groupJson);
    }
    advice["families"] = json::array();
    for (const std::string& key : familyOrder)
        if (families[key]["views"].size() > 1)
            advice["families"].push_back(families[key]);
    return advice;
}

namespace {

std::string candidateText(const json& c, const std::string& errorMetric) {
    return c["method"].get<std::string>() + ": " + number(c["time_ms"].get<double>(), 4) + " ms (" +
           number(c["time_min_ms"].get<double>(), 4) + "-" +
           number(c["time_max_ms"].get<double>(), 4) + "), " + errorMetric + " " +
           number(c["error"].get<double>(), 4);
}

void appendAnswer(std::ostringstream& out, const char* title, const json& answer,
                  const std::string& errorMetric, bool time) {
    out << "  " << title << ": ";
    if (answer["best"].is_null()) {
        out << answer["why_none"].get<std::string>() << "\n";
        return;
    }
    out << candidateText(answer["best"], errorMetric);
    if (!answer["distinguishable"].get<bool>()) {
        out << "; INDISTINGUISHABLE from";
        for (const json& tied : answer["tied"])
            out << " " << tied["method"].get<std::string>();
        out << (time ? " (repetition ranges overlap)" : " (equal error)");
    } else if (!answer["runner_up"].is_null()) {
        const json& runner = answer["runner_up"];
        if (!answer["margin"].is_null())
            out << "; " << number(answer["margin"].get<double>(), 3) << "x "
                << (time ? "faster than " : "less error than ")
                << runner["method"].get<std::string>();
        else
            out << "; next: " << runner["method"].get<std::string>();
    } else {
        out << " (the only one)";
    }
    out << "\n";
}

} // namespace

std::string adviceText(const json& advice) {
    std::ostringstream out;
    const std::string errorMetric = advice["error_metric"].get<std::string>();
    const json& criteria = advice["criteria"];
    out << "budget " << number(criteria["budget_ms"].get<double>()) << " ms";
    if (!criteria["max_flip"].is_null())
        out << ", flip <= " << number(criteria["max_flip"].get<double>());
    if (!criteria["max_relative_rmse"].is_null())
        out << ", relative_rmse <= " << number(criteria["max_relative_rmse"].get<double>());
    out << "; times are median total frame times (min-max over the repetitions)\n";
    if (advice["groups"].empty())
        out << "no group matches\n";
    for (const json& group : advice["groups"]) {
        out << group["label"].get<std::string>() << " (" << group["jobs"].get<size_t>()
            << " jobs):\n";
        const std::string errorBudget =
            criteria["max_flip"].is_null() && criteria["max_relative_rmse"].is_null()
                ? "fastest"
                : "fastest within the error budget";
        appendAnswer(out, errorBudget.c_str(), group["fastest"], errorMetric, true);
        appendAnswer(out, "least error within the time budget", group["least_error"], errorMetric,
                     false);
        out << "  pareto front:";
        for (const json& c : group["pareto"])
            out << " " << c["method"].get<std::string>() << " ("
                << number(c["time_ms"].get<double>(), 4) << " ms, "
                << number(c["error"].get<double>(), 3) << ")";
        out << "\n";
        if (!group["excluded"].empty())
            out << "  excluded: " << group["excluded"].size() << " job(s) (advice.json says why)\n";
    }
    for (const json& family : advice["families"]) {
        out << "across " << family["views"].size() << " views of " << family["fixed"].dump() << ":";
        for (const char* key : {"fastest_wins", "least_error_wins"})
            for (const auto& [method, wins] : family[key].items())
                out << " " << (key[0] == 'f' ? "fastest " : "least error ") << method << " in "
                    << wins.get<int>() << "/" << family["views"].size() << ";";
        out << "\n";
    }
    return out.str();
}

std::string adviceHtml(const json& advice) {
    const std::string errorMetric = advice.value("error_metric", std::string("?"));
    auto answerCell = [&](const json& answer, bool time) {
        if (answer["best"].is_null())
            return "<td class=\"text\">" + htmlEscape(answer.value("why_none", "")) + "</td>";
        const json& best = answer["best"];
        std::string cell = "<td class=\"text\"><b>" + htmlEscape(best["method"]) + "</b> " +
                           number(best["time_ms"].get<double>(), 4) + " ms (" +
                           number(best["time_min_ms"].get<double>(), 4) + "&ndash;" +
                           number(best["time_max_ms"].get<double>(), 4) + "), " +
                           htmlEscape(errorMetric) + " " + number(best["error"].get<double>(), 4);
        if (!answer["distinguishable"].get<bool>()) {
            cell += "<br><b>indistinguishable</b> from";
            for (const json& tied : answer["tied"])
                cell += " " + htmlEscape(tied["method"].get<std::string>());
            cell += time ? " (repetition ranges overlap)" : " (equal error)";
        } else if (!answer["runner_up"].is_null() && !answer["margin"].is_null()) {
            cell += "<br>" + number(answer["margin"].get<double>(), 3) + "&times; " +
                    (time ? "faster than " : "less error than ") +
                    htmlEscape(answer["runner_up"]["method"].get<std::string>());
        }
        return cell + "</td>";
    };
    std::ostringstream html;
    const json& criteria = advice["criteria"];
    html << "<h2 id=\"advice\">Advice</h2>\n<p>From <code>testbed advise</code>: budget "
         << number(criteria["budget_ms"].get<double>()) << " ms";
    if (!criteria["max_flip"].is_null())
        html << ", ꟻLIP &le; " << number(criteria["max_flip"].get<double>());
    if (!criteria["max_relative_rmse"].is_null())
        html << ", relative RMSE &le; " << number(criteria["max_relative_rmse"].get<double>());
    html << "; times are median total frame times with the repetitions' min&ndash;max; two "
            "methods whose ranges overlap are reported as indistinguishable.</p>\n"
            "<table><tr><th class=\"text\">group</th><th class=\"text\">fastest within the "
            "error budget</th><th class=\"text\">least error within the time budget</th><th "
            "class=\"text\">Pareto front (ms, "
         << htmlEscape(errorMetric) << ")</th></tr>\n";
    for (const json& group : advice["groups"]) {
        html << "<tr><td class=\"text\">" << htmlEscape(group["label"].get<std::string>())
             << "</td>" << answerCell(group["fastest"], true)
             << answerCell(group["least_error"], false) << "<td class=\"text\">";
        for (const json& c : group["pareto"])
            html << htmlEscape(c["method"].get<std::string>()) << " ("
                 << number(c["time_ms"].get<double>(), 4) << ", "
                 << number(c["error"].get<double>(), 3) << ")<br>";
        html << "</td></tr>\n";
    }
    html << "</table>\n";
    return html.str();
}

int runAdviseCommand(const AdviseCommandOptions& options) {
    try {
        const nlohmann::ordered_json results = readResults(options.dir);
        const json advice = adviseOnResults(json::parse(results.dump()), options.criteria);
        writeTextAtomically(options.dir / "advice.json", advice.dump(1) + "\n");
        std::cout << adviceText(advice) << "advice: " << (options.dir / "advice.json").string()
                  << "\n";
        return 0;
    } catch (const std::exception& error) {
        return reportError(error);
    }
}

} // namespace experiments
