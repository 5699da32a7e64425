// The advisor (experiments/advise/Advisor.h) on a small sweep whose answers follow by hand: one
// scene at two light counts and two views, four methods each. Times are the total frame time's
// median and min-max over repetitions; errors are mean ꟻLIP.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "experiments/advise/Advisor.h"
#include "tests/experiments/TestFolders.h"

namespace {

using nlohmann::json;

json job(const std::string& id, const std::string& stage, const std::string& layout, int lights,
         const std::string& view, double median, double min, double max, double flip,
         double relativeRmse) {
    return {{"job_id", id},
            {"status", "ok"},
            {"error", ""},
            {"scene", "atrium"},
            {"stage", stage},
            {"lights", lights},
            {"layout", layout},
            {"view", view},
            {"width", 320},
            {"height", 180},
            {"time_total_median_ms", median},
            {"time_total_min_ms", min},
            {"time_total_max_ms", max},
            {"flip", flip},
            {"relative_rmse", relativeRmse}};
}

// At 256 lights, view a:
//   brute     20 ms (19-21)   flip 0      exact but slow
//   tiled      6 ms (5.8-6.2) flip 0.010
//   clustered  8 ms (7.9-8.1) flip 0.010
//   inferred   5 ms (4.9-5.1) flip 0.060  fastest, too wrong for a 0.05 budget
// At 1024 lights, view a: tiled and clustered overlap in time (9-11 vs 9.5-10.5).
json results() {
    json jobs = json::array({
        job("0001", "brute", "full", 256, "a", 20, 19, 21, 0.0, 0.0),
        job("0002", "tiled", "full", 256, "a", 6, 5.8, 6.2, 0.010, 0.02),
        job("0003", "clustered", "full", 256, "a", 8, 7.9, 8.1, 0.010, 0.02),
        job("0004", "inferred", "full", 256, "a", 5, 4.9, 5.1, 0.060, 0.8),
        job("0005", "brute", "full", 1024, "a", 70, 69, 71, 0.0, 0.0),
        job("0006", "tiled", "full", 1024, "a", 10, 9, 11, 0.010, 0.02),
        job("0007", "clustered", "full", 1024, "a", 10.2, 9.5, 10.5, 0.012, 0.02),
        job("0008", "inferred", "full", 1024, "a", 7, 6.9, 7.1, 0.070, 0.9),
        job("0009", "brute", "full", 256, "b", 21, 20, 22, 0.0, 0.0),
        job("0010", "tiled", "full", 256, "b", 7, 6.9, 7.1, 0.011, 0.02),
        job("0011", "clustered", "full", 256, "b", 6.5, 6.4, 6.6, 0.011, 0.02),
        job("0012", "inferred", "full", 256, "b", 5, 4.9, 5.1, 0.055, 0.7),
    });
    return {{"axis_columns", {"scene", "stage", "lights", "layout", "view", "width", "height"}},
            {"jobs", jobs}};
}

const json& groupWith(const json& advice, int lights, const std::string& view) {
    for (const json& group : advice["groups"])
        if (group["fixed"]["lights"] == lights && group["fixed"]["view"] == view)
            return group;
    throw std::runtime_error("no group");
}

TEST(Advisor, FastestWithinTheErrorBudgetAndLeastErrorWithinTheTimeBudget) {
    experiments::AdviceCriteria criteria;
    criteria.budgetMs = 16;
    criteria.maxFlip = 0.05;
    const json advice = experiments::adviseOnResults(results(), criteria);
    ASSERT_EQ(advice["groups"].size(), 3u);
    EXPECT_EQ(advice["error_metric"], "flip");

    const json& g = groupWith(advice, 256, "a");
    // inferred (5 ms) is over the error budget, so tiled (6 ms) is the fastest that fits; its
    // range does not overlap clustered's, so the answer is distinguishable, 8/6 = 1.33x.
    EXPECT_EQ(g["fastest"]["best"]["method"], "tiled");
    EXPECT_TRUE(g["fastest"]["distinguishable"].get<bool>());
    EXPECT_EQ(g["fastest"]["runner_up"]["method"], "clustered");
    EXPECT_NEAR(g["fastest"]["margin"].get<double>(), 8.0 / 6.0, 1e-12);
    // Within 16 ms, brute (20 ms) is out: tiled and clustered tie at flip 0.010 exactly, and the
    // answer says so rather than picking one silently.
    EXPECT_EQ(g["least_error"]["best"]["method"], "tiled");
    EXPECT_FALSE(g["least_error"]["distinguishable"].get<bool>());
    ASSERT_EQ(g["least_error"]["tied"].size(), 1u);
    EXPECT_EQ(g["least_error"]["tied"][0]["method"], "clustered");
    // Pareto: inferred (5, 0.06), tiled (6, 0.01), brute (20, 0); clustered is dominated.
    ASSERT_EQ(g["pareto"].size(), 3u);
    EXPECT_EQ(g["pareto"][0]["method"], "inferred");
    EXPECT_EQ(g["pareto"][1]["method"], "tiled");
    EXPECT_EQ(g["pareto"][2]["method"], "brute");

    // At 1024 lights tiled (9-11) and clustered (9.5-10.5) overlap: indistinguishable in time.
    const json& g1024 = groupWith(advice, 1024, "a");
    EXPECT_EQ(g1024["fastest"]["best"]["method"], "tiled");
    EXPECT_FALSE(g1024["fastest"]["distinguishable"].get<bool>());
    EXPECT_EQ(g1024["fastest"]["tied"][0]["method"], "clustered");

    // Across the two views at 256 lights: tiled wins view a, clustered view b.
    ASSERT_EQ(advice["families"].size(), 1u);
    const json& family = advice["families"][0];
    EXPECT_EQ(family["views"].size(), 2u);
    EXPECT_EQ(family["fastest_wins"]["tiled"], 1);
    EXPECT_EQ(family["fastest_wins"]["clustered"], 1);

    const std::string text = experiments::adviceText(advice);
    EXPECT_NE(text.find("INDISTINGUISHABLE"), std::string::npos) << text;
    EXPECT_NE(text.find("tiled"), std::string::npos) << text;
}

TEST(Advisor, SaysWhyWhenNothingFits) {
    experiments::AdviceCriteria criteria;
    criteria.budgetMs = 4; // faster than every method
    criteria.maxFlip = 0.001;
    const json advice = experiments::adviseOnResults(results(), criteria);
    const json& g = groupWith(advice, 256, "a");
    // Only brute (flip 0) is within 0.001: it is the fastest that fits.
    EXPECT_EQ(g["fastest"]["best"]["method"], "brute");
    EXPECT_TRUE(g["least_error"]["best"].is_null());
    EXPECT_NE(g["least_error"]["why_none"].get<std::string>().find("inferred"), std::string::npos);
}

TEST(Advisor, RelativeRmseBudgetAndGroupFilter) {
    experiments::AdviceCriteria criteria;
    criteria.budgetMs = 16;
    criteria.maxRelativeRmse = 0.75; // inferred at 256 lights view b (0.7) fits, view a does not
    criteria.groupFilters = {{"view", "b"}};
    const json advice = experiments::adviseOnResults(results(), criteria);
    ASSERT_EQ(advice["groups"].size(), 1u);
    EXPECT_EQ(advice["error_metric"], "relative_rmse");
    EXPECT_EQ(advice["groups"][0]["fastest"]["best"]["method"], "inferred");
}

TEST(Advisor, FailedJobsAreExcludedWithTheirReason) {
    json r = results();
    r["jobs"][1]["status"] = "failed";
    r["jobs"][1]["error"] = "out of memory";
    experiments::AdviceCriteria criteria;
    criteria.budgetMs = 16;
    criteria.maxFlip = 0.05;
    const json advice = experiments::adviseOnResults(r, criteria);
    const json& g = groupWith(advice, 256, "a");
    EXPECT_EQ(g["fastest"]["best"]["method"], "clustered");
    ASSERT_EQ(g["excluded"].size(), 1u);
    EXPECT_NE(g["excluded"][0]["reason"].get<std::string>().find("out of memory"),
              std::string::npos);
}

TEST(Advisor, RefusesBadCriteria) {
    experiments::AdviceCriteria criteria;
    criteria.budgetMs = 0;
    EXPECT_THROW(experiments::adviseOnResults(results(), criteria), std::invalid_argument);
    criteria.budgetMs = 16;
    criteria.maxFlip = 0.1;
    criteria.maxRelativeRmse = 0.1;
    EXPECT_THROW(experiments::adviseOnResults(results(), criteria), std::invalid_argument);
    criteria.maxRelativeRmse.reset();
    criteria.groupFilters = {{"no-such-setting", "1"}};
    EXPECT_THROW(experiments::adviseOnResults(results(), criteria), std::invalid_argument);
}

TEST(Advisor, CommandWritesAdviceJson) {
    const std::filesystem::path dir = experiments::test_files::freshTestFolder();
    json r = results();
    r["sweep"] = json::object();
    r["sweep_file"] = "hand-made";
    r["quick"] = false;
    r["columns"] = json::array();
    std::ofstream(dir / "results.json") << r.dump();
    experiments::AdviseCommandOptions options;
    options.dir = dir;
    options.criteria.budgetMs = 16;
    options.criteria.maxFlip = 0.05;
    ASSERT_EQ(experiments::runAdviseCommand(options), 0);
    std::ifstream file(dir / "advice.json");
    const json advice = json::parse(file);
    EXPECT_EQ(advice["groups"].size(), 3u);
}

} // namespace
