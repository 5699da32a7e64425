// NormalStudy: the study's steps in order. Sampling is NormalSampling.h, the statistics
// NormalStatistics.h, the files and the printed table NormalStudyOutputs.h, the plots
// StudyPlots.h; this file checks the options, runs each step under the study's thread count and
// times it, and assembles the rows (codec-major: every data set of a codec x bits together).
#include "experiments/studies/NormalStudy.h"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <stdexcept>
#include <thread>

#include <tbb/task_arena.h>

#include "experiments/CommandErrors.h"
#include "experiments/output/AtomicFile.h"
#include "experiments/output/PlotScript.h"
#include "experiments/studies/NormalSampling.h"
#include "experiments/studies/NormalStatistics.h"
#include "experiments/studies/NormalStudyOutputs.h"
#include "experiments/studies/StudyPlots.h"
#include "scenes/input/MessageText.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace experiments {

namespace {

using namespace normal_study;
using gbuffer::NormalCodecSpec;
using Clock = std::chrono::steady_clock;
using Progress = std::function<void(const std::string&)>;

// Error maps: equirectangular grid, each cell the max over sub x sub stratified samples.
constexpr int kMapWidth = 720, kMapHeight = 360, kMapSub = 4; // 0.5 degree cells
constexpr int kQuickMapWidth = 90, kQuickMapHeight = 45, kQuickMapSub = 2;
constexpr int kQuickSceneWidth = 160, kQuickSceneHeight = 90;

// The options resolved and checked: what --quick implies, the thread count, the plot script.
struct Setup {
    std::uint64_t directions = 0;
    int sceneWidth = 0, sceneHeight = 0;
    int threads = 1;
    std::filesystem::path plotsScript; // empty without plots
};

void checkScenes(const std::vector<std::string>& sources) {
    for (const std::string& scene : sources)
        if (!scenes::isProceduralScene(scene) && !std::filesystem::is_regular_file(scene)) {
            std::string names;
            for (const std::string& name : scenes::proceduralSceneNames())
                names += " " + name;
            throw std::invalid_argument("--scene '" + scene + "': not a built-in scene (" +
                                        names.substr(1) + ") and no such file");
        }
}

// Everything is checked before any work; throws std::invalid_argument naming the option.
Setup checkOptions(const NormalStudyOptions& options) {
    if (options.out.empty())
        throw std::invalid_argument("--out: an output folder is required");
    Setup setup;
    setup.directions = options.directions.value_or(options.quick ? kNormalStudyQuickDirections
                                                                 : kNormalStudyDirections);
    if (setup.directions < 1000 || setup.directions > 1'000'000'000)
        throw std::invalid_argument("--directions " + std::to_string(setup.directions) +
                                    ": expected 1000 .. 1000000000");
    if (options.threads < 0 || options.threads > 1024)
        throw std::invalid_argument("--threads " + std::to_string(options.threads) +
                                    ": expected 0 .. 1024");
    setup.sceneWidth = options.quick ? kQuickSceneWidth : options.sceneWidth;
    setup.sceneHeight = options.quick ? kQuickSceneHeight : options.sceneHeight;
    if (setup.sceneWidth < 1 || setup.sceneHeight < 1 || setup.sceneWidth > 8192 ||
        setup.sceneHeight > 8192)
        throw std::invalid_argument("--width/--height " + std::to_string(setup.sceneWidth) + "x" +
                                    std::to_string(setup.sceneHeight) +
                                    ": expected 1 .. 8192 each");
    checkScenes(options.scenes);
    if (options.plots)
        setup.plotsScript = requirePlotScript(options.plotsScript, "normals.py");
    setup.threads = options.threads > 0 ? options.threads
                                        : std::max(1, int(std::thread::hardware_concurrency()));
    return setup;
}

// The scenes to render: the requested ones, then the models found (label = name or file stem).
std::vector<std::pair<std::string, std::string>>
sceneSources(const NormalStudyOptions& options, const std::vector<std::string>& models) {
    std::vector<std::pair<std::string, std::string>> sources; // source, label
    for (const std::string& s : options.scenes)
        sources.emplace_back(
            s, scenes::isProceduralScene(s) ? s : std::filesystem::path(s).stem().string());
    for (const std::string& s : models)
        sources.emplace_back(s, std::filesystem::path(s).stem().string());
    return sources;
}

// One run of the study: its steps share the codecs, the rows per codec and the record.
class StudyRun {
public:
    StudyRun(const NormalStudyOptions& options, const Setup& setup, const Progress& progress)
        : mOptions(options), mSetup(setup), mProgress(progress),
          mSpecs(gbuffer::allNormalCodecSpecs()), mRowsBySpec(mSpecs.size()) {}

    NormalStudyResult run() {
        findModels();
        tbb::task_arena arena(mSetup.threads);
        arena.execute([&] {
            timed("sphere", [&] { sphere(); });
            timed("visible-60", [&] { visible(); });
            timed("scenes", [&] { renderedScenes(); });
            timed("hard", [&] { hard(); });
            timed("negative_z_fractions", [&] { negativeZ(); });
            timed("occupancy", [&] { occupancy(); });
            timed("maps", [&] { maps(); });
        });
        // Throughput last, on this thread alone, with no parallel work running.
        timed("throughput", [&] { throughput(); });
        for (const std::vector<NormalStudyRow>& rows : mRowsBySpec)
            mResult.rows.insert(mResult.rows.end(), rows.begin(), rows.end());
        mRecord.config = config();
        mRecord.directions = mSetup.directions;
        mResult.json = normalStudyJson(mResult, mRecord);
        return std::move(mResult);
    }

private:
    void step(const std::string& what) const {
        if (mProgress)
            mProgress(what);
    }
    template <typename Fn> void timed(const std::string& name, Fn&& fn) {
        const auto start = Clock::now();
        fn();
        mRecord.timings[name] = std::chrono::duration<double>(Clock::now() - start).count();
    }
    void addDataset(const Dataset& data) {
        for (std::size_t s = 0; s < mSpecs.size(); ++s)
            mRowsBySpec[s].push_back(evaluate(mSpecs[s], data, mErrors));
    }
    // Per codec figures, copied onto each of its rows.
    template <typename Fn> void forEachCodec(Fn&& setRows) {
        for (std::size_t s = 0; s < mSpecs.size(); ++s)
            setRows(mSpecs[s], mRowsBySpec[s]);
    }

    void findModels() {
        if (!mOptions.modelsDir && mOptions.quick)
            return;
        mModelsDir = mOptions.modelsDir.value_or(kNormalStudyModelsDir);
        if (!std::filesystem::is_directory(mModelsDir)) {
            mResult.warnings.push_back("models folder " + mModelsDir.string() +
                                       " not found: no glTF models studied");
            return;
        }
        for (const std::filesystem::path& model : normal_study::findModels(mModelsDir))
            mModels.push_back(model.string());
    }
    void sphere() {
        step("sphere: " + std::to_string(mSetup.directions) + " uniform directions x " +
             std::to_string(mSpecs.size()) + " codecs");
        addDataset(sphereDataset(mSetup.directions, mOptions.seed));
    }
    void visible() {
        step("visible-60: " + std::to_string(mSetup.directions) + " front-facing normals");
        addDataset(visibleDataset(mSetup.directions, mOptions.seed));
    }
    void renderedScenes() {
        for (const auto& [source, label] : sceneSources(mOptions, mModels)) {
            step("scene " + label + " at " + std::to_string(mSetup.sceneWidth) + "x" +
                 std::to_string(mSetup.sceneHeight));
            NormalStudyScene info, geometricInfo;
            Dataset geometric;
            const Dataset data = sceneDataset(source, label, mSetup.sceneWidth, mSetup.sceneHeight,
                                              info, mResult.warnings, geometric, geometricInfo);
            mResult.scenes.push_back(info);
            addDataset(data);
            if (!geometric.normals.empty()) {
                step("scene " + label + " without its normal maps (" + geometric.name + ")");
                mResult.scenes.push_back(geometricInfo);
                addDataset(geometric);
            }
        }
    }
    void hard() {
        step("hard cases");
        const Dataset data = hardDataset();
        forEachCodec([&](const NormalCodecSpec& spec, std::vector<NormalStudyRow>& rows) {
            NormalStudyRow row = evaluate(spec, data, mErrors);
            row.zeroVectorDecodesTo = zeroVectorDecodesTo(spec);
            rows.push_back(row);
        });
    }
    void negativeZ() {
        step("negative view-space z fractions at 45/60/90 degrees");
        for (double fov : {45.0, 60.0, 90.0})
            for (double aspect : {16.0 / 9.0, 1.0})
                mResult.negativeZ.push_back(
                    negativeZFraction(fov, aspect, mSetup.directions, mOptions.seed));
    }
    void occupancy() {
        step("occupancy (encode(decode(code)) == code)");
        forEachCodec([&](const NormalCodecSpec& spec, std::vector<NormalStudyRow>& rows) {
            const Occupancy occupancy = measureOccupancy(spec, mOptions.quick, mOptions.seed);
            for (NormalStudyRow& row : rows) {
                row.occupancy = occupancy.fraction;
                row.occupancyCodesTested = occupancy.tested;
            }
        });
    }
    void maps();
    void throughput() {
        step("single-threaded encode/decode throughput (wall clock of this run)");
        const std::size_t count = mOptions.quick ? kThroughputQuickNormals : kThroughputNormals;
        const int repeats = mOptions.quick ? 1 : kThroughputRepeats;
        forEachCodec([&](const NormalCodecSpec& spec, std::vector<NormalStudyRow>& rows) {
            const Throughput measured = measureThroughput(spec, count, repeats, mOptions.seed);
            for (NormalStudyRow& row : rows) {
                row.encodePerSecond = measured.encodePerSecond;
                row.decodePerSecond = measured.decodePerSecond;
            }
        });
    }
    nlohmann::json config() const;

    const NormalStudyOptions& mOptions;
    const Setup& mSetup;
    const Progress& mProgress;
    const std::vector<NormalCodecSpec> mSpecs;
    std::vector<std::vector<NormalStudyRow>> mRowsBySpec;
    std::vector<float> mErrors; // scratch of evaluate()
    std::filesystem::path mModelsDir;
    std::vector<std::string> mModels;
    NormalStudyResult mResult;
    StudyRecord mRecord;
};

// One error map per codec, at the bit depth of mapBits, written as DIR/maps/<codec>-<bits>.f32.
void StudyRun::maps() {
    step("error maps");
    const int w = mOptions.quick ? kQuickMapWidth : kMapWidth;
    const int h = mOptions.quick ? kQuickMapHeight : kMapHeight;
    const int sub = mOptions.quick ? kQuickMapSub : kMapSub;
    for (const NormalCodecSpec& spec : mSpecs) {
        if (spec.bits != mapBits(spec.kind))
            continue;
        const std::string stem =
            std::string(gbuffer::normalCodecName(spec.kind)) + "-" + std::to_string(spec.bits);
        const std::vector<float> grid = errorMap(spec, w, h, sub);
        writeFloats(mOptions.out / "maps" / (stem + ".f32"), grid);
        mRecord.maps.push_back({{"codec", spec.text()},
                                {"name", gbuffer::normalCodecName(spec.kind)},
                                {"bits", spec.bits},
                                {"data", "maps/" + stem + ".f32"},
                                {"png", "maps/" + stem + ".png"},
                                {"width", w},
                                {"height", h},
                                {"samples_per_cell", sub * sub},
                                {"max_deg", *std::max_element(grid.begin(), grid.end())}});
    }
}

nlohmann::json StudyRun::config() const {
    return {{"directions", mSetup.directions},
            {"seed", mOptions.seed},
            {"scenes", mOptions.scenes},
            {"models_dir", mModelsDir.string()},
            {"models", mModels},
            {"scene_width", mSetup.sceneWidth},
            {"scene_height", mSetup.sceneHeight},
            {"threads", mSetup.threads},
            {"quick", mOptions.quick},
            {"visible_fov_deg", kVisibleFovDegrees},
            {"visible_aspect", kVisibleAspect},
            {"throughput_normals", mOptions.quick ? kThroughputQuickNormals : kThroughputNormals},
            {"occupancy_exhaustive_max_bits",
             mOptions.quick ? kOccupancyQuickExhaustiveBits : kOccupancyExhaustiveBits}};
}

} // namespace

NormalStudyResult runNormalStudy(const NormalStudyOptions& options, const Progress& progress) {
    const Setup setup = checkOptions(options);
    ensureWritableDirectory(options.out);
    std::filesystem::create_directories(options.out / "maps");
    NormalStudyResult result = StudyRun(options, setup, progress).run();
    if (progress)
        progress("writing normals.csv, normals.json");
    writeTextAtomically(options.out / "normals.csv", normalStudyCsv(result.rows));
    writeTextAtomically(options.out / "normals.json", result.json.dump(2) + "\n");
    if (options.plots) {
        if (progress)
            progress("plots (matplotlib)");
        runStudyPlots(options.python, setup.plotsScript, {"--out", options.out.string()},
                      "normals.csv and normals.json were written to " + options.out.string() +
                          " (--no-plots skips the plots)");
    }
    return result;
}

int runNormalStudyCommand(const NormalStudyOptions& options) {
    const auto start = Clock::now();
    auto progress = [&](const std::string& what) {
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        std::cerr << "[" << std::fixed << std::setprecision(1) << seconds << " s] " << what << "\n";
    };
    try {
        const NormalStudyResult result = runNormalStudy(options, progress);
        for (const std::string& warning : result.warnings)
            std::cerr << "testbed normals: warning: " << scenes::escapeControlCharacters(warning)
                      << "\n";
        printSummary(result, std::cout);
        std::cout << "outputs in " << std::filesystem::absolute(options.out).string() << "\n";
        return 0;
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

} // namespace experiments
