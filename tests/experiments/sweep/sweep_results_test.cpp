// Results tables: column order, CSV quoting, and merging shard outputs (union, refusal of
// conflicting duplicates and of outputs of different sweeps), on synthetic rows.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "experiments/output/AtomicFile.h"
#include "experiments/sweep/ResultsTable.h"
#include "experiments/sweep/SweepFile.h"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

fs::path testDir(const std::string& name) {
    const fs::path dir =
        fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / ("sweep-results-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

Json row(const std::string& id, const std::string& stage, double shading) {
    Json r = Json::object();
    r["job_id"] = id;
    r["status"] = "ok";
    r["error"] = "";
    r["stage"] = stage;
    r["repetitions"] = 1;
    r["warmup"] = 0;
    r["time_total_median_ms"] = shading + 1.0;
    r["time_shading_median_ms"] = shading;
    r["time_gbuffer_median_ms"] = 1.0;
    r["rmse"] = 0.0;
    return r;
}

const std::vector<std::string> kAxis = {"stage", "repetitions", "warmup"};

// A fake sweep output: results.json plus one job folder with a marker and a file per row.
void writeOutput(const fs::path& dir, const Json& sweep, const std::vector<Json>& rows) {
    fs::create_directories(dir);
    for (const Json& r : rows) {
        const fs::path job = dir / "jobs" / r["job_id"].get<std::string>();
        fs::create_directories(job);
        experiments::writeTextAtomically(job / "stats.json",
                                         "{\"stage\": " + r["stage"].dump() + "}\n");
        Json marker = {{"job_id", r["job_id"]}, {"status", r["status"]}, {"row", r}};
        experiments::writeTextAtomically(job / experiments::kDoneMarker, marker.dump());
    }
    experiments::writeResults(dir, experiments::resultsJson(sweep, "s.json", false, kAxis, rows));
}

TEST(ResultsTable, ColumnsInPipelineOrderAndNullForMissing) {
    Json withAssign = row("0001-bbbbbbbb", "clustered", 2.0);
    withAssign["time_assign_median_ms"] = 0.5;
    withAssign["time_zzz_median_ms"] = 0.1;
    const Json results = experiments::resultsJson(Json::object(), "s.json", true, kAxis,
                                                  {withAssign, row("0000-aaaaaaaa", "brute", 3.0)});
    std::vector<std::string> columns = results["columns"].get<std::vector<std::string>>();
    auto at = [&](const std::string& name) {
        return std::find(columns.begin(), columns.end(), name) - columns.begin();
    };
    EXPECT_EQ(columns[0], "job_id");
    EXPECT_EQ(columns[3], "stage");
    EXPECT_LT(at("time_gbuffer_median_ms"), at("time_assign_median_ms"));
    EXPECT_LT(at("time_assign_median_ms"), at("time_shading_median_ms"));
    EXPECT_LT(at("time_shading_median_ms"), at("time_zzz_median_ms"));
    EXPECT_LT(at("time_zzz_median_ms"), at("time_total_median_ms"));
    EXPECT_EQ(at("time_total_max_ms"), at("time_total_median_ms") + 2);
    EXPECT_LT(at("time_total_max_ms"), at("light_evaluations"));
    EXPECT_LT(at("p99_abs"), long(columns.size()));
    // Sorted by job id; missing values are null and every row has every column.
    ASSERT_EQ(results["jobs"].size(), 2u);
    EXPECT_EQ(results["jobs"][0]["job_id"], "0000-aaaaaaaa");
    EXPECT_TRUE(results["jobs"][0]["time_assign_median_ms"].is_null());
    for (const Json& job : results["jobs"])
        EXPECT_EQ(job.size(), columns.size());
}

TEST(ResultsTable, CsvQuotesAndEmptiesNulls) {
    Json failed = row("0000-aaaaaaaa", "tiled:tile=8,vfc=0", 1.0);
    failed["status"] = "failed";
    failed["error"] = "said \"no\"\nthen stopped";
    failed["rmse"] = nullptr;
    const Json results = experiments::resultsJson(Json::object(), "s.json", false, kAxis, {failed});
    const std::string csv = experiments::resultsCsv(results);
    const std::string header = csv.substr(0, csv.find('\n'));
    EXPECT_EQ(
        header.rfind("job_id,status,error,stage,repetitions,warmup,time_gbuffer_median_ms", 0), 0u)
        << header;
    EXPECT_NE(
        csv.find(
            "0000-aaaaaaaa,failed,\"said \"\"no\"\"\nthen stopped\",\"tiled:tile=8,vfc=0\",1,0,"),
        std::string::npos)
        << csv;
    // rmse column empty: the column before psnr (also empty), then max_abs... all empty here.
    EXPECT_NE(csv.find(",,,,,,,,,,\n"), std::string::npos) << csv;
}

TEST(ResultsTable, MergeTakesTheUnionOfShards) {
    const fs::path dir = testDir("merge");
    const Json sweep = {{"name", "m"}};
    writeOutput(dir / "a", sweep,
                {row("0000-aaaaaaaa", "brute", 3.0), row("0002-cccccccc", "tiled", 1.0)});
    writeOutput(dir / "b", sweep,
                {row("0001-bbbbbbbb", "deferred", 2.0), row("0002-cccccccc", "tiled", 1.0)});
    EXPECT_EQ(experiments::mergeSweepOutputs({dir / "a", dir / "b"}, dir / "out"), 3u);
    const Json merged = experiments::readResults(dir / "out");
    ASSERT_EQ(merged["jobs"].size(), 3u);
    EXPECT_EQ(merged["jobs"][1]["job_id"], "0001-bbbbbbbb");
    EXPECT_EQ(merged["sweep"], sweep);
    for (const char* id : {"0000-aaaaaaaa", "0001-bbbbbbbb", "0002-cccccccc"}) {
        EXPECT_TRUE(fs::is_regular_file(dir / "out" / "jobs" / id / "stats.json")) << id;
        EXPECT_TRUE(fs::is_regular_file(dir / "out" / "jobs" / id / experiments::kDoneMarker))
            << id;
    }
    EXPECT_TRUE(fs::is_regular_file(dir / "out" / "results.csv"));
    // Merging into one of the inputs works too.
    EXPECT_EQ(experiments::mergeSweepOutputs({dir / "a", dir / "b"}, dir / "a"), 3u);
    EXPECT_EQ(experiments::readResults(dir / "a")["jobs"].size(), 3u);
}

TEST(ResultsTable, MergeRefusesConflictsAndForeignSweeps) {
    const fs::path dir = testDir("conflict");
    writeOutput(dir / "a", {{"name", "m"}}, {row("0000-aaaaaaaa", "brute", 3.0)});
    writeOutput(dir / "b", {{"name", "m"}}, {row("0000-aaaaaaaa", "brute", 3.5)});
    writeOutput(dir / "c", {{"name", "other"}}, {row("0001-bbbbbbbb", "brute", 3.0)});
    try {
        experiments::mergeSweepOutputs({dir / "a", dir / "b"}, dir / "out");
        FAIL() << "conflicting duplicate accepted";
    } catch (const experiments::SweepError& e) {
        EXPECT_NE(std::string(e.what()).find("0000-aaaaaaaa"), std::string::npos) << e.what();
    }
    try {
        experiments::mergeSweepOutputs({dir / "a", dir / "c"}, dir / "out");
        FAIL() << "outputs of different sweeps merged";
    } catch (const experiments::SweepError& e) {
        EXPECT_NE(std::string(e.what()).find("sweep"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "out" / "results.json"));
    EXPECT_THROW(experiments::mergeSweepOutputs({dir / "missing"}, dir / "out"),
                 experiments::SweepError);
}

} // namespace
