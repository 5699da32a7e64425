// Tests for experiments/ReportCommand: the matching of published figures (known numbers give known
// medians and ratios), and `testbed report` on a hand-made results folder that follows the sweep
// runner's format (failed job, null metrics, "inf" PSNR, a missing error image, single-valued
// axes). Folders are left under <build>/test-output/experiments/ for inspection.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "experiments/advise/Advisor.h"
#include "experiments/output/ImageOutput.h"
#include "experiments/report/ReportCommand.h"
#include "tests/experiments/TestFolders.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using experiments::test_files::freshTestFolder;
using experiments::test_files::readText;

json okJob(const std::string& id, const std::string& stage, int lights, json time) {
    return {{"job_id", id},
            {"status", "ok"},
            {"error", ""},
            {"stage", stage},
            {"lights", lights},
            {"time_total_median_ms", time},
            {"time_shading_median_ms", 1.0}};
}

TEST(ReportSelect, NumbersCompareByValueWhateverTheirSpelling) {
    EXPECT_EQ(normalisedSelectValue(1500), "1500");
    EXPECT_EQ(normalisedSelectValue("1500"), "1500");
    EXPECT_EQ(normalisedSelectValue(1500.0), "1500");
    EXPECT_EQ(normalisedSelectValue("1500.0"), "1500");
    EXPECT_EQ(normalisedSelectValue(0.25), "0.25");
    EXPECT_EQ(normalisedSelectValue("0.25"), "0.25");
    EXPECT_EQ(normalisedSelectValue("deferred:vfc=1"), "deferred:vfc=1");
    EXPECT_EQ(normalisedSelectValue("24x12x16"), "24x12x16");
    EXPECT_EQ(normalisedSelectValue(true), "true");
    const json job = {{"lights", 1500}, {"stage", "tiled"}, {"scene-option.behind", "0"}};
    EXPECT_TRUE(jobMatchesSelect(job, {{"lights", "1500"}, {"scene-option.behind", 0}}));
    EXPECT_FALSE(jobMatchesSelect(job, {{"lights", 1600}}));
    EXPECT_FALSE(jobMatchesSelect(job, {{"threads", 2}})) << "a key the job lacks never matches";
    EXPECT_TRUE(jobMatchesSelect(job, json::object()));
}

TEST(ReportSelect, MetricListsAreSummedAndMissingValuesGiveNothing) {
    const json job = {{"a", 2.0}, {"b", 3.5}, {"c", nullptr}, {"d", "inf"}};
    EXPECT_EQ(jobMetric(job, "a"), 2.0);
    EXPECT_EQ(jobMetric(job, json::array({"a", "b"})), 5.5);
    EXPECT_FALSE(jobMetric(job, "c").has_value());
    EXPECT_FALSE(jobMetric(job, "d").has_value());
    EXPECT_FALSE(jobMetric(job, json::array({"a", "missing"})).has_value());
    EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
    EXPECT_EQ(median({4.0, 1.0, 2.0, 3.0}), 2.5);
    EXPECT_FALSE(median({}).has_value());
}

TEST(ReportPublished, KnownNumbersGiveKnownMediansAndRatios) {
    const json jobs = json::array({
        okJob("0", "deferred", 1500, 10.0),
        okJob("1", "deferred", 1500, 14.0), // two matches: median 12
        okJob("2", "tiled", 1500, 3.0),
        {{"job_id", "3"},
         {"status", "failed"},
         {"error", "boom"},
         {"stage", "tiled"},
         {"lights", 1500},
         {"time_total_median_ms", 1000.0}}, // failed: never counted
        okJob("4", "deferred", 2000, 40.0),
        okJob("5", "tiled", 2000, nullptr), // matches, but its metric is missing
    });
    const json published = {
        {"title", "T"},
        {"source", "S"},
        {"metric", "time_total_median_ms"},
        {"columns",
         {{{"label", "deferred"}, {"select", {{"stage", "deferred"}}}},
          {{"label", "tiled"}, {"select", {{"stage", "tiled"}}}}}},
        {"rows",
         {{{"label", "Test 1"}, {"select", {{"lights", "1500"}}}, {"values", {30.0, 15.0}}},
          {{"label", "Test 2"}, {"select", {{"lights", 2000.0}}}, {"values", {60.0, nullptr}}},
          {{"label", "Test 3"}, {"select", {{"lights", 9999}}}, {"values", {1.0, 2.0}}}}},
        {"ratio_to", 0},
        {"finding", "F"}};
    const json table = comparePublished(published, jobs);
    EXPECT_EQ(table["columns"], json::array({"deferred", "tiled"}));
    EXPECT_EQ(table["finding"], "F");
    const json& test1 = table["rows"][0]["cells"];
    EXPECT_DOUBLE_EQ(test1[0]["published"].get<double>(), 30.0);
    EXPECT_DOUBLE_EQ(test1[0]["measured"].get<double>(), 12.0);
    EXPECT_EQ(test1[0]["matched_jobs"], 2);
    EXPECT_DOUBLE_EQ(test1[0]["published_ratio"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(test1[0]["measured_ratio"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(test1[1]["measured"].get<double>(), 3.0);
    EXPECT_EQ(test1[1]["matched_jobs"], 1) << "the failed job does not count";
    EXPECT_DOUBLE_EQ(test1[1]["published_ratio"].get<double>(), 0.5);
    EXPECT_DOUBLE_EQ(test1[1]["measured_ratio"].get<double>(), 0.25);
    const json& test2 = table["rows"][1]["cells"];
    EXPECT_DOUBLE_EQ(test2[0]["measured"].get<double>(), 40.0);
    EXPECT_TRUE(test2[1]["published"].is_null());
    EXPECT_TRUE(test2[1]["published_ratio"].is_null());
    EXPECT_TRUE(test2[1]["measured"].is_null()) << "matched, but no metric";
    EXPECT_EQ(test2[1]["matched_jobs"], 1);
    const json& test3 = table["rows"][2]["cells"];
    EXPECT_TRUE(test3[0]["measured"].is_null());
    EXPECT_TRUE(test3[1]["measured_ratio"].is_null());
    EXPECT_DOUBLE_EQ(test3[1]["published_ratio"].get<double>(), 2.0);
}

TEST(ReportPublished, ModelledColumnGivesMediansAndRatiosOfTheSameJobs) {
    json jobs = json::array({okJob("0", "a", 10, 4.0), okJob("1", "a", 10, 6.0),
                             okJob("2", "b", 10, 2.0), okJob("3", "b", 10, 2.0)});
    const double slots[] = {100.0, 300.0, 50.0, 70.0};
    for (size_t j = 0; j < jobs.size(); ++j)
        jobs[j]["simt_lane_slots"] = slots[j];
    json published = {{"title", "model"},
                      {"metric", "time_total_median_ms"},
                      {"modelled", "simt_lane_slots"},
                      {"columns",
                       {{{"label", "a"}, {"select", {{"stage", "a"}}}},
                        {{"label", "b"}, {"select", {{"stage", "b"}}}}}},
                      {"rows", {{{"label", "r"}, {"values", {8.0, 2.0}}}}}};
    const json table = comparePublished(published, jobs);
    EXPECT_EQ(table["modelled"], "simt_lane_slots");
    const json& cells = table["rows"][0]["cells"];
    EXPECT_DOUBLE_EQ(cells[0]["modelled"].get<double>(), 200.0);
    EXPECT_DOUBLE_EQ(cells[1]["modelled"].get<double>(), 60.0);
    EXPECT_DOUBLE_EQ(cells[1]["modelled_ratio"].get<double>(), 0.3);
    EXPECT_DOUBLE_EQ(cells[1]["measured_ratio"].get<double>(), 0.4);
    EXPECT_DOUBLE_EQ(cells[1]["published_ratio"].get<double>(), 0.25);
    // Without a model the cells say so with nulls; a model that is not a column name is refused.
    published.erase("modelled");
    EXPECT_TRUE(
        comparePublished(published, jobs)["rows"][0]["cells"][1]["modelled_ratio"].is_null());
    published["modelled"] = 3;
    EXPECT_THROW(comparePublished(published, jobs), std::runtime_error);
}

TEST(ReportPublished, SummedMetricAndAnotherBaseline) {
    json jobs = json::array({okJob("0", "a", 10, 4.0), okJob("1", "b", 10, 7.0)});
    const json published = {{"title", "sum"},
                            {"metric", {"time_total_median_ms", "time_shading_median_ms"}},
                            {"columns",
                             {{{"label", "a"}, {"select", {{"stage", "a"}}}},
                              {{"label", "b"}, {"select", {{"stage", "b"}}}}}},
                            {"rows", {{{"label", "r"}, {"values", {2.0, 4.0}}}}},
                            {"ratio_to", 1}};
    const json table = comparePublished(published, jobs);
    EXPECT_EQ(table["metric_label"], "time_total_median_ms + time_shading_median_ms");
    const json& cells = table["rows"][0]["cells"];
    EXPECT_DOUBLE_EQ(cells[0]["measured"].get<double>(), 5.0);
    EXPECT_DOUBLE_EQ(cells[1]["measured"].get<double>(), 8.0);
    EXPECT_DOUBLE_EQ(cells[0]["measured_ratio"].get<double>(), 5.0 / 8.0);
    EXPECT_DOUBLE_EQ(cells[0]["published_ratio"].get<double>(), 0.5);
    EXPECT_DOUBLE_EQ(cells[1]["published_ratio"].get<double>(), 1.0);
}

TEST(ReportPublished, MalformedEntriesAreRefusedByName) {
    const json columns = {{{"label", "a"}, {"select", json::object()}}};
    auto messageOf = [](const json& entry) {
        try {
            comparePublished(entry, json::array());
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(messageOf({{"title", "X"},
                         {"metric", "m"},
                         {"columns", columns},
                         {"rows", {{{"label", "r"}, {"values", {1.0, 2.0}}}}}})
                  .find("published entry 'X': rows[0].values must have one entry per column"),
              std::string::npos);
    EXPECT_NE(messageOf({{"title", "X"},
                         {"metric", "m"},
                         {"columns", columns},
                         {"rows", json::array()},
                         {"ratio_to", 3}})
                  .find("ratio_to"),
              std::string::npos);
    EXPECT_NE(
        messageOf({{"title", "X"}, {"columns", columns}, {"rows", json::array()}}).find("metric"),
        std::string::npos);
}

// A results folder in the sweep runner's format: six ok jobs (two stages x three light counts,
// so three comparable groups of two) with tiny images, one failed job without a folder; job 0005
// lacks error.png. Jobs 0000-0003 also have a render.exr whose lights.evaluated peak at
// 8 * (ordinal + 1) and whose error peaks at 0.01 * (ordinal + 1), so that the report redraws
// their maps at their group's scale; ꟻLIP is unavailable (null, with a reason), as for images
// that could not be compared (withFlip below gives every ok job a known ꟻLIP).
fs::path writeResultsFolder(const fs::path& dir, bool singleJob) {
    const int w = 32, h = 18;
    std::vector<float> red(w * h), green(w * h), blue(w * h);
    std::vector<uint32_t> counts(w * h);
    json jobs = json::array();
    const std::vector<std::string> stages = {"brute", "tiled"};
    const std::vector<int> lightCounts =
        singleJob ? std::vector<int>{64} : std::vector<int>{16, 64, 256};
    int ordinal = 0;
    for (const std::string& stage : singleJob ? std::vector<std::string>{"tiled"} : stages)
        for (int lights : lightCounts) {
            char id[32];
            std::snprintf(id, sizeof id, "%04d-%s", ordinal, stage.c_str());
            const fs::path jobDir = dir / "jobs" / id;
            fs::create_directories(jobDir);
            for (int i = 0; i < w * h; ++i) {
                red[i] = float(i % w) / w;
                green[i] = float(i / w) / h * float(ordinal + 1) / 6.0f;
                blue[i] = 0.5f;
                counts[i] = uint32_t((i + ordinal) % 9);
            }
            writePreviewPng(jobDir / "preview.png", w, h, red.data(), green.data(), blue.data());
            writeHeatmapPng(jobDir / "heatmap.png", w, h, counts.data(), 0);
            if (ordinal != 5)
                writePreviewPng(jobDir / "error.png", w, h, blue.data(), red.data(), green.data());
            if (ordinal < 4) {
                std::vector<float> evaluated(w * h), error(w * h);
                for (int i = 0; i < w * h; ++i) {
                    evaluated[i] = float((i % 9) * (ordinal + 1));
                    error[i] = 0.01f * float(ordinal + 1) * float(i % 5) / 4.0f;
                }
                writeMultiLayerExr(jobDir / "render.exr", w, h,
                                   {{"R", red.data()},
                                    {"G", green.data()},
                                    {"B", blue.data()},
                                    {"lights.evaluated", evaluated.data()},
                                    {"error.R", error.data()},
                                    {"error.G", error.data()},
                                    {"error.B", error.data()}},
                                   {});
            }
            const bool brute = stage == "brute";
            const double time = (brute ? 2.0 : 0.5) * lights + ordinal;
            jobs.push_back({{"job_id", id},
                            {"status", "ok"},
                            {"error", ""},
                            {"scene", "atrium"},
                            {"stage", stage},
                            {"lights", lights},
                            {"width", w},
                            {"height", h},
                            {"repetitions", 3},
                            {"time_total_median_ms", time},
                            {"time_total_min_ms", time * 0.9},
                            {"time_total_max_ms", time * 1.2},
                            {"light_evaluations", (brute ? 1.0 : 0.2) * lights * w * h},
                            {"culling_efficiency", brute ? 0.05 : 0.4 + 0.001 * lights},
                            {"simt_lane_slots", (brute ? 1.0 : 0.3) * lights * w * h},
                            {"simt_efficiency", brute ? 0.05 : 0.2},
                            {"counted_pixels", w * h},
                            {"bytes_per_pixel", 16},
                            {"rmse", brute ? 1e-7 * (ordinal + 1) : 2e-6 * (ordinal + 1)},
                            {"relative_rmse", brute ? 1e-6 * (ordinal + 1) : 2e-5 * (ordinal + 1)},
                            {"psnr", ordinal == 0 ? json("inf") : json(80.0 - ordinal)},
                            {"max_abs", ordinal == 1 ? json() : json(1e-5)},
                            {"flip", nullptr},
                            {"flip_unavailable", "flip-evaluator is not installed <here>"}});
            ++ordinal;
        }
    jobs.push_back({{"job_id", "9999-failed"},
                    {"status", "failed"},
                    {"error", "stage 'nope' <unknown>"},
                    {"scene", "atrium"},
                    {"stage", "nope"},
                    {"lights", 16},
                    {"width", w},
                    {"height", h},
                    {"repetitions", 3},
                    {"time_total_median_ms", nullptr},
                    {"time_total_min_ms", nullptr},
                    {"time_total_max_ms", nullptr},
                    {"light_evaluations", nullptr},
                    {"culling_efficiency", nullptr},
                    {"simt_lane_slots", nullptr},
                    {"simt_efficiency", nullptr},
                    {"counted_pixels", nullptr},
                    {"bytes_per_pixel", nullptr},
                    {"rmse", nullptr},
                    {"relative_rmse", nullptr},
                    {"psnr", nullptr},
                    {"max_abs", nullptr},
                    {"flip", nullptr},
                    {"flip_unavailable", nullptr}});
    const json columns = {"job_id",
                          "status",
                          "error",
                          "scene",
                          "stage",
                          "lights",
                          "width",
                          "height",
                          "repetitions",
                          "time_total_median_ms",
                          "time_total_min_ms",
                          "time_total_max_ms",
                          "light_evaluations",
                          "culling_efficiency",
                          "simt_lane_slots",
                          "simt_efficiency",
                          "counted_pixels",
                          "bytes_per_pixel",
                          "rmse",
                          "relative_rmse",
                          "psnr",
                          "max_abs",
                          "flip",
                          "flip_unavailable"};
    const json published = json::array(
        {{{"title", "Thesis-like table"},
          {"source", "made up"},
          {"metric", "time_total_median_ms"},
          {"modelled", "simt_lane_slots"},
          {"columns",
           {{{"label", "brute"}, {"select", {{"stage", "brute"}}}},
            {{"label", "tiled"}, {"select", {{"stage", "tiled"}}}}}},
          {"rows",
           {{{"label", "Test 64"}, {"select", {{"lights", 64}}}, {"values", {128.0, 32.0}}}}},
          {"ratio_to", 0},
          {"finding", "tiled wins <by far>"}}});
    const json results = {{"sweep", {{"name", "fixture"}, {"published", published}}},
                          {"sweep_file", "fixture.json"},
                          {"quick", false},
                          {"columns", columns},
                          {"jobs", jobs}};
    std::ofstream(dir / "results.json") << results.dump(1);
    return dir;
}

// A plot is not blank: it has many distinct colours and a sizeable non-white part.
void expectNotBlank(const fs::path& png) {
    OIIO::ImageBuf image(png.string());
    ASSERT_TRUE(image.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << png;
    const OIIO::ImageBufAlgo::PixelStats stats = OIIO::ImageBufAlgo::computePixelStats(image);
    EXPECT_GT(stats.stddev[0] + stats.stddev[1] + stats.stddev[2], 0.05) << png;
    OIIO::ImageBuf rgb = OIIO::ImageBufAlgo::channels(image, 3, {0, 1, 2});
    // Distinct colours: hash the quantised pixels.
    std::vector<float> pixels(size_t(rgb.spec().image_pixels()) * 3);
    rgb.get_pixels(rgb.roi(), OIIO::TypeDesc::FLOAT, pixels.data());
    std::set<uint32_t> colours;
    for (size_t i = 0; i < pixels.size(); i += 3)
        colours.insert(uint32_t(std::lround(pixels[i] * 255)) << 16 |
                       uint32_t(std::lround(pixels[i + 1] * 255)) << 8 |
                       uint32_t(std::lround(pixels[i + 2] * 255)));
    EXPECT_GT(colours.size(), 32u) << png;
}

TEST(ReportCommand, WritesThePageWithTablesPlotsAndThumbnails) {
    const fs::path dir = writeResultsFolder(freshTestFolder(), false);
    ReportCommandOptions options;
    options.dir = dir;
    ASSERT_EQ(runReportCommand(options), 0) << dir;
    const std::string html = readText(dir / "report.html");
    for (const char* id : {"0000-brute", "0001-brute", "0002-brute", "0003-tiled", "0004-tiled",
                           "0005-tiled", "9999-failed"})
        EXPECT_NE(html.find(std::string("<td class=\"text\">") + id + "</td>"), std::string::npos)
            << id;
    EXPECT_NE(html.find("<tr class=\"failed\">"), std::string::npos);
    EXPECT_NE(html.find("stage &#39;nope&#39; &lt;unknown&gt;"), std::string::npos)
        << "error shown, escaped";
    EXPECT_NE(html.find("<td class=\"text extra\">inf</td>"), std::string::npos)
        << "psnr inf shown as text";
    EXPECT_NE(html.find("tiled wins &lt;by far&gt;"), std::string::npos);
    // Published table, row "Test 64": brute measured 129 (2*64 + ordinal 1), tiled 36 (0.5*64 +
    // ordinal 4): published ratio 32/128 = 0.25, measured 36/129 = 0.2791.
    EXPECT_NE(html.find("<td>128</td><td>129</td><td>1&times;</td><td>1&times;</td><td>1&times;</"
                        "td><td>1</td>"),
              std::string::npos);
    EXPECT_NE(html.find("<td>32</td><td>36</td><td>0.25&times;</td><td>0.3&times;</"
                        "td><td>0.2791&times;</td><td>1</td>"),
              std::string::npos);
    EXPECT_NE(html.find("no error.png"), std::string::npos) << "job 0005 has no error image";
    EXPECT_NE(html.find("id=\"page-check\""), std::string::npos);
    EXPECT_EQ(html.find("http://"), std::string::npos) << "nothing from the network";
    EXPECT_EQ(html.find("https://"), std::string::npos);

    const json manifest = json::parse(readText(dir / "report" / "plots.json"));
    std::set<std::string> files;
    for (const json& plot : manifest["plots"]) {
        files.insert(plot["file"].get<std::string>());
        expectNotBlank(dir / "report" / plot["file"].get<std::string>());
        EXPECT_NE(html.find("src=\"report/" + plot["file"].get<std::string>() + "\""),
                  std::string::npos);
    }
    // One Pareto plot per comparable group (the three light counts), nothing pooled across them.
    for (const char* expected :
         {"pareto_g1.png", "pareto_g2.png", "pareto_g3.png", "evaluations_vs_lights_1.png",
          "culling_vs_lights_1.png", "time_vs_lights_1.png", "published_0.png"})
        EXPECT_EQ(files.count(expected), 1u) << expected << " in " << manifest.dump();
    EXPECT_EQ(files.count("bytes_g1.png"), 0u) << "one bytes-per-pixel value: not drawn";
    for (const json& plot : manifest["plots"]) {
        if (plot["kind"] == "pareto") {
            EXPECT_NE(plot["caption"].get<std::string>().find("min-max of the total time over 3 "
                                                              "repetitions"),
                      std::string::npos)
                << plot.dump();
        }
    }
    EXPECT_NE(html.find("not enough data"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir / "report" / "thumbs" / "0000-brute-preview.png"));
    EXPECT_TRUE(fs::exists(dir / "report" / "thumbs" / "0000-brute-heatmap.png"));
    EXPECT_FALSE(fs::exists(dir / "report" / "thumbs" / "0005-tiled-error.png"));

    // Groups: one section each, with its Pareto plot inside.
    const json groups = json::parse(readText(dir / "report" / "groups.json"));
    ASSERT_EQ(groups["groups"].size(), 3u) << groups.dump();
    EXPECT_EQ(groups["groups"][0]["label"], "atrium, 16 lights, 32x18");
    EXPECT_EQ(groups["groups"][0]["jobs"],
              json::array({"0000-brute", "0003-tiled", "9999-failed"}));
    for (const char* id : {"g1", "g2", "g3"}) {
        const size_t section = html.find(std::string("<section class=\"group\" id=\"group-") + id);
        ASSERT_NE(section, std::string::npos) << id;
        const size_t end = html.find("</section>", section);
        const std::string body = html.substr(section, end - section);
        EXPECT_NE(body.find(std::string("data-kind=\"pareto\" src=\"report/pareto_") + id),
                  std::string::npos)
            << id;
    }
    // Maps at the group's scale: g1 holds jobs 0000 (counts up to 8) and 0003 (up to 32), so both
    // heatmaps are drawn 0..32; job 0005's group has no EXR for it, so its images keep their own.
    EXPECT_TRUE(fs::exists(dir / "report" / "maps" / "0000-brute-heatmap.png"));
    EXPECT_TRUE(fs::exists(dir / "report" / "maps" / "0003-tiled-error.png"));
    EXPECT_NE(html.find("heatmaps 0..32 lights (the group's largest count)"), std::string::npos);
    EXPECT_NE(html.find("error maps linear up to 0.04 (the group's largest error)"),
              std::string::npos);
    // The table: the compared columns first, the rest behind the toggle; ꟻLIP among the first,
    // and a visible note saying why it is empty.
    EXPECT_NE(html.find("id=\"toggle-columns\""), std::string::npos);
    EXPECT_NE(html.find("<th class=\"col\" data-column=\"flip\""), std::string::npos);
    EXPECT_NE(html.find("<th class=\"col\" data-column=\"relative_rmse\""), std::string::npos);
    EXPECT_NE(html.find("<th class=\"col extra\" data-column=\"psnr\""), std::string::npos);
    EXPECT_NE(html.find("id=\"flip-note\""), std::string::npos);
    EXPECT_NE(html.find("flip-evaluator is not installed &lt;here&gt;"), std::string::npos);
    EXPECT_EQ(html.find("id=\"counts-note\""), std::string::npos) << "every job counts every pixel";
    const json published = json::parse(readText(dir / "report" / "published.json"));
    EXPECT_NEAR(published[0]["rows"][0]["cells"][1]["measured_ratio"].get<double>(), 36.0 / 129.0,
                1e-12);
    // The SIMT model beside published and measured: its ratio in the table, its efficiency
    // among the main columns.
    EXPECT_NEAR(published[0]["rows"][0]["cells"][1]["modelled_ratio"].get<double>(), 0.3, 1e-12);
    EXPECT_NE(html.find("<th>modelled ratio</th>"), std::string::npos);
    EXPECT_NE(html.find("<th class=\"col\" data-column=\"simt_efficiency\""), std::string::npos);
}

TEST(ReportCommand, SingleValuedAxesSayNotEnoughDataInsteadOfEmptyPlots) {
    const fs::path dir = writeResultsFolder(freshTestFolder(), true);
    ReportCommandOptions options;
    options.dir = dir;
    ASSERT_EQ(runReportCommand(options), 0) << dir;
    const json manifest = json::parse(readText(dir / "report" / "plots.json"));
    EXPECT_TRUE(manifest["plots"].empty())
        << "one ok job, no brute baseline: nothing to plot: " << manifest.dump();
    EXPECT_GE(manifest["skipped"].size(), 4u);
    const std::string html = readText(dir / "report.html");
    EXPECT_NE(html.find("Time against relative_rmse, group g1: atrium, 64 lights, 32x18: not "
                        "enough data (1 job of the group"),
              std::string::npos);
    EXPECT_NE(html.find("Culling efficiency against light count: not enough data"),
              std::string::npos);
}

TEST(ReportGroups, OnlyTheMethodColumnsVaryInsideAGroup) {
    auto job = [](const char* stage, const char* normals, int lights, int width, int threads) {
        return json{{"job_id", stage},    {"status", "ok"},     {"scene", "atrium"},
                    {"stage", stage},     {"normals", normals}, {"lights", lights},
                    {"width", width},     {"height", 90},       {"threads", threads},
                    {"resolution", "any"}};
    };
    const json jobs = json::array({job("a", "oct:16", 64, 160, 1), job("b", "oct:24", 64, 160, 1),
                                   job("c", "oct:16", 256, 160, 1), job("d", "oct:16", 64, 320, 1),
                                   job("e", "oct:16", 64, 160, 2), job("f", "sph:16", 64, 160, 1)});
    const std::vector<std::string> axes = {"scene", "stage",  "lights",  "resolution",
                                           "width", "height", "threads", "normals"};
    const std::vector<JobGroup> groups = comparableGroups(jobs, axes);
    ASSERT_EQ(groups.size(), 4u);
    EXPECT_EQ(groups[0].jobs, (std::vector<size_t>{0, 1, 5})) << "stage and normals are methods";
    EXPECT_EQ(groups[0].label, "atrium, 64 lights, 160x90, 1 threads");
    EXPECT_EQ(groups[1].jobs, (std::vector<size_t>{2}));
    EXPECT_EQ(groups[2].jobs, (std::vector<size_t>{3})) << "another size is another group";
    EXPECT_EQ(groups[3].jobs, (std::vector<size_t>{4})) << "other threads: another group";
    EXPECT_FALSE(groups[0].fixed.contains("resolution"));
    EXPECT_TRUE(isMethodColumn("normal-space"));
    EXPECT_FALSE(isMethodColumn("lights"));
}

TEST(ReportPublished, AMedianSaysWhichSettingsItsJobsDifferIn) {
    json a = okJob("0", "tiled", 64, 10.0), b = okJob("1", "tiled", 64, 20.0);
    a["threads"] = 1;
    b["threads"] = 2;
    const json published = {
        {"title", "T"},
        {"metric", "time_total_median_ms"},
        {"columns", {{{"label", "tiled"}, {"select", {{"stage", "tiled"}}}}}},
        {"rows", {{{"label", "64"}, {"select", {{"lights", 64}}}, {"values", {1.0}}}}}};
    const json table =
        comparePublished(published, json::array({a, b}), {"stage", "lights", "threads"});
    const json& cell = table["rows"][0]["cells"][0];
    EXPECT_DOUBLE_EQ(cell["measured"].get<double>(), 15.0);
    EXPECT_EQ(cell["differ_in"], json::array({"threads"}));
}

TEST(ReportCommand, TheErrorMetricIsTheUsersChoiceAndFlipSaysWhyItIsMissing) {
    const fs::path dir = writeResultsFolder(freshTestFolder(), false);
    ReportCommandOptions options;
    options.dir = dir;
    options.errorMetric = "flip";
    ASSERT_EQ(runReportCommand(options), 0);
    const json manifest = json::parse(readText(dir / "report" / "plots.json"));
    size_t skippedPareto = 0;
    for (const json& skipped : manifest["skipped"])
        if (skipped["kind"] == "pareto") {
            ++skippedPareto;
            EXPECT_NE(skipped["reason"].get<std::string>().find(
                          "flip unavailable: flip-evaluator is not installed <here>"),
                      std::string::npos)
                << skipped.dump();
        }
    EXPECT_EQ(skippedPareto, 3u);

    options.errorMetric = "psnr";
    ASSERT_EQ(runReportCommand(options), 0);
    options.errorMetric = "speed";
    testing::internal::CaptureStderr();
    EXPECT_EQ(runReportCommand(options), 1);
    const std::string error = testing::internal::GetCapturedStderr();
    EXPECT_NE(error.find("--error-metric 'speed' is not an error column"), std::string::npos)
        << error;
}

// The results of writeResultsFolder with a known ꟻLIP per ok job: tiled 0.02, brute 0.001.
void withFlip(const fs::path& dir) {
    json results = json::parse(readText(dir / "results.json"));
    // What the sweep runner writes and the advisor requires (the report guesses without it).
    results["axis_columns"] = {"scene", "stage", "lights", "width", "height", "repetitions"};
    results["sweep_file"] = "hand-made";
    results["quick"] = false;
    if (!results.contains("sweep"))
        results["sweep"] = json::object();
    for (json& job : results["jobs"]) {
        if (job["status"] != "ok")
            continue;
        job["flip"] = job["stage"] == "tiled" ? 0.02 : 0.001;
        job["flip_unavailable"] = "";
    }
    std::ofstream(dir / "results.json") << results.dump();
}

// ꟻLIP as a column and a Pareto axis, and the advisor's section once `advise` has run: tiled is
// 4x faster than brute at every light count (0.5 vs 2 ms per light), and within flip <= 0.05 it
// is the fastest; within 40 ms the least error is brute at 16 lights (32 ms), tiled above.
TEST(ReportCommand, FlipIsAColumnAndAParetoAxisAndTheAdviceIsASection) {
    const fs::path dir = writeResultsFolder(freshTestFolder(), false);
    withFlip(dir);
    ReportCommandOptions options;
    options.dir = dir;
    options.errorMetric = "flip";
    ASSERT_EQ(runReportCommand(options), 0);
    std::string html = readText(dir / "report.html");
    EXPECT_NE(html.find("<th class=\"col\" data-column=\"flip\""), std::string::npos);
    EXPECT_EQ(html.find("id=\"flip-note\""), std::string::npos) << "every job has ꟻLIP";
    EXPECT_NE(html.find("Relative RMSE and ꟻLIP: why they can disagree"), std::string::npos);
    EXPECT_NE(html.find("No advice yet"), std::string::npos);
    const json manifest = json::parse(readText(dir / "report" / "plots.json"));
    size_t paretoPlots = 0;
    for (const json& plot : manifest["plots"])
        paretoPlots += plot["kind"] == "pareto";
    EXPECT_EQ(paretoPlots, 3u) << manifest.dump();

    AdviseCommandOptions advise;
    advise.dir = dir;
    advise.criteria.budgetMs = 40;
    advise.criteria.maxFlip = 0.05;
    testing::internal::CaptureStdout();
    ASSERT_EQ(runAdviseCommand(advise), 0);
    const std::string text = testing::internal::GetCapturedStdout();
    EXPECT_NE(text.find("tiled"), std::string::npos) << text;
    ASSERT_EQ(runReportCommand(options), 0);
    html = readText(dir / "report.html");
    EXPECT_NE(html.find("<h2 id=\"advice\">Advice</h2>"), std::string::npos);
    EXPECT_EQ(html.find("No advice yet"), std::string::npos);
    // 16 lights: brute 32 ms (28.8-38.4), tiled 11 ms (9.9-13.2): tiled 2.91x faster; the least
    // ꟻLIP within 40 ms is brute's 0.001.
    EXPECT_NE(html.find("<b>tiled</b> 11 ms"), std::string::npos);
    EXPECT_NE(html.find("2.91&times; faster than brute"), std::string::npos);
    EXPECT_NE(html.find("<b>brute</b> 32 ms"), std::string::npos);
}

// Views: each view is its own comparable group (no Pareto plot pools views), and the views are
// aggregated explicitly per family (groups differing only in the view) and method: known times
// and errors give known medians and min-max over the views, a failed view is counted apart.
TEST(ReportViews, EachViewIsAGroupAndTheAggregatesOverViewsAreKnownNumbers) {
    const std::vector<std::string> views = {"nave", "far-end", "gallery"};
    json jobs = json::array();
    int ordinal = 0;
    const double bruteTimes[] = {10.0, 30.0, 20.0}, bruteErrors[] = {1e-6, 3e-6, 2e-6};
    for (int lights : {16, 64})
        for (size_t v = 0; v < views.size(); ++v)
            for (const std::string stage : {"brute", "tiled"}) {
                const std::string& view = views[v];
                // brute: 10, 30, 20 ms (x lights/16), errors 1e-6, 3e-6, 2e-6; tiled: 5 ms
                // everywhere, errors 4e-5, 1e-5, failed at gallery with 64 lights.
                const double scale = lights / 16.0;
                json job = okJob("j" + std::to_string(ordinal++), stage, lights,
                                 json(stage == "brute" ? scale * bruteTimes[v] : 5.0));
                job["scene"] = "atrium";
                job["view"] = view;
                job["width"] = 32;
                job["height"] = 18;
                job["relative_rmse"] = stage == "brute" ? bruteErrors[v] : (v == 0 ? 4e-5 : 1e-5);
                job["flip"] = nullptr;
                if (stage == "tiled" && lights == 64 && view == "gallery") {
                    job["status"] = "failed";
                    job["error"] = "out of memory <test>";
                    job["time_total_median_ms"] = nullptr;
                    job["relative_rmse"] = nullptr;
                }
                jobs.push_back(job);
            }
    const std::vector<std::string> axes = {"scene", "stage", "lights", "width", "height", "view"};
    const std::vector<JobGroup> groups = comparableGroups(jobs, axes);
    ASSERT_EQ(groups.size(), 6u) << "one group per (lights, view): views are never pooled";
    for (const JobGroup& group : groups) {
        EXPECT_EQ(group.jobs.size(), 2u);
        EXPECT_NE(group.label.find("view "), std::string::npos) << group.label;
    }

    const json aggregates = aggregateOverViews(jobs, groups, axes, "relative_rmse");
    EXPECT_EQ(aggregates["aggregated_over"], "view");
    ASSERT_EQ(aggregates["families"].size(), 2u);
    const json& family16 = aggregates["families"][0];
    EXPECT_EQ(family16["views"], json(views));
    EXPECT_EQ(family16["groups"], json({"g1", "g2", "g3"}));
    EXPECT_FALSE(family16["fixed"].contains("view"));
    ASSERT_EQ(family16["methods"].size(), 2u);
    const json& brute = family16["methods"][0];
    EXPECT_EQ(brute["label"], "brute");
    EXPECT_EQ(brute["views_ok"], 3);
    EXPECT_DOUBLE_EQ(brute["time_total_median_ms"]["median"].get<double>(), 20.0);
    EXPECT_DOUBLE_EQ(brute["time_total_median_ms"]["min"].get<double>(), 10.0);
    EXPECT_DOUBLE_EQ(brute["time_total_median_ms"]["max"].get<double>(), 30.0);
    EXPECT_DOUBLE_EQ(brute["relative_rmse"]["median"].get<double>(), 2e-6);
    EXPECT_TRUE(brute["flip"].is_null()) << "no view has ꟻLIP";
    EXPECT_EQ(brute["rows"].size(), 3u);
    const json& tiled64 = aggregates["families"][1]["methods"][1];
    EXPECT_EQ(tiled64["label"], "tiled");
    EXPECT_EQ(tiled64["views_ok"], 2);
    EXPECT_EQ(tiled64["views_failed"], 1);
    EXPECT_EQ(tiled64["relative_rmse"]["count"], 2);
    EXPECT_DOUBLE_EQ(tiled64["relative_rmse"]["median"].get<double>(), 2.5e-5)
        << "the mean of the two middle values of an even count";
    EXPECT_DOUBLE_EQ(
        aggregates["families"][1]["methods"][0]["time_total_median_ms"]["median"].get<double>(),
        80.0);

    // Without a view column, or with one view only, there is nothing to aggregate.
    EXPECT_TRUE(
        aggregateOverViews(jobs, groups, {"scene", "stage", "lights"}, "relative_rmse")["families"]
            .empty());
    json oneView = json::array();
    for (const json& job : jobs)
        if (job["view"] == "nave")
            oneView.push_back(job);
    EXPECT_TRUE(aggregateOverViews(oneView, comparableGroups(oneView, axes), axes,
                                   "relative_rmse")["families"]
                    .empty());

    // The page: the section says what is aggregated, the per-view rows sit in a closed toggle.
    const fs::path dir = freshTestFolder();
    const json columns = {"job_id",        "status", "error",  "scene", "stage",
                          "lights",        "width",  "height", "view",  "time_total_median_ms",
                          "relative_rmse", "flip"};
    std::ofstream(dir / "results.json")
        << json{{"sweep", {{"name", "views"}}}, {"columns", columns}, {"jobs", jobs}}.dump(1);
    ReportCommandOptions options;
    options.dir = dir;
    ASSERT_EQ(runReportCommand(options), 0);
    const std::string html = readText(dir / "report.html");
    EXPECT_EQ(json::parse(readText(dir / "report" / "views.json")), aggregates);
    EXPECT_NE(html.find("<h2 id=\"views\">Across views</h2>"), std::string::npos);
    EXPECT_NE(html.find("median and the min&ndash;max over the views"), std::string::npos);
    EXPECT_NE(html.find("<td>20 (10&ndash;30)</td>"), std::string::npos) << "brute, 16 lights";
    EXPECT_NE(html.find("2 of 3 <span class=\"error\">(failed: gallery)</span>"),
              std::string::npos);
    size_t details = 0;
    for (size_t at = html.find("<details class=\"per-view\""); at != std::string::npos;
         at = html.find("<details class=\"per-view\"", at + 1)) {
        ++details;
        const size_t end = html.find("</details>", at);
        EXPECT_EQ(html.substr(at, html.find('>', at) - at).find("open"), std::string::npos)
            << "the per-view rows are behind the toggle";
        const std::string block = html.substr(at, end - at);
        EXPECT_NE(block.find("Per-view rows (6 jobs)"), std::string::npos) << block;
    }
    EXPECT_EQ(details, 2u);
    EXPECT_NE(html.find("views, light counts"), std::string::npos);
}

TEST(ReportCommand, MissingResultsOrPythonIsOneClearError) {
    const fs::path dir = freshTestFolder();
    ReportCommandOptions options;
    options.dir = dir;
    testing::internal::CaptureStderr();
    EXPECT_EQ(runReportCommand(options), 1);
    std::string error = testing::internal::GetCapturedStderr();
    EXPECT_NE(error.find("testbed: error: cannot read " + (dir / "results.json").string()),
              std::string::npos)
        << error;
    EXPECT_FALSE(fs::exists(dir / "report.html"));

    writeResultsFolder(dir, true);
    options.python = "/nonexistent/python3";
    testing::internal::CaptureStderr();
    EXPECT_EQ(runReportCommand(options), 1);
    error = testing::internal::GetCapturedStderr();
    EXPECT_NE(error.find("python3-matplotlib"), std::string::npos) << error;
    EXPECT_FALSE(fs::exists(dir / "report.html"));

    options.python.clear();
    options.plotsScript = dir / "missing.py";
    testing::internal::CaptureStderr();
    EXPECT_EQ(runReportCommand(options), 1);
    error = testing::internal::GetCapturedStderr();
    EXPECT_NE(error.find("missing.py not found"), std::string::npos) << error;
}

} // namespace
} // namespace experiments
