#include "experiments/render/RenderJob.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include <tbb/task_arena.h>

#include "experiments/compare/FlipMetric.h"
#include "experiments/render/CpuLoad.h"
#include "lighting/MultisampleShading.h"
#include "lighting/Oracle.h"
#include "lighting/StageRegistry.h"
#include "lighting/SupersampledReference.h"
#include "lighting/passes/PassNames.h"
#include "lighting/postaa/PostAa.h"

namespace experiments {

namespace {

using Clock = std::chrono::steady_clock;
using Progress = std::function<void(const std::string&)>;

constexpr const char* kReferenceStage = "reference";

double millisecondsSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The warm-up runs, then the timed repetitions of the G-buffer pass and the stage; run.result
// keeps the last repetition's image. Returns the timed passes, and sets run.metrics.cpuLoad from
// the process's CPU time and the wall time summed over the timed repetitions (each from its
// G-buffer pass to the end of its stage; the first run's G-buffer pass ran in PreparedScene's
// constructor, among the serial preparation of the scene, so without warm-up the first timed
// repetition counts its stage only).
std::vector<PassTiming> shadeRepetitions(RenderRun& run, lighting::ShadingStage& stage,
                                         bool exactSurface, lighting::postaa::PostAa postAa,
                                         const std::optional<lighting::ShadowSettings>& shadows,
                                         const Progress& step) {
    const RenderOptions& options = run.options;
    const int runs = options.warmup + options.repetitions;
    std::vector<PassTiming> passes;
    double cpuSeconds = 0.0, wallSeconds = 0.0;
    lighting::MultisampleShading multisampleShading;
    lighting::postaa::PostAaPass postAaPass(postAa); // scratch planes reused across repetitions
    for (int i = 0; i < runs; ++i) {
        const bool timed = i >= options.warmup;
        step(std::string(timed ? "" : "warm-up ") + "shading: " + options.stage +
             (runs > 1 ? " (" + std::to_string(i + 1) + "/" + std::to_string(runs) + ")" : ""));
        const double cpuStart = processCpuSeconds();
        const Clock::time_point wallStart = Clock::now();
        if (i > 0)
            run.prepared->renderGBuffer();
        const gbuffer::GBufferPassTimings& gbufferTimings = run.prepared->gbufferTimings;
        std::vector<std::pair<std::string, double>> repetition;
        repetition.emplace_back(lighting::pass::kGBuffer,
                                gbufferTimings.transformMs + gbufferTimings.rasterMs +
                                    gbufferTimings.layersMs + gbufferTimings.resolveMs);
        if (exactSurface)
            repetition.emplace_back(lighting::pass::kExactSurface, gbufferTimings.exactMs);
        if (shadows) {
            // Every frame renders its maps (a moving light or camera would need it): timed with
            // the frame, read by the stage through inputs.shadows.
            const Clock::time_point start = Clock::now();
            run.prepared->inputs.shadows = nullptr;
            lighting::ShadowMaps maps =
                lighting::ShadowMaps::render(run.prepared->scene, run.prepared->geometry,
                                             run.prepared->view, *shadows, run.shadowMaps.get());
            if (run.shadowMaps)
                *run.shadowMaps = std::move(maps); // the last frame's buffers, taken over
            else
                run.shadowMaps = std::make_unique<lighting::ShadowMaps>(std::move(maps));
            run.prepared->inputs.shadows = run.shadowMaps.get();
            repetition.emplace_back(lighting::pass::kShadowMaps, millisecondsSince(start));
        }
        lighting::StageResult result;
        multisampleShading.shade(stage, *run.prepared, result);
        if (postAa != lighting::postaa::PostAa::None) {
            lighting::PassTimer timer(result, lighting::pass::kPostAa);
            postAaPass.apply(*run.prepared->gbuffer, result.radiance, run.postAaEdges);
        }
        if (timed) {
            cpuSeconds += processCpuSeconds() - cpuStart;
            wallSeconds += std::chrono::duration<double>(Clock::now() - wallStart).count();
        }
        for (const auto& timing : result.timingsMs)
            repetition.push_back(timing);
        double total = 0.0;
        for (const auto& [name, ms] : repetition)
            total += ms;
        repetition.emplace_back(pass::kTotal, total);
        if (timed)
            addRepetition(passes, repetition);
        run.result = std::move(result);
    }
    run.metrics.cpuLoad = judgeCpuLoad(cpuSeconds, wallSeconds, run.threads,
                                       int(std::thread::hardware_concurrency()));
    return passes;
}

// Whether the run's G-buffer holds every channel the BRDF reads (the forward stages' holds depth
// alone: they shade while they rasterize).
bool holdsTheShadedSurface(const RenderRun& run) {
    const gbuffer::GBufferLayout& stored = run.prepared->gbuffer->layout();
    return stored.provides(gbuffer::Channel::Normal) && stored.provides(gbuffer::Channel::Albedo) &&
           stored.provides(gbuffer::Channel::Specular);
}

// The run's frame with a G-buffer that holds the surface the stage shades, for measurements that
// decode it per pixel (the oracles, the shadow misclassification): the stage's own G-buffer when
// it holds every channel the BRDF reads, else a lossless G-buffer of the same view, rendered now
// (what the forward stages shade: float attributes, no encoding). Single-sample frames; the
// lossless G-buffer lives as long as the struct.
struct ShadedSurface {
    lighting::StageInputs frame;
    std::unique_ptr<gbuffer::GBuffer> lossless;
};
ShadedSurface shadedSurface(const RenderRun& run) {
    ShadedSurface surface{run.prepared->inputs, nullptr};
    if (!holdsTheShadedSurface(run)) {
        surface.lossless = run.prepared->renderLosslessGBuffer();
        surface.frame.gbuffer = surface.lossless.get();
    }
    return surface;
}

// The oracle counts lights on the surface the stage shades: its G-buffer when that holds every
// channel the BRDF reads, else the lossless G-buffer (what forward stages shade).
void countOracle(RenderRun& run) {
    if (run.options.oracle == "visibility") {
        // Every light's visibility by ray, on the surface the stage shades (checkOptions refuses
        // multisampled frames).
        const lighting::shadows::RayShadows everyLight(
            run.prepared->scene, run.prepared->geometry, run.prepared->view,
            lighting::shadows::RayShadows::everyLightCasts(run.prepared->scene));
        const ShadedSurface surface = shadedSurface(run);
        run.oracleFromLosslessGBuffer = surface.lossless != nullptr;
        run.oracle = lighting::countVisibleLights(surface.frame, everyLight);
        return;
    }
    if (!run.result.lightsOracle.empty()) {
        run.oracle = run.result.lightsOracle;
        return;
    }
    if (run.prepared->multisample) {
        // Summed over the fragment layers, as the stage's evaluations are; on the stored layers
        // (the count is then on the lossy surfaces, like a stage's) when they hold what the BRDF
        // reads, else (the forward stages, which read no channel) on the layers of a lossless
        // multisampled frame of the same view: one more multisampled G-buffer pass.
        if (holdsTheShadedSurface(run)) {
            run.oracle = lighting::countContributingLightsOverLayers(*run.prepared);
            return;
        }
        run.oracleFromLosslessGBuffer = true;
        lighting::Multisampling multisampling;
        multisampling.samples = run.prepared->multisample->samples;
        multisampling.layers = run.prepared->multisample->options;
        const gbuffer::CameraView& view = run.prepared->view;
        const lighting::PreparedScene lossless(
            run.prepared->scene, view.width, view.height, false,
            gbuffer::GBufferLayout::lossless(view.depthConvention, view.infiniteFar),
            multisampling);
        run.oracle = lighting::countContributingLightsOverLayers(lossless);
        return;
    }
    const ShadedSurface surface = shadedSurface(run);
    run.oracleFromLosslessGBuffer = surface.lossless != nullptr;
    run.oracle = lighting::countContributingLights(surface.frame);
}

// The reference image of the run: the given one; at 1 sample per pixel the stage's own image
// when the stage is the reference, else rendered from the run's exact surface, computed now
// (after the timed passes) when the stage did not need it itself; at more samples the
// supersampled reference of the run's scene (lighting/SupersampledReference.h), even when the
// stage is `reference` itself (its image is then the 1-sample reference, measured against the
// same anti-aliased truth as every other stage).
// The run's ray-traced shadows (the reference's truth), built once when first needed.
const lighting::shadows::RayShadows& rayShadows(RenderRun& run,
                                                const lighting::ShadowSettings& settings) {
    if (!run.rayShadows)
        run.rayShadows = std::make_unique<lighting::shadows::RayShadows>(
            run.prepared->scene, run.prepared->geometry, run.prepared->view, settings);
    return *run.rayShadows;
}

void fillReference(RenderRun& run, const std::string& stageName,
                   const lighting::StageResult* givenReference,
                   const std::optional<lighting::ShadowSettings>& shadows) {
    if (givenReference) {
        run.reference = *givenReference;
    } else if (run.options.referenceSpp > 1) {
        run.reference = lighting::renderSupersampledReference(run.prepared->scene,
                                                              run.options.width, run.options.height,
                                                              run.options.referenceSpp, shadows);
    } else if (run.prepared->multisample) {
        // Not from this frame's exact surface (layer 0 only): the reference is its own render.
        run.reference = renderReference(run.options);
    } else if (stageName == kReferenceStage) {
        run.reference = run.result;
    } else {
        run.prepared->addExactSurface();
        lighting::StageInputs frame = run.prepared->inputs;
        if (shadows)
            frame.exactShadows = &rayShadows(run, *shadows);
        lighting::makeStage(kReferenceStage)->shade(frame, run.reference);
    }
}

// The anti-aliasing figures (RunMetrics.h), also for one-sample frames (1 surface per pixel).
void setMultisampleMetrics(RunMetrics& metrics, const lighting::PreparedScene& prepared) {
    const double pixels = double(prepared.gbuffer->pixelCount());
    metrics.gbufferBytes = metrics.bytesPerPixel * pixels;
    metrics.gbufferAllocatedBytes = metrics.allocatedBytesPerPixel * pixels;
    if (!prepared.multisample)
        return;
    const gbuffer::FragmentLayers& layers = prepared.multisample->layers;
    metrics.msaaSamples = layers.samples();
    metrics.complexFraction = layers.complexFraction();
    const auto& counts = layers.counts();
    metrics.surfacesPerCoveredPixel =
        counts.coveredPixels ? double(counts.fragments) / double(counts.coveredPixels) : 1.0;
    metrics.gbufferBytes = layers.storedBytes(metrics.bytesPerPixel);
    metrics.gbufferAllocatedBytes = layers.allocatedBytes(metrics.allocatedBytesPerPixel);
}

} // namespace

lighting::StageResult renderReference(const RenderOptions& options) {
    validate(options);
    lighting::StageResult reference;
    tbb::task_arena arena(effectiveThreads(options.threads));
    arena.execute([&] {
        reference = lighting::renderSupersampledReference(
            loadRequestedScene(options), options.width, options.height, options.referenceSpp,
            shadowSettings(options));
    });
    return reference;
}

RenderRun runRender(RenderPlan plan, const Progress& progress,
                    const lighting::StageResult* givenReference) {
    auto step = [&](const std::string& what) {
        if (progress)
            progress(what);
    };
    const RenderOptions& options = plan.options;
    checkMemoryEstimate(plan.memory); // before the G-buffer, the stage and the reference
    if (givenReference &&
        (givenReference->width != options.width || givenReference->height != options.height))
        throw UsageError("the given reference image is " + std::to_string(givenReference->width) +
                         "x" + std::to_string(givenReference->height) + ", the render " +
                         std::to_string(options.width) + "x" + std::to_string(options.height));
    const bool compare = options.compareReference || givenReference;
    RenderRun run;
    run.options = options;
    run.threads = plan.threads;
    run.memory = plan.memory;
    tbb::task_arena arena(run.threads);
    arena.execute([&] {
        step("G-buffer pass");
        // The exact surface only when the stage reads it: the reference's (compare) is computed
        // after the timed passes, so its work never inflates the stage's G-buffer time.
        lighting::Multisampling multisampling;
        multisampling.samples = options.msaa;
        gbuffer::parseComplexDetection(options.complexDetect, multisampling.layers.detection);
        multisampling.alphaToCoverage = options.alphaToCoverage == "on";
        run.prepared = std::make_unique<lighting::PreparedScene>(
            std::move(plan.scene), options.width, options.height, plan.requirements.exactSurface,
            plan.layout, multisampling);
        run.prepared->inputs.isa = plan.isa;
        run.prepared->inputs.simtWarpLanes = options.simtWarp;
        if (plan.shadows && plan.stage->name() == kReferenceStage) // it shadows by ray tracing
            run.prepared->inputs.exactShadows = &rayShadows(run, *plan.shadows);
        std::vector<PassTiming> passes = shadeRepetitions(
            run, *plan.stage, plan.requirements.exactSurface, plan.postAa, plan.shadows, step);
        run.coverage = measureCoverage(*run.prepared);

        // The oracle and the reference are measurement, not part of the stage: timed apart.
        step("counting contributing lights (oracle)");
        auto start = Clock::now();
        countOracle(run);
        const double oracleMs = millisecondsSince(start);
        std::optional<ErrorMetrics> error;
        double referenceMs = 0.0, flipMs = 0.0;
        if (compare) {
            step("reference (double precision, " + std::to_string(options.referenceSpp) + " spp)");
            start = Clock::now();
            fillReference(run, plan.stage->name(), givenReference, plan.shadows);
            referenceMs = millisecondsSince(start);
            if (plan.shadows && run.shadowMaps) {
                // On the surface the stage shades, as the oracle: the forward stages' G-buffer
                // holds depth alone, and its decoded normal would fail the facing test at random.
                step("shadow misclassification (one ray per pixel and casting light)");
                const ShadedSurface surface = shadedSurface(run);
                run.shadowError = lighting::shadows::measureShadowError(
                    surface.frame, rayShadows(run, *plan.shadows));
            }
            error = compareImages(run.result, run.reference);
            step("HDR-FLIP");
            start = Clock::now();
            FlipComparison flip = computeFlip(run.result, run.reference);
            flipMs = millisecondsSince(start);
            error->flip = flip.mean;
            error->flipWeightedMedian = flip.weightedMedian;
            error->flipP95 = flip.p95;
            error->flipP99 = flip.p99;
            error->flipUnavailable = flip.unavailableReason;
            run.flipMap = std::move(flip.errorMap);
            run.flipParameters = std::move(flip.parameters);
        }
        const gbuffer::GBufferLayout& layout = run.gbuffer().layout();
        const CpuLoad cpuLoad = run.metrics.cpuLoad;
        run.metrics = measureRun(std::move(passes), run.result.lightsEvaluated, run.oracle,
                                 run.result.lightingSamples, layout.bytesPerPixel(),
                                 layout.allocatedBytesPerPixel(), error);
        run.metrics.setSimtModel(run.result.parameters);
        setMultisampleMetrics(run.metrics, *run.prepared);
        run.metrics.cpuLoad = cpuLoad;
        if (run.shadowMaps)
            run.metrics.shadowMapBytes = double(run.shadowMaps->stats().totalBytes);
        if (run.shadowError)
            run.metrics.shadowMisclassified = run.shadowError->misclassifiedFraction();
        run.metrics.oracleMs = oracleMs;
        run.metrics.referenceMs = referenceMs;
        run.metrics.flipMs = flipMs;
        std::vector<uint32_t> covered;
        const gbuffer::GBuffer& gb = run.gbuffer();
        for (size_t pixel = 0; pixel < run.oracle.size(); ++pixel)
            if (gb.covered(pixel))
                covered.push_back(run.oracle[pixel]);
        if (!covered.empty()) {
            uint64_t sum = 0;
            for (uint32_t count : covered)
                sum += count;
            run.metrics.oracleLightsPerCoveredPixelMean = double(sum) / double(covered.size());
            const size_t rank = std::min(covered.size() - 1, size_t(0.99 * covered.size()));
            std::nth_element(covered.begin(), covered.begin() + rank, covered.end());
            run.metrics.oracleLightsPerCoveredPixelP99 = covered[rank];
        }
    });
    return run;
}

} // namespace experiments
