// The sweep runner in process on tiny real sweeps (spheres at 160x90, a few lights): every job
// runs once, one reference per key (rendered, then read back bit-exact from DIR/references),
// finished jobs are skipped, failing jobs are recorded and retried, invalid sweeps run nothing,
// and two shards merged give the same table as one unsharded run.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "experiments/sweep/ResultsTable.h"
#include "experiments/sweep/SweepFile.h"
#include "experiments/sweep/SweepRunner.h"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

fs::path testDir(const std::string& name) {
    const fs::path dir =
        fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / ("sweep-runner-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// 2 light counts x 3 stages = 6 jobs, 2 reference keys.
Json tinySweep() {
    return Json::parse(R"({
        "name": "tiny",
        "fixed": {"scene": "spheres", "resolution": "160x90", "seed": 5, "threads": 2},
        "axes": {"lights": [4, 12], "stage": ["brute", "tiled:tile=8", "deferred"]},
        "repetitions": 2
    })");
}

fs::path writeSweep(const fs::path& dir, const Json& sweep) {
    const fs::path file = dir / "sweep.json";
    std::ofstream(file) << sweep.dump(2);
    return file;
}

experiments::SweepSummary run(const fs::path& file, const fs::path& out, int shard = 1,
                              int shards = 1) {
    experiments::SweepOptions options;
    options.file = file;
    options.out = out;
    options.shardIndex = shard;
    options.shardCount = shards;
    std::ostringstream log;
    return experiments::runSweep(options, log);
}

TEST(SweepRunner, RunsEachJobOnceAndSharesReferences) {
    const fs::path dir = testDir("basic");
    const fs::path file = writeSweep(dir, tinySweep());
    const auto first = run(file, dir / "out");
    EXPECT_EQ(first.jobsInSweep, 6u);
    EXPECT_EQ(first.ran, 6u);
    EXPECT_EQ(first.failed, 0u);
    EXPECT_EQ(first.referencesRendered, 2u);
    EXPECT_EQ(first.referencesLoaded, 0u);
    size_t referenceFiles = 0;
    for (const auto& entry : fs::directory_iterator(dir / "out" / "references"))
        referenceFiles += entry.path().extension() == ".exr";
    EXPECT_EQ(referenceFiles, 2u);

    const Json results = experiments::readResults(dir / "out");
    ASSERT_EQ(results["jobs"].size(), 6u);
    EXPECT_EQ(results["sweep"], tinySweep());
    EXPECT_EQ(results["quick"], false);
    for (const Json& job : results["jobs"]) {
        EXPECT_EQ(job["status"], "ok") << job.dump();
        EXPECT_TRUE(job["time_total_median_ms"].is_number()) << job.dump();
        EXPECT_LE(job["time_total_min_ms"].get<double>(), job["time_total_max_ms"].get<double>());
        EXPECT_TRUE(job["rmse"].is_number()) << job.dump();
        EXPECT_TRUE(job["bytes_per_pixel"].is_number()) << job.dump();
        EXPECT_GE(job["light_evaluations"].get<double>(),
                  job["oracle_light_evaluations"].get<double>());
        EXPECT_EQ(job["repetitions"], 2);
        const fs::path folder = dir / "out" / "jobs" / job["job_id"].get<std::string>();
        for (const char* name :
             {"render.exr", "preview.png", "heatmap.png", "stats.json", "done.json"})
            EXPECT_TRUE(fs::is_regular_file(folder / name)) << folder / name;
        // One RunMetrics behind both files: the row's figures are the job's stats.json figures,
        // by the same names.
        std::ifstream statsFile(folder / "stats.json");
        const Json stats = Json::parse(statsFile);
        for (const char* figure :
             {"light_evaluations", "oracle_light_evaluations", "culling_efficiency",
              "counted_pixels", "bytes_per_pixel", "simt_lane_slots", "simt_efficiency"})
            EXPECT_EQ(job[figure], stats[figure]) << figure;
        for (const char* figure : {"rmse", "relative_rmse", "max_abs", "relative_mean", "p99_abs",
                                   "flip", "flip_unavailable"})
            EXPECT_EQ(job[figure], stats["error"][figure]) << figure;
        // ꟻLIP is in every row: a number, or null with the reason it is unavailable.
        EXPECT_TRUE(job["flip"].is_number() != !job["flip_unavailable"].get<std::string>().empty())
            << job.dump();
        for (const char* pass : {"gbuffer", "total"})
            EXPECT_EQ(job[std::string("time_") + pass + "_median_ms"], stats["timings_ms"][pass])
                << pass;
        // Memory and coverage as stats.json has them: the estimate the job was checked against,
        // a measured peak (the job's render, after its reference), the covered fraction.
        EXPECT_EQ(job["memory_estimate_bytes"], stats["memory"]["estimate_bytes"]);
        ASSERT_TRUE(job["peak_rss_bytes"].is_number()) << job.dump();
        EXPECT_GT(job["peak_rss_bytes"].get<double>(), 1e6);
        EXPECT_LE(job["peak_rss_bytes"].get<double>(),
                  stats["memory"]["measured_peak_rss_bytes"].get<double>());
        const double covered = stats["coverage"]["covered_pixels"].get<double>() /
                               stats["coverage"]["pixels"].get<double>();
        EXPECT_DOUBLE_EQ(job["covered_fraction"].get<double>(), covered);
        EXPECT_GT(covered, 0.0);
    }
    std::ifstream csv(dir / "out" / "results.csv");
    size_t lines = 0;
    for (std::string line; std::getline(csv, line);)
        ++lines;
    EXPECT_EQ(lines, 7u);

    // Everything finished: a rerun runs and renders nothing.
    const auto again = run(file, dir / "out");
    EXPECT_EQ(again.ran, 0u);
    EXPECT_EQ(again.skipped, 6u);
    EXPECT_EQ(again.referencesRendered + again.referencesLoaded, 0u);

    // One job unfinished: rerun with the reference read back from disk, bit-exact (same error).
    const Json victim = results["jobs"][3];
    fs::remove(dir / "out" / "jobs" / victim["job_id"].get<std::string>() / "done.json");
    const auto resumed = run(file, dir / "out");
    EXPECT_EQ(resumed.ran, 1u);
    EXPECT_EQ(resumed.referencesRendered, 0u);
    EXPECT_EQ(resumed.referencesLoaded, 1u);
    const Json redone = experiments::readResults(dir / "out")["jobs"][3];
    EXPECT_EQ(redone["job_id"], victim["job_id"]);
    for (const char* metric :
         {"rmse", "max_abs", "p99_abs", "light_evaluations", "oracle_light_evaluations"})
        EXPECT_EQ(redone[metric], victim[metric]) << metric;
}

// A job that fails while it runs (here: its reference cannot be cached, a folder is where the
// reference EXR goes) is recorded as failed and the sweep goes on; a rerun retries it.
TEST(SweepRunner, FailingJobIsRecordedAndTheSweepGoesOn) {
    const fs::path dir = testDir("failing");
    Json sweep = tinySweep();
    sweep["axes"] = Json::object();
    sweep["axes"]["scene"] = Json::array({"spheres", "wall"});
    sweep["fixed"]["stage"] = "brute";
    sweep["fixed"]["lights"] = 4;
    sweep["fixed"].erase("scene");
    const fs::path file = writeSweep(dir, sweep);
    const std::vector<experiments::SweepJob> jobs =
        experiments::expandSweep(experiments::readSweepFile(file)).jobs();
    ASSERT_EQ(jobs.size(), 2u);
    const fs::path blocker = dir / "out" / "references" / (jobs[1].referenceKey + ".exr");
    fs::create_directories(blocker);
    const auto summary = run(file, dir / "out");
    EXPECT_EQ(summary.ran, 2u);
    EXPECT_EQ(summary.failed, 1u);
    const Json results = experiments::readResults(dir / "out");
    ASSERT_EQ(results["jobs"].size(), 2u);
    EXPECT_EQ(results["jobs"][0]["status"], "ok");
    EXPECT_EQ(results["jobs"][1]["status"], "failed");
    EXPECT_NE(results["jobs"][1]["error"].get<std::string>().find(jobs[1].referenceKey),
              std::string::npos)
        << results["jobs"][1]["error"];
    EXPECT_TRUE(results["jobs"][1]["time_total_median_ms"].is_null());

    experiments::SweepOptions options;
    options.file = file;
    options.out = dir / "out";
    EXPECT_EQ(experiments::runSweepCommand(options), 1) << "a failed job must fail the command";
    fs::remove_all(blocker);
    const auto retried = run(file, dir / "out"); // the failed job is retried, the ok one skipped
    EXPECT_EQ(retried.skipped, 1u);
    EXPECT_EQ(retried.ran, 1u);
    EXPECT_EQ(retried.failed, 0u);
}

// A scene file that cannot be loaded is found before any job runs (issue 32, class 4), with the
// job, the file and the reason; the output folder is not created.
TEST(SweepRunner, ABrokenSceneIsRefusedBeforeAnyJobRuns) {
    const fs::path dir = testDir("broken-scene");
    std::ofstream(dir / "broken.json") << "{ this is not a scene";
    Json sweep = tinySweep();
    sweep["axes"] = Json::object();
    sweep["axes"]["scene"] = Json::array({"spheres", (dir / "broken.json").string()});
    sweep["fixed"]["stage"] = "brute";
    sweep["fixed"]["lights"] = 4;
    sweep["fixed"].erase("scene");
    const fs::path file = writeSweep(dir, sweep);
    try {
        run(file, dir / "out");
        FAIL() << "a sweep with a broken scene ran";
    } catch (const experiments::SweepError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("1 of 2 jobs cannot run; nothing was run"), std::string::npos)
            << message;
        EXPECT_NE(message.find("broken.json: invalid JSON"), std::string::npos) << message;
    }
    EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(SweepRunner, InvalidSweepRunsNothing) {
    const fs::path dir = testDir("invalid");
    Json sweep = tinySweep();
    sweep["axes"]["stage"] = Json::array({"brute", "no-such-stage"});
    const fs::path file = writeSweep(dir, sweep);
    try {
        run(file, dir / "out");
        FAIL() << "an invalid sweep ran";
    } catch (const experiments::SweepError& e) {
        EXPECT_NE(std::string(e.what()).find("2 of 4 jobs are invalid"), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "out"));
    experiments::SweepOptions options;
    options.file = file;
    options.out = dir / "out";
    EXPECT_EQ(experiments::runSweepCommand(options), 2);
}

TEST(SweepRunner, TwoShardsMergedEqualOneRun) {
    const fs::path dir = testDir("shards");
    const fs::path file = writeSweep(dir, tinySweep());
    run(file, dir / "all");
    const auto a = run(file, dir / "shard1", 1, 2);
    const auto b = run(file, dir / "shard2", 2, 2);
    EXPECT_EQ(a.ran + b.ran, 6u);
    EXPECT_GT(a.ran, 0u);
    EXPECT_GT(b.ran, 0u);
    EXPECT_EQ(experiments::mergeSweepOutputs({dir / "shard1", dir / "shard2"}, dir / "merged"), 6u);

    const Json one = experiments::readResults(dir / "all");
    const Json merged = experiments::readResults(dir / "merged");
    EXPECT_EQ(merged["columns"], one["columns"]);
    EXPECT_EQ(merged["sweep"], one["sweep"]);
    ASSERT_EQ(merged["jobs"].size(), one["jobs"].size());
    for (size_t i = 0; i < one["jobs"].size(); ++i)
        for (const auto& [column, value] : one["jobs"][i].items()) {
            if (column.rfind("time_", 0) == 0 || column == "peak_rss_bytes")
                continue; // timings and the measured peak differ from run to run
            EXPECT_EQ(merged["jobs"][i][column], value)
                << one["jobs"][i]["job_id"] << " " << column;
        }
    for (const Json& job : merged["jobs"])
        EXPECT_TRUE(fs::is_regular_file(dir / "merged" / "jobs" / job["job_id"].get<std::string>() /
                                        "render.exr"));
}

} // namespace
