#include "experiments/RenderJob.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <tbb/task_arena.h>

#include "lighting/Oracle.h"
#include "lighting/StageRegistry.h"
#include "scenes/ProceduralScenes.h"
#include "scenes/SceneLoader.h"

namespace experiments {

namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

int effectiveThreads(int requested) {
    return requested > 0 ? requested : std::max(1, int(std::thread::hardware_concurrency()));
}

// The stage's radiance as a 3-channel float ImageBuf wrapping nothing: copied, planar to
// interleaved, because ImageBufAlgo works on interleaved pixels.
OIIO::ImageBuf toImageBuf(const lighting::StageResult& image) {
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buffer(spec);
    std::vector<float> interleaved(size_t(image.width) * image.height * 3);
    for (size_t i = 0; i < interleaved.size() / 3; ++i)
        for (int c = 0; c < 3; ++c) interleaved[3 * i + c] = image.radiance[c][i];
    buffer.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, interleaved.data());
    return buffer;
}

}  // namespace

void validate(const RenderOptions& options) {
    if (options.width <= 0 || options.height <= 0 || options.width > kMaxImageSide ||
        options.height > kMaxImageSide ||
        uint64_t(options.width) * uint64_t(options.height) > kMaxPixels)
        throw UsageError("image size " + std::to_string(options.width) + "x" +
                         std::to_string(options.height) + " refused: each side must be 1.." +
                         std::to_string(kMaxImageSide) + " and at most " +
                         std::to_string(kMaxPixels) + " pixels in all");
    if (options.lights < 0 || options.lights > kMaxLights)
        throw UsageError("--lights " + std::to_string(options.lights) + " refused: must be 0.." +
                         std::to_string(kMaxLights));
    if (options.threads < 0 || options.threads > kMaxThreads)
        throw UsageError("--threads " + std::to_string(options.threads) +
                         " refused: must be 0 (all) .. " + std::to_string(kMaxThreads));
    lighting::makeStage(options.stage);  // throws StageError listing the valid names
    if (!scenes::isProceduralScene(options.scene)) {
        const std::filesystem::path path(options.scene);
        const std::string extension = path.extension().string();
        if (extension != ".gltf" && extension != ".glb" && extension != ".json") {
            std::string names;
            for (const std::string& name : scenes::proceduralSceneNames())
                names += (names.empty() ? "" : ", ") + name;
            throw UsageError("unknown scene '" + options.scene + "': not a built-in scene (" +
                             names + ") nor a .gltf/.glb/.json file");
        }
        if (!std::filesystem::is_regular_file(path))
            throw UsageError("scene file '" + options.scene + "' not found");
    }
}

namespace {

template <typename Number>
Number parseNumber(const std::string& key, const std::string& value) {
    Number number{};
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
    if (error != std::errc() || end != value.data() + value.size())
        throw UsageError("option '" + key + "': '" + value + "' is not a valid number");
    return number;
}

}  // namespace

std::vector<std::string> renderOptionKeys() {
    return {"scene", "stage",  "lights", "seed",   "width",    "height",
            "resolution", "threads", "layout", "normals", "depth", "position",
            "scene-option.<key>"};
}

void setRenderOption(RenderOptions& options, const std::string& key, const std::string& value) {
    static const std::string kSceneOption = "scene-option.";
    if (key == "scene") options.scene = value;
    else if (key == "stage") options.stage = value;
    else if (key == "lights") options.lights = parseNumber<int>(key, value);
    else if (key == "seed") options.seed = parseNumber<uint64_t>(key, value);
    else if (key == "width") options.width = parseNumber<int>(key, value);
    else if (key == "height") options.height = parseNumber<int>(key, value);
    else if (key == "threads") options.threads = parseNumber<int>(key, value);
    else if (key == "layout") options.layout = value;
    else if (key == "normals") options.normals = value;
    else if (key == "depth") options.depth = value;
    else if (key == "position") options.position = value;
    else if (key == "resolution") {
        const size_t x = value.find('x');
        if (x == std::string::npos) throw UsageError("option 'resolution': '" + value + "' is not WIDTHxHEIGHT");
        options.width = parseNumber<int>(key, value.substr(0, x));
        options.height = parseNumber<int>(key, value.substr(x + 1));
    } else if (key.rfind(kSceneOption, 0) == 0 && key.size() > kSceneOption.size()) {
        options.sceneOptions[key.substr(kSceneOption.size())] = value;
    } else {
        std::string keys;
        for (const std::string& k : renderOptionKeys()) keys += (keys.empty() ? "" : ", ") + k;
        throw UsageError("unknown render option '" + key + "'; valid: " + keys);
    }
}

uint64_t RenderRun::lightEvaluations() const {
    uint64_t sum = 0;
    for (uint32_t count : result.lightsEvaluated) sum += count;
    return sum;
}

uint64_t RenderRun::oracleLightEvaluations() const {
    uint64_t sum = 0;
    for (uint32_t count : oracle) sum += count;
    return sum;
}

ErrorMetrics compareImages(const lighting::StageResult& image, const lighting::StageResult& reference) {
    const OIIO::ImageBuf a = toImageBuf(image), b = toImageBuf(reference);
    const auto comparison = OIIO::ImageBufAlgo::compare(a, b, 0.0f, 0.0f);
    const auto referenceStats = OIIO::ImageBufAlgo::computePixelStats(b);
    double peak = 0.0, sumSquares = 0.0;
    for (int c = 0; c < 3; ++c) {
        peak = std::max(peak, double(referenceStats.max[size_t(c)]));
        const double rms = referenceStats.stddev[size_t(c)], mean = referenceStats.avg[size_t(c)];
        sumSquares += rms * rms + mean * mean;
    }
    ErrorMetrics metrics;
    metrics.rmse = comparison.rms_error;
    metrics.maxAbs = comparison.maxerror;
    const double referenceRms = std::sqrt(sumSquares / 3.0);
    metrics.relativeRmse = referenceRms > 0.0 ? metrics.rmse / referenceRms : 0.0;
    metrics.psnr = metrics.rmse > 0.0 && peak > 0.0 ? 20.0 * std::log10(peak / metrics.rmse)
                                                    : std::numeric_limits<double>::infinity();
    return metrics;
}

RenderRun runRender(const RenderOptions& options,
                    const std::function<void(const std::string&)>& progress) {
    auto step = [&](const std::string& what) {
        if (progress) progress(what);
    };
    validate(options);
    RenderRun run;
    run.options = options;
    run.threads = effectiveThreads(options.threads);
    tbb::task_arena arena(run.threads);
    arena.execute([&] {
        step("loading scene " + options.scene);
        scenes::SceneRequest request;
        request.lightCount = options.lights;
        request.seed = options.seed;
        request.options = options.sceneOptions;
        scenes::Scene scene = scenes::loadScene(options.scene, request);
        std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(options.stage);
        const lighting::StageRequirements needs = stage->requirements();

        step("G-buffer pass");
        run.prepared = std::make_unique<lighting::PreparedFrame>(
            std::move(scene), options.width, options.height, needs.exactSurface || options.compareReference);
        const gbuffer::GBufferPassTimings& passTimings = run.prepared->gbufferTimings;
        run.timingsMs.emplace_back("gbuffer", passTimings.transformMs + passTimings.rasterMs + passTimings.resolveMs);
        if (needs.exactSurface) run.timingsMs.emplace_back("exact_surface", passTimings.exactMs);
        const lighting::Frame& frame = run.prepared->frame;
        step("shading: " + options.stage);
        stage->shade(frame, run.result);
        for (const auto& timing : run.result.timingsMs) run.timingsMs.push_back(timing);
        double total = 0.0;
        for (const auto& [pass, ms] : run.timingsMs) total += ms;
        run.timingsMs.emplace_back("total", total);

        // The oracle and the reference are measurement, not part of the stage: timed apart.
        step("counting contributing lights (oracle)");
        auto start = Clock::now();
        run.oracle = run.result.lightsOracle.empty() ? lighting::countContributingLights(frame)
                                                     : run.result.lightsOracle;
        run.oracleMs = millisecondsSince(start);
        if (options.compareReference) {
            step("reference (double precision)");
            start = Clock::now();
            if (stage->name() == "reference") {
                run.reference = run.result;
            } else {
                lighting::makeStage("reference")->shade(frame, run.reference);
            }
            run.referenceMs = millisecondsSince(start);
            run.error = compareImages(run.result, run.reference);
        }
    });
    return run;
}

}  // namespace experiments
