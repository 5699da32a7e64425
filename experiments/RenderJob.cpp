#include "experiments/RenderJob.h"

#include <algorithm>
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
        for (int c = 0; c < 3; ++c)
            interleaved[3 * i + c] = image.radiance[c][i];
    buffer.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, interleaved.data());
    return buffer;
}

} // namespace

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
    lighting::makeStage(options.stage); // throws StageError listing the valid names
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
    if (options.warmup < 0 || options.warmup > kMaxRepetitions || options.repetitions < 1 ||
        options.repetitions > kMaxRepetitions)
        throw UsageError("--warmup " + std::to_string(options.warmup) + " / --repetitions " +
                         std::to_string(options.repetitions) + " refused: warmup 0.." +
                         std::to_string(kMaxRepetitions) + ", repetitions 1.." +
                         std::to_string(kMaxRepetitions));
    layoutRequest(options); // throws UsageError for bad encodings, formats or presets
}

gbuffer::LayoutRequest layoutRequest(const RenderOptions& options) {
    gbuffer::LayoutRequest request;
    try {
        if (!options.layout.empty()) {
            const std::vector<std::string> presets = gbuffer::layoutPresetNames();
            if (std::find(presets.begin(), presets.end(), options.layout) == presets.end()) {
                std::string valid;
                for (const std::string& preset : presets)
                    valid += (valid.empty() ? "" : ", ") + preset;
                throw std::invalid_argument("unknown G-buffer layout '" + options.layout +
                                            "'; valid: " + valid);
            }
            request.preset = options.layout;
        }
        if (!options.normals.empty())
            request.normals = gbuffer::NormalCodecSpec::parse(options.normals);
        if (!options.depth.empty())
            request.depth = gbuffer::DepthFormatSpec::parse(options.depth);
        if (!options.position.empty())
            request.position = gbuffer::parsePositionMethod(options.position);
        if (!options.normalSpace.empty())
            request.normalSpace = gbuffer::parseNormalSpace(options.normalSpace);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    return request;
}

double PassTiming::medianMs() const {
    if (samplesMs.empty())
        return 0.0;
    std::vector<double> sorted = samplesMs;
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}
double PassTiming::minMs() const {
    return samplesMs.empty() ? 0.0 : *std::min_element(samplesMs.begin(), samplesMs.end());
}
double PassTiming::maxMs() const {
    return samplesMs.empty() ? 0.0 : *std::max_element(samplesMs.begin(), samplesMs.end());
}

namespace {

template <typename Number> Number parseNumber(const std::string& key, const std::string& value) {
    Number number{};
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
    if (error != std::errc() || end != value.data() + value.size())
        throw UsageError("option '" + key + "': '" + value + "' is not a valid number");
    return number;
}

} // namespace

std::vector<std::string> renderOptionKeys() {
    return {
        "scene",   "stage",  "lights",  "seed",         "width", "height",   "resolution",
        "threads", "layout", "normals", "normal-space", "depth", "position", "scene-option.<key>"};
}

void setRenderOption(RenderOptions& options, const std::string& key, const std::string& value) {
    static const std::string kSceneOption = "scene-option.";
    if (key == "scene")
        options.scene = value;
    else if (key == "stage")
        options.stage = value;
    else if (key == "lights")
        options.lights = parseNumber<int>(key, value);
    else if (key == "seed")
        options.seed = parseNumber<uint64_t>(key, value);
    else if (key == "width")
        options.width = parseNumber<int>(key, value);
    else if (key == "height")
        options.height = parseNumber<int>(key, value);
    else if (key == "threads")
        options.threads = parseNumber<int>(key, value);
    else if (key == "layout")
        options.layout = value;
    else if (key == "normals")
        options.normals = value;
    else if (key == "normal-space")
        options.normalSpace = value;
    else if (key == "depth")
        options.depth = value;
    else if (key == "position")
        options.position = value;
    else if (key == "resolution") {
        const size_t x = value.find('x');
        if (x == std::string::npos)
            throw UsageError("option 'resolution': '" + value + "' is not WIDTHxHEIGHT");
        options.width = parseNumber<int>(key, value.substr(0, x));
        options.height = parseNumber<int>(key, value.substr(x + 1));
    } else if (key.rfind(kSceneOption, 0) == 0 && key.size() > kSceneOption.size()) {
        options.sceneOptions[key.substr(kSceneOption.size())] = value;
    } else {
        std::string keys;
        for (const std::string& k : renderOptionKeys())
            keys += (keys.empty() ? "" : ", ") + k;
        throw UsageError("unknown render option '" + key + "'; valid: " + keys);
    }
}

uint64_t RenderRun::lightEvaluations() const {
    uint64_t sum = 0;
    for (uint32_t count : result.lightsEvaluated)
        sum += count;
    return sum;
}

uint64_t RenderRun::oracleLightEvaluations() const {
    uint64_t sum = 0;
    for (uint32_t count : oracle)
        sum += count;
    return sum;
}

ErrorMetrics compareImages(const lighting::StageResult& image,
                           const lighting::StageResult& reference) {
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
    // Mean and percentile of |a - b| over every pixel and channel: the difference image comes from
    // ImageBufAlgo; the percentile is a selection over its values.
    const OIIO::ImageBuf difference = OIIO::ImageBufAlgo::absdiff(a, b);
    const auto differenceStats = OIIO::ImageBufAlgo::computePixelStats(difference);
    double meanDifference = 0.0, meanReference = 0.0;
    for (int c = 0; c < 3; ++c) {
        meanDifference += differenceStats.avg[size_t(c)] / 3.0;
        meanReference += std::abs(double(referenceStats.avg[size_t(c)])) / 3.0;
    }
    metrics.relativeMean = meanReference > 0.0 ? meanDifference / meanReference : 0.0;
    std::vector<float> values(size_t(image.width) * image.height * 3);
    difference.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, values.data());
    if (!values.empty()) {
        const size_t rank =
            std::min(values.size() - 1, size_t(std::ceil(0.99 * double(values.size()))) - 1);
        std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(rank), values.end());
        metrics.p99Abs = values[rank];
    }
    return metrics;
}

namespace {

scenes::Scene loadRequestedScene(const RenderOptions& options) {
    scenes::SceneRequest request;
    request.lightCount = options.lights;
    request.seed = options.seed;
    request.options = options.sceneOptions;
    return scenes::loadScene(options.scene, request);
}

// Adds one repetition's pass times to `timings`, keeping the passes' first-seen order and
// summing a pass that a stage reports twice.
void addRepetition(std::vector<PassTiming>& timings,
                   const std::vector<std::pair<std::string, double>>& passes) {
    std::vector<std::pair<std::string, double>> merged;
    for (const auto& [pass, ms] : passes) {
        auto it = std::find_if(merged.begin(), merged.end(),
                               [&](const auto& m) { return m.first == pass; });
        if (it == merged.end())
            merged.emplace_back(pass, ms);
        else
            it->second += ms;
    }
    for (const auto& [pass, ms] : merged) {
        auto it = std::find_if(timings.begin(), timings.end(),
                               [&](const PassTiming& t) { return t.pass == pass; });
        if (it == timings.end()) {
            timings.push_back({pass, {}});
            it = timings.end() - 1;
        }
        it->samplesMs.push_back(ms);
    }
}

} // namespace

gbuffer::GBufferLayout renderLayout(const RenderOptions& options) {
    validate(options);
    const scenes::Scene scene = loadRequestedScene(options);
    const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(options.stage);
    try {
        return gbuffer::makeLayout(scene, stage->requirements().channels, stage->name(),
                                   layoutRequest(options));
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
}

lighting::StageResult renderReference(const RenderOptions& options) {
    validate(options);
    lighting::StageResult reference;
    tbb::task_arena arena(effectiveThreads(options.threads));
    arena.execute([&] {
        lighting::PreparedScene frame(loadRequestedScene(options), options.width, options.height,
                                      true);
        lighting::makeStage("reference")->shade(frame.inputs, reference);
    });
    return reference;
}

RenderRun runRender(const RenderOptions& options,
                    const std::function<void(const std::string&)>& progress,
                    const lighting::StageResult* givenReference) {
    auto step = [&](const std::string& what) {
        if (progress)
            progress(what);
    };
    validate(options);
    if (givenReference &&
        (givenReference->width != options.width || givenReference->height != options.height))
        throw UsageError("the given reference image is " + std::to_string(givenReference->width) +
                         "x" + std::to_string(givenReference->height) + ", the render " +
                         std::to_string(options.width) + "x" + std::to_string(options.height));
    const bool compare = options.compareReference || givenReference;
    RenderRun run;
    run.options = options;
    run.threads = effectiveThreads(options.threads);
    tbb::task_arena arena(run.threads);
    arena.execute([&] {
        step("loading scene " + options.scene);
        scenes::Scene scene = loadRequestedScene(options);
        std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(options.stage);
        const lighting::StageRequirements needs = stage->requirements();
        gbuffer::GBufferLayout layout;
        try {
            layout =
                gbuffer::makeLayout(scene, needs.channels, stage->name(), layoutRequest(options));
        } catch (const std::invalid_argument& e) {
            throw UsageError(e.what());
        }

        step("G-buffer pass");
        const bool needExact = needs.exactSurface || (compare && !givenReference);
        run.prepared = std::make_unique<lighting::PreparedScene>(std::move(scene), options.width,
                                                                 options.height, needExact, layout);
        const lighting::StageInputs& frame = run.prepared->inputs;
        const int runs = options.warmup + options.repetitions;
        for (int i = 0; i < runs; ++i) {
            const bool timed = i >= options.warmup;
            step(std::string(timed ? "" : "warm-up ") + "shading: " + options.stage +
                 (runs > 1 ? " (" + std::to_string(i + 1) + "/" + std::to_string(runs) + ")" : ""));
            if (i > 0)
                run.prepared->renderGBuffer();
            const gbuffer::GBufferPassTimings& passTimings = run.prepared->gbufferTimings;
            std::vector<std::pair<std::string, double>> passes;
            passes.emplace_back("gbuffer", passTimings.transformMs + passTimings.rasterMs +
                                               passTimings.resolveMs);
            if (needs.exactSurface)
                passes.emplace_back("exact_surface", passTimings.exactMs);
            lighting::StageResult result;
            stage->shade(frame, result);
            for (const auto& timing : result.timingsMs)
                passes.push_back(timing);
            double total = 0.0;
            for (const auto& [pass, ms] : passes)
                total += ms;
            passes.emplace_back("total", total);
            if (timed)
                addRepetition(run.passTimings, passes);
            run.result = std::move(result);
        }
        for (const PassTiming& timing : run.passTimings)
            run.timingsMs.emplace_back(timing.pass, timing.medianMs());

        // The oracle and the reference are measurement, not part of the stage: timed apart. The
        // oracle counts lights on the surface the stage shades: its G-buffer when that holds every
        // channel the BRDF reads, else the lossless G-buffer (what forward stages shade).
        step("counting contributing lights (oracle)");
        auto start = Clock::now();
        if (!run.result.lightsOracle.empty()) {
            run.oracle = run.result.lightsOracle;
        } else {
            const gbuffer::GBufferLayout& stored = run.prepared->gbuffer->layout();
            const bool complete = stored.provides(gbuffer::Channel::Normal) &&
                                  stored.provides(gbuffer::Channel::Albedo) &&
                                  stored.provides(gbuffer::Channel::Specular);
            if (complete) {
                run.oracle = lighting::countContributingLights(frame);
            } else {
                run.oracleFromLosslessGBuffer = true;
                const std::unique_ptr<gbuffer::GBuffer> lossless =
                    run.prepared->renderLosslessGBuffer();
                lighting::StageInputs losslessFrame = frame;
                losslessFrame.gbuffer = lossless.get();
                run.oracle = lighting::countContributingLights(losslessFrame);
            }
        }
        run.oracleMs = millisecondsSince(start);
        if (compare) {
            step("reference (double precision)");
            start = Clock::now();
            if (givenReference) {
                run.reference = *givenReference;
            } else if (stage->name() == "reference") {
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

} // namespace experiments
