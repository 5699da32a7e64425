// Sweep files: parsing (JSON and TOML), strict keys, quick overrides, expansion into jobs with
// stable ids, validation of every job before any runs, reference grouping, and sharding.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <tuple>

#include "experiments/render/RenderPlan.h"
#include "experiments/sweep/SweepFile.h"
#include "scenes/Viewpoints.h"

namespace {

namespace fs = std::filesystem;
using experiments::SweepError;
using experiments::SweepJob;
using Json = nlohmann::ordered_json;

fs::path testDir(const std::string& name) {
    const fs::path dir =
        fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / ("sweep-file-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

Json baseSweep() {
    return Json::parse(R"({
        "name": "unit",
        "fixed": {"scene": "spheres", "resolution": "160x90", "seed": 3},
        "axes": {"stage": ["brute", "tiled:tile=8", "clustered"], "lights": [4, 8]},
        "cases": [{"scene-option.segments": 16}, {"scene-option.segments": 32}],
        "warmup": 0, "repetitions": 2,
        "quick": {"fixed": {"resolution": "80x45"}, "axes": {"stage": ["brute"]}, "repetitions": 1}
    })");
}

// A job's settings as sorted "key=value" text, to compare jobs made in different orders.
std::string describeSettingsSorted(const SweepJob& job) {
    std::vector<std::string> parts;
    for (const experiments::SweepSetting& s : job.settings)
        parts.push_back(s.key + "=" + experiments::settingText(s.value, s.key));
    std::sort(parts.begin(), parts.end());
    std::string text;
    for (const std::string& part : parts)
        text += part + ";";
    return text;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const SweepError& e) {
        return e.what();
    }
    return "";
}

TEST(SweepFile, ExpandsCasesTimesAxesWithStableIds) {
    const auto spec = experiments::parseSweep(baseSweep(), "unit.json");
    const auto expansion = experiments::expandSweep(spec);
    ASSERT_EQ(expansion.jobs().size(), 2u * 3u * 2u);
    std::set<std::string> ids;
    std::set<size_t> ordinals;
    const std::regex idPattern("^[0-9]{4}-[0-9a-f]{8}$");
    for (const SweepJob& job : expansion.jobs()) {
        EXPECT_TRUE(std::regex_match(job.id, idPattern)) << job.id;
        EXPECT_EQ(job.id.substr(0, 4), std::string(4 - std::to_string(job.ordinal).size(), '0') +
                                           std::to_string(job.ordinal));
        ids.insert(job.id);
        ordinals.insert(job.ordinal);
        EXPECT_EQ(job.options.width, 160);
        EXPECT_EQ(job.options.height, 90);
        EXPECT_EQ(job.options.repetitions, 2);
        EXPECT_EQ(job.options.scene, "spheres");
    }
    EXPECT_EQ(ids.size(), expansion.jobs().size());
    EXPECT_EQ(*ordinals.rbegin(), expansion.jobs().size() - 1);
    // Ordinal order: cases outermost, then the axes in file order, last axis fastest.
    std::vector<SweepJob> byOrdinal = expansion.jobs();
    std::sort(byOrdinal.begin(), byOrdinal.end(),
              [](auto& a, auto& b) { return a.ordinal < b.ordinal; });
    EXPECT_EQ(byOrdinal[0].options.stage, "brute");
    EXPECT_EQ(byOrdinal[0].options.lights, 4);
    EXPECT_EQ(byOrdinal[1].options.lights, 8);
    EXPECT_EQ(byOrdinal[2].options.stage, "tiled:tile=8");
    EXPECT_EQ(byOrdinal[0].options.sceneOptions.at("segments"), "16");
    EXPECT_EQ(byOrdinal[6].options.sceneOptions.at("segments"), "32");

    // The same file expands to the same ids; changing one setting changes only those jobs' ids.
    const auto again =
        experiments::expandSweep(experiments::parseSweep(baseSweep(), "other-name.json"));
    for (size_t i = 0; i < again.jobs().size(); ++i)
        EXPECT_EQ(again.jobs()[i].id, expansion.jobs()[i].id);
    Json changed = baseSweep();
    changed["fixed"]["seed"] = 4;
    const auto moved = experiments::expandSweep(experiments::parseSweep(changed, "unit.json"));
    for (size_t i = 0; i < moved.jobs().size(); ++i)
        EXPECT_NE(moved.jobs()[i].id, expansion.jobs()[i].id);
}

TEST(SweepFile, JobsSharingAReferenceAreAdjacent) {
    const auto expansion =
        experiments::expandSweep(experiments::parseSweep(baseSweep(), "unit.json"));
    // Reference keys: (segments, lights) -> 4 groups of 3 stages each.
    std::vector<std::string> groups;
    for (const SweepJob& job : expansion.jobs())
        if (groups.empty() || groups.back() != job.referenceKey)
            groups.push_back(job.referenceKey);
    EXPECT_EQ(groups.size(), 4u);
    EXPECT_EQ(std::set<std::string>(groups.begin(), groups.end()).size(), 4u)
        << "a key appears twice";
    for (const SweepJob& job : expansion.jobs()) {
        EXPECT_EQ(job.referenceKey.find('/'), std::string::npos);
        EXPECT_EQ(job.referenceKey.rfind("spheres-160x90-", 0), 0u) << job.referenceKey;
    }
}

// The reference's samples per pixel are part of its key (a sweep option and axis like any render
// option); 1 keeps the key references had before supersampling.
TEST(SweepFile, TheReferenceSamplesArePartOfTheReferenceKey) {
    std::map<int, std::string> keyOfSpp;
    for (const int spp : {1, 4, 16}) {
        Json sweep = baseSweep();
        sweep["fixed"]["reference-spp"] = spp;
        const auto expansion =
            experiments::expandSweep(experiments::parseSweep(sweep, "unit.json"));
        const SweepJob job = expansion.jobs().front(); // jobs() makes them: a copy
        EXPECT_EQ(job.options.referenceSpp, spp);
        keyOfSpp[spp] = job.referenceKey;
    }
    const auto plain = experiments::expandSweep(experiments::parseSweep(baseSweep(), "unit.json"));
    EXPECT_EQ(plain.jobs().front().referenceKey, keyOfSpp[16]) << "16 is the default";
    EXPECT_NE(keyOfSpp[1], keyOfSpp[4]);
    EXPECT_NE(keyOfSpp[4], keyOfSpp[16]);
    EXPECT_EQ(keyOfSpp[1].find("spp"), std::string::npos) << keyOfSpp[1];
    EXPECT_NE(keyOfSpp[16].find("-spp16-"), std::string::npos) << keyOfSpp[16];
    Json bad = baseSweep();
    bad["fixed"]["reference-spp"] = 15;
    const std::string error =
        errorOf([&] { experiments::expandSweep(experiments::parseSweep(bad, "unit.json")); });
    EXPECT_NE(error.find("--reference-spp 15 refused"), std::string::npos) << error;
}

// Each view has its own reference image; the default view keeps the key it had before views.
TEST(SweepFile, EveryViewHasItsOwnReference) {
    const auto plain = experiments::expandSweep(experiments::parseSweep(baseSweep(), "unit.json"));
    Json withViews = baseSweep();
    withViews["axes"]["view"] = {"front", "above"};
    const auto expansion =
        experiments::expandSweep(experiments::parseSweep(withViews, "unit.json"));
    std::set<std::string> keys;
    for (const SweepJob& job : expansion.jobs()) {
        keys.insert(job.referenceKey);
        EXPECT_NE(job.referenceKey.find("-" + job.options.view + "-"), std::string::npos)
            << job.referenceKey;
    }
    EXPECT_EQ(keys.size(), 8u); // (segments, lights) x view
    for (const SweepJob& job : plain.jobs())
        EXPECT_EQ(job.referenceKey.find("front"), std::string::npos);
}

// "view": "all" stands for every view of each job's scene, resolved per scene: the jobs are those
// of the sweep that lists each scene's views, with the same settings, ids (hash part) and one
// reference per view.
TEST(SweepFile, EveryViewOfEachSceneIsOneJobWithItsOwnReference) {
    Json all = Json::parse(R"({
        "fixed": {"resolution": "80x45", "seed": 3, "lights": 4},
        "axes": {"scene": ["spheres", "wall"], "view": ["all"], "stage": ["brute", "tiled"]}
    })");
    const auto expansion = experiments::expandSweep(experiments::parseSweep(all, "all.json"));
    std::map<std::string, std::vector<std::string>> viewsOf;
    for (const std::string scene : {"spheres", "wall"}) {
        experiments::RenderOptions options;
        options.scene = scene;
        viewsOf[scene] = scenes::viewNames(experiments::loadRequestedScene(options));
        ASSERT_GE(viewsOf[scene].size(), 2u) << scene;
    }
    const size_t expected = 2 * (viewsOf["spheres"].size() + viewsOf["wall"].size());
    ASSERT_EQ(expansion.size(), expected);

    // The same sweep with the views listed, one case per scene (the scenes' lists differ).
    Json listed = Json::parse(R"({
        "fixed": {"resolution": "80x45", "seed": 3, "lights": 4},
        "axes": {"stage": ["brute", "tiled"]}
    })");
    std::set<std::string> listedJobs, listedKeys;
    for (const std::string scene : {"spheres", "wall"}) {
        Json one = listed;
        one["fixed"]["scene"] = scene;
        one["axes"]["view"] = viewsOf[scene];
        for (const SweepJob& job :
             experiments::expandSweep(experiments::parseSweep(one, "listed.json")).jobs()) {
            listedJobs.insert(describeSettingsSorted(job) + " " + job.id.substr(job.id.find('-')));
            listedKeys.insert(job.referenceKey);
        }
    }
    std::set<std::string> jobs, keys, ids;
    for (const SweepJob& job : expansion.jobs()) {
        const auto& views = viewsOf[job.options.scene];
        EXPECT_NE(std::find(views.begin(), views.end(), job.options.view), views.end())
            << job.options.scene << " has no view '" << job.options.view << "'";
        jobs.insert(describeSettingsSorted(job) + " " + job.id.substr(job.id.find('-')));
        keys.insert(job.referenceKey);
        ids.insert(job.id);
        // The job handed to a child process comes back the same.
        EXPECT_EQ(experiments::sweepJobFromJson(experiments::sweepJobJson(job)).referenceKey,
                  job.referenceKey);
    }
    EXPECT_EQ(ids.size(), expected);
    EXPECT_EQ(jobs, listedJobs);
    EXPECT_EQ(keys, listedKeys);
    EXPECT_EQ(keys.size(), viewsOf["spheres"].size() + viewsOf["wall"].size())
        << "one reference per scene and view";
    // Ordinals 0..n-1, each job at its own ordinal, and the views of one unresolved job adjacent
    // in the scene's order.
    for (size_t ordinal = 0; ordinal < expansion.size(); ++ordinal)
        EXPECT_EQ(expansion.jobAtOrdinal(ordinal).ordinal, ordinal);
    // Unresolved job 0 (spheres, brute) becomes ordinals 0..3, one per view in the scene's order.
    for (size_t v = 0; v < viewsOf["spheres"].size(); ++v) {
        const SweepJob job = expansion.jobAtOrdinal(v);
        EXPECT_EQ(job.options.scene, "spheres");
        EXPECT_EQ(job.options.stage, "brute");
        EXPECT_EQ(job.options.view, viewsOf["spheres"][v]) << "the views are the fastest";
    }
    EXPECT_EQ(expansion.jobAtOrdinal(viewsOf["spheres"].size()).options.stage, "tiled");

    // "view": "all" as a fixed setting does the same for the one scene.
    Json fixedAll = Json::parse(R"({
        "fixed": {"scene": "wall", "view": "all", "resolution": "80x45", "lights": 4},
        "axes": {"stage": ["brute"]}
    })");
    EXPECT_EQ(experiments::expandSweep(experiments::parseSweep(fixedAll, "fixed.json")).size(),
              viewsOf["wall"].size());
}

TEST(SweepFile, EveryViewBesideNamedViewsOrOnABadSceneIsRefused) {
    Json both = Json::parse(R"({
        "fixed": {"scene": "spheres"}, "axes": {"view": ["all", "front"]}
    })");
    EXPECT_NE(errorOf([&] {
                  experiments::expandSweep(experiments::parseSweep(both, "b.json"));
              }).find("must be the axis' only value"),
              std::string::npos);
    Json missing = Json::parse(R"({
        "fixed": {"view": "all"}, "axes": {"scene": ["spheres", "/no/such/scene.gltf"]}
    })");
    const std::string message =
        errorOf([&] { experiments::expandSweep(experiments::parseSweep(missing, "m.json")); });
    // The missing file is found by the job's own check, before any scene is loaded: it stays
    // one invalid job (the 4 views of spheres are fine).
    EXPECT_NE(message.find("1 of 5 jobs are invalid"), std::string::npos) << message;
    EXPECT_NE(message.find("view=all scene=/no/such/scene.gltf"), std::string::npos) << message;
    EXPECT_NE(message.find("not found"), std::string::npos) << message;
}

TEST(SweepFile, AxisColumnsInCanonicalOrder) {
    const auto expansion =
        experiments::expandSweep(experiments::parseSweep(baseSweep(), "unit.json"));
    const std::vector<std::string> expected = {
        "scene",       "stage", "lights", "seed",
        "resolution",  "width", "height", "scene-option.segments",
        "repetitions", "warmup"};
    EXPECT_EQ(expansion.axisColumns(), expected);
    const SweepJob job = expansion.job(0);
    EXPECT_EQ(experiments::axisValue(job, "width"), Json(160));
    EXPECT_EQ(experiments::axisValue(job, "resolution"), Json("160x90"));
    EXPECT_EQ(experiments::axisValue(job, "repetitions"), Json(2));
}

TEST(SweepFile, QuickBlockOverrides) {
    const auto quick = experiments::applyQuick(experiments::parseSweep(baseSweep(), "unit.json"));
    const auto expansion = experiments::expandSweep(quick);
    ASSERT_EQ(expansion.jobs().size(), 2u * 1u * 2u);
    for (const SweepJob& job : expansion.jobs()) {
        EXPECT_EQ(job.options.width, 80);
        EXPECT_EQ(job.options.stage, "brute");
        EXPECT_EQ(job.options.repetitions, 1);
    }
    // A key moved from the axes to quick.fixed leaves the axes.
    Json file = baseSweep();
    file["quick"] = Json::parse(R"({"fixed": {"lights": 2}})");
    const auto moved =
        experiments::expandSweep(experiments::applyQuick(experiments::parseSweep(file, "u.json")));
    EXPECT_EQ(moved.jobs().size(), 2u * 3u);
    Json noQuick = baseSweep();
    noQuick.erase("quick");
    const std::string message =
        errorOf([&] { experiments::applyQuick(experiments::parseSweep(noQuick, "nq.json")); });
    EXPECT_NE(message.find("nq.json"), std::string::npos) << message;
    EXPECT_NE(message.find("quick"), std::string::npos) << message;
}

// A file with only a name (a truncated or typo'd file) once ran one default render silently.
TEST(SweepFile, SweepThatSetsNothingIsRefused) {
    std::string message = errorOf(
        [&] { experiments::parseSweep(Json::parse(R"({"name": "empty"})"), "empty.json"); });
    EXPECT_NE(message.find("empty.json: the sweep sets nothing to run"), std::string::npos)
        << message;
    EXPECT_NE(message.find("only 'name'"), std::string::npos) << message;
    message = errorOf([&] { experiments::parseSweep(Json::object(), "bare.json"); });
    EXPECT_NE(message.find("has no keys"), std::string::npos) << message;
    // One setting is enough.
    EXPECT_NO_THROW(experiments::expandSweep(
        experiments::parseSweep(Json::parse(R"({"fixed": {"scene": "wall"}})"), "one.json")));
}

TEST(SweepFile, RejectsUnknownKeysNamingFileAndKey) {
    Json file = baseSweep();
    file["axis"] = Json::object(); // typo of "axes"
    std::string message = errorOf([&] { experiments::parseSweep(file, "typo.json"); });
    EXPECT_NE(message.find("typo.json"), std::string::npos) << message;
    EXPECT_NE(message.find("'axis'"), std::string::npos) << message;

    file = baseSweep();
    file["quick"]["repetition"] = 1;
    message = errorOf([&] { experiments::parseSweep(file, "typo.json"); });
    EXPECT_NE(message.find("quick.repetition"), std::string::npos) << message;

    file = baseSweep();
    file["fixed"]["lights"] = 3; // also an axis
    message = errorOf([&] { experiments::parseSweep(file, "dup.json"); });
    EXPECT_NE(message.find("'lights'"), std::string::npos) << message;

    file = baseSweep();
    file["cases"][1] = Json::parse(R"({"scene-option.behind": 1})");
    message = errorOf([&] { experiments::parseSweep(file, "cases.json"); });
    EXPECT_NE(message.find("cases[1]"), std::string::npos) << message;

    file = baseSweep();
    file["axes"]["lights"] = Json::array({true});
    message = errorOf([&] { experiments::parseSweep(file, "type.json"); });
    EXPECT_NE(message.find("axes.lights"), std::string::npos) << message;
}

TEST(SweepFile, ReportsEveryInvalidJobBeforeRunning) {
    Json file = baseSweep();
    file["axes"]["stage"] = Json::array({"brute", "no-such-stage", "tiled:tile=9999"});
    const std::string message =
        errorOf([&] { experiments::expandSweep(experiments::parseSweep(file, "bad.json")); });
    EXPECT_NE(message.find("bad.json"), std::string::npos) << message;
    EXPECT_NE(message.find("8 of 12 jobs are invalid"), std::string::npos) << message;
    EXPECT_NE(message.find("stage=no-such-stage"), std::string::npos) << message;
    EXPECT_NE(message.find("stage=tiled:tile=9999"), std::string::npos) << message;

    file = baseSweep();
    file["fixed"]["no-such-option"] = 1;
    const std::string unknown =
        errorOf([&] { experiments::expandSweep(experiments::parseSweep(file, "bad.json")); });
    EXPECT_NE(unknown.find("no-such-option"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("12 of 12"), std::string::npos) << unknown;
}

// Display keys: one scale for every job's heatmap and error map; not part of the job ids.
TEST(SweepFile, MapScalesApplyToEveryJobAndKeepTheIds) {
    Json file = baseSweep();
    const auto plain = experiments::expandSweep(experiments::parseSweep(file, "unit.json"));
    file["heatmap-max"] = 64;
    file["error-scale"] = "log";
    file["error-max"] = 0.5;
    const auto spec = experiments::parseSweep(file, "unit.json");
    EXPECT_EQ(spec.heatmapMax, 64u);
    EXPECT_EQ(spec.errorScale, experiments::MapScale::Log);
    EXPECT_EQ(spec.errorMax, 0.5);
    const std::vector<SweepJob> plainJobs = plain.jobs();
    const std::vector<SweepJob> scaledJobs = experiments::expandSweep(spec).jobs();
    ASSERT_EQ(scaledJobs.size(), plainJobs.size());
    for (size_t i = 0; i < plainJobs.size(); ++i) {
        EXPECT_EQ(scaledJobs[i].id, plainJobs[i].id);
        EXPECT_EQ(scaledJobs[i].heatmapMax, 64u);
        EXPECT_EQ(scaledJobs[i].errorScale, experiments::MapScale::Log);
        EXPECT_EQ(scaledJobs[i].errorMax, 0.5);
        // A job handed to its process as JSON keeps the scales.
        const SweepJob again =
            experiments::sweepJobFromJson(experiments::sweepJobJson(scaledJobs[i]));
        EXPECT_EQ(again.heatmapMax, 64u);
        EXPECT_EQ(again.errorScale, experiments::MapScale::Log);
        EXPECT_EQ(again.errorMax, 0.5);
    }
    for (const auto& [key, value, expected] :
         {std::tuple<const char*, Json, const char*>{"heatmap-max", -1, "'heatmap-max' must be"},
          {"heatmap-max", "64", "'heatmap-max' must be"},
          {"error-scale", "logarithmic", "'error-scale' must be \"linear\" or \"log\""},
          {"error-max", -0.5, "'error-max' must be a number >= 0"}}) {
        Json bad = baseSweep();
        bad[key] = value;
        const std::string message = errorOf([&] { experiments::parseSweep(bad, "unit.json"); });
        EXPECT_NE(message.find(expected), std::string::npos) << key << ": " << message;
    }
}

// job-timeout: the runner's limit per job (SweepRunner.h), not a setting: it keeps the ids.
TEST(SweepFile, JobTimeoutIsReadAndChecked) {
    Json file = baseSweep();
    EXPECT_EQ(experiments::parseSweep(file, "unit.json").jobTimeoutSeconds, 0.0); // no limit
    const auto plainJobs = experiments::expandSweep(experiments::parseSweep(file, "unit.json"));
    file["job-timeout"] = 90.5;
    const auto spec = experiments::parseSweep(file, "unit.json");
    EXPECT_EQ(spec.jobTimeoutSeconds, 90.5);
    const auto limitedJobs = experiments::expandSweep(spec);
    ASSERT_EQ(limitedJobs.size(), plainJobs.size());
    for (size_t i = 0; i < plainJobs.size(); ++i)
        EXPECT_EQ(limitedJobs.jobId(i), plainJobs.jobId(i));
    const auto toml = experiments::readSweepText(
        "name = \"t\"\njob-timeout = 600\n[fixed]\nscene = \"wall\"\n", "t.toml", true);
    EXPECT_EQ(toml.jobTimeoutSeconds, 600.0);
    for (const Json& value : {Json(-1), Json("60"), Json(2e8), Json(nullptr)}) {
        Json bad = baseSweep();
        bad["job-timeout"] = value;
        const std::string message = errorOf([&] { experiments::parseSweep(bad, "unit.json"); });
        EXPECT_NE(message.find("'job-timeout' must be a number of seconds"), std::string::npos)
            << value.dump() << ": " << message;
    }
}

TEST(SweepFile, ChecksPublishedTables) {
    Json file = baseSweep();
    file["published"] = Json::parse(R"([{"title": "t", "metric": "time_total_median_ms",
        "columns": [{"label": "brute", "select": {"stage": "brute"}}],
        "rows": [{"label": "4 lights", "select": {"lights": 4}, "values": [1.5]}], "ratio_to": 0}])");
    EXPECT_NO_THROW(experiments::parseSweep(file, "pub.json"));
    file["published"][0]["modelled"] = "simt_lane_slots";
    EXPECT_NO_THROW(experiments::parseSweep(file, "pub.json"));
    file["published"][0]["modelled"] = Json::array({"simt_lane_slots"});
    EXPECT_NE(errorOf([&] {
                  experiments::parseSweep(file, "pub.json");
              }).find("'published[0].modelled' must be a column name"),
              std::string::npos);
    file["published"][0].erase("modelled");
    file["published"][0]["rows"][0]["values"] = Json::array({1.0, 2.0});
    EXPECT_NE(errorOf([&] { experiments::parseSweep(file, "pub.json"); }).find("values"),
              std::string::npos);
    file["published"][0]["rows"][0]["values"] = Json::array({nullptr});
    file["published"][0]["rows"][0]["select"] = Json::parse(R"({"colour": 4})");
    EXPECT_NE(errorOf([&] { experiments::parseSweep(file, "pub.json"); }).find("colour"),
              std::string::npos);
}

TEST(SweepFile, TomlEqualsJson) {
    const fs::path dir = testDir("toml");
    std::ofstream(dir / "s.toml") << R"(name = "unit"
warmup = 0
repetitions = 2

[fixed]
scene = "spheres"
resolution = "160x90"
seed = 3

[axes]
stage = ["brute", "tiled:tile=8", "clustered"]
lights = [4, 8]

[[cases]]
"scene-option.segments" = 16

[[cases]]
"scene-option.segments" = 32
)";
    std::ofstream(dir / "s.json") << baseSweep().dump();
    const auto fromToml = experiments::expandSweep(experiments::readSweepFile(dir / "s.toml"));
    const auto fromJson = experiments::expandSweep(experiments::readSweepFile(dir / "s.json"));
    ASSERT_EQ(fromToml.jobs().size(), fromJson.jobs().size());
    std::set<std::string> tomlIds, jsonIds;
    for (const SweepJob& job : fromToml.jobs())
        tomlIds.insert(job.id);
    for (const SweepJob& job : fromJson.jobs())
        jsonIds.insert(job.id);
    EXPECT_EQ(tomlIds, jsonIds);

    std::ofstream(dir / "broken.toml") << "name = \"x\"\n[axes\n";
    const std::string message = errorOf([&] { experiments::readSweepFile(dir / "broken.toml"); });
    EXPECT_NE(message.find("broken.toml:2"), std::string::npos) << message;
}

TEST(SweepFile, ShardsPartitionTheJobs) {
    const auto jobs =
        experiments::expandSweep(experiments::parseSweep(baseSweep(), "unit.json")).jobs();
    for (int count : {1, 2, 5, 12, 13}) {
        std::multiset<std::string> seen;
        size_t smallest = jobs.size(), largest = 0;
        for (int index = 1; index <= count; ++index) {
            const auto shard = experiments::shardJobs(jobs, index, count);
            smallest = std::min(smallest, shard.size());
            largest = std::max(largest, shard.size());
            for (const SweepJob& job : shard)
                seen.insert(job.id);
        }
        EXPECT_EQ(seen.size(), jobs.size()) << count;
        EXPECT_EQ(std::set<std::string>(seen.begin(), seen.end()).size(), jobs.size()) << count;
        EXPECT_LE(largest - smallest, 1u) << count;
    }
    EXPECT_EQ(experiments::parseShard("2/4"), std::make_pair(2, 4));
    for (const char* bad : {"0/4", "5/4", "2", "a/b", "2/4x", "-1/2"})
        EXPECT_THROW(experiments::parseShard(bad), SweepError) << bad;
}

// The reproductions in experiments/sweeps (full and --quick) expand into valid jobs: a renamed
// stage, encoding or option breaks this test, not a sweep after an hour.
TEST(SweepFile, ReproductionSweepsAreValid) {
    const fs::path folder = fs::path(TESTBED_SOURCE_DIR) / "experiments" / "sweeps";
    ASSERT_TRUE(fs::is_directory(folder)) << folder;
    // The sweeps are run from the repository root (their glTF scenes are ../shared/... paths).
    const fs::path previous = fs::current_path();
    fs::current_path(TESTBED_SOURCE_DIR);
    struct Restore {
        fs::path path;
        ~Restore() { fs::current_path(path); }
    } restore{previous};
    size_t files = 0;
    for (const auto& entry : fs::directory_iterator(folder)) {
        if (entry.path().extension() != ".json" && entry.path().extension() != ".toml")
            continue;
        ++files;
        SCOPED_TRACE(entry.path().string());
        const auto spec = experiments::readSweepFile(entry.path());
        EXPECT_FALSE(spec.name.empty());
        EXPECT_FALSE(experiments::expandSweep(spec).jobs().empty());
        EXPECT_FALSE(experiments::expandSweep(experiments::applyQuick(spec)).jobs().empty());
    }
    EXPECT_GE(files, 4u);
}

TEST(SweepFile, SettingTextOfNumbers) {
    EXPECT_EQ(experiments::settingText(Json(1500), "k"), "1500");
    EXPECT_EQ(experiments::settingText(Json(1500.0), "k"), "1500");
    EXPECT_EQ(experiments::settingText(Json(0.25), "k"), "0.25");
    EXPECT_EQ(experiments::settingText(Json("tiled:tile=32"), "k"), "tiled:tile=32");
    EXPECT_THROW(experiments::settingText(Json(true), "k"), SweepError);
}

} // namespace
