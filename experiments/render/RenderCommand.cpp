#include "experiments/render/RenderCommand.h"

#include "scenes/procedural/LightGenerator.h"

#include "experiments/BuildCommit.h"
#include "experiments/compare/FlipMetric.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <tbb/parallel_for.h>

#include "experiments/CommandErrors.h"
#include "experiments/output/AtomicFile.h"
#include "experiments/output/ImageOutput.h"
#include "experiments/output/JsonText.h"
#include "experiments/output/Progress.h"
#include "experiments/output/StagedFolder.h"
#include "experiments/render/LightOrigins.h"
#include "lighting/StageRegistry.h"
#include "lighting/SupersampledReference.h"
#include "lighting/passes/PassNames.h"
#include "lighting/postaa/PostAa.h"
#include "scenes/Scene.h"
#include "scenes/Viewpoints.h"
#include "scenes/input/MessageText.h"

namespace experiments {

namespace {

// Decoded G-buffer layers for the EXR: what the stage read, after its layout's encodings.
// Z is view-space depth in metres (positive, along the view direction), 0 = background; a
// channel the layout does not provide is not written.
struct DecodedLayers {
    std::vector<float> z;
    std::vector<float> normal[3];
    std::vector<float> albedo[3];
};

DecodedLayers decodeLayers(const gbuffer::GBuffer& gb) {
    const size_t n = gb.pixelCount();
    const gbuffer::GBufferLayout& layout = gb.layout();
    DecodedLayers layers;
    layers.z.assign(n, 0.0f);
    const bool normals = layout.provides(gbuffer::Channel::Normal);
    const bool albedo = layout.provides(gbuffer::Channel::Albedo);
    for (int c = 0; c < 3; ++c) {
        if (normals)
            layers.normal[c].assign(n, 0.0f);
        if (albedo)
            layers.albedo[c].assign(n, 0.0f);
    }
    tbb::parallel_for(0, gb.height(), [&](int y) {
        for (int x = 0; x < gb.width(); ++x) {
            const size_t pixel = size_t(y) * gb.width() + x;
            if (!gb.covered(pixel))
                continue;
            const gbuffer::Surface s = gb.decode(x, y);
            layers.z[pixel] = -s.positionView.z;
            for (int c = 0; c < 3; ++c) {
                if (normals)
                    layers.normal[c][pixel] = s.normalView[c];
                if (albedo)
                    layers.albedo[c][pixel] = s.albedo[c];
            }
        }
    });
    return layers;
}

std::vector<float> toFloat(const std::vector<uint32_t>& counts) {
    return std::vector<float>(counts.begin(), counts.end());
}

// |image - reference| per channel, through ImageBufAlgo; empty planes without a reference.
std::array<std::vector<float>, 3> errorPlanes(const RenderRun& run) {
    std::array<std::vector<float>, 3> planes;
    if (!run.metrics.error)
        return planes;
    runImageLibraryOnTheCallingThread();
    const int w = run.result.width, h = run.result.height;
    auto toBuffer = [&](const lighting::StageResult& image) {
        OIIO::ImageBuf buffer(OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT));
        for (int c = 0; c < 3; ++c)
            buffer.set_pixels(OIIO::ROI(0, w, 0, h, 0, 1, c, c + 1), OIIO::TypeDesc::FLOAT,
                              image.radiance[c].data());
        return buffer;
    };
    const OIIO::ImageBuf difference =
        OIIO::ImageBufAlgo::absdiff(toBuffer(run.result), toBuffer(run.reference));
    for (int c = 0; c < 3; ++c) {
        planes[size_t(c)].resize(size_t(w) * h);
        difference.get_pixels(OIIO::ROI(0, w, 0, h, 0, 1, c, c + 1), OIIO::TypeDesc::FLOAT,
                              planes[size_t(c)].data());
    }
    return planes;
}

// The largest channel error per pixel (what error.png shows).
std::vector<float> largestChannelError(const std::array<std::vector<float>, 3>& error) {
    std::vector<float> values(error[0].size());
    for (size_t i = 0; i < values.size(); ++i)
        values[i] = std::max({error[0][i], error[1][i], error[2][i]});
    return values;
}

// What the printed and recorded pass times are: a single timed run is one frame (a cold one
// without warm-up: caches, page faults and the thread pool's start included), several are
// summarised by their median and range.
std::string timingFigure(const RenderOptions& options) {
    const std::string warmup = options.warmup > 0
                                   ? " after " + std::to_string(options.warmup) + " warm-up run" +
                                         (options.warmup > 1 ? "s" : "")
                                   : "";
    if (options.repetitions <= 1)
        return options.warmup > 0 ? "one frame" + warmup
                                  : "cold frame (no warm-up, one repetition)";
    return "median of " + std::to_string(options.repetitions) + " (min\u2013max)" + warmup;
}

// What `testbed render` prints when done: the run, its pass medians, the error, the files. Text
// that an input controls (the scene's name, a warning quoting a file, the output paths, which are
// bytes) is printed escaped, so that it cannot forge a line or drive the terminal.
void printSummary(const RenderRun& run, const std::filesystem::path& out,
                  const std::vector<std::string>& written) {
    std::cout << "testbed: " << run.options.stage << " on "
              << scenes::escapeControlCharacters(run.scene().name) << " ("
              << run.scene().triangleCount() << " triangles, " << run.scene().lights.size()
              << " lights) at " << run.options.width << "x" << run.options.height << ", "
              << run.threads << " threads\n";
    std::cout << "  lights: " << lightOrigins(run.options, run.scene()).summary() << "\n";
    const bool several = run.options.repetitions > 1;
    std::cout << "  timings: " << timingFigure(run.options) << "; CPU " << std::fixed
              << std::setprecision(2) << run.metrics.cpuLoad.cpuWallRatio
              << " s per wall second on " << run.threads << " threads"
              << (run.metrics.cpuLoad.loaded ? " (loaded machine: see the warning)" : "") << "\n";
    for (const PassTiming& timing : run.metrics.passes) {
        std::cout << "  " << timing.pass << ": " << std::fixed << std::setprecision(2)
                  << timing.medianMs() << " ms";
        if (several)
            std::cout << " (" << timing.minMs() << "\u2013" << timing.maxMs() << ")";
        std::cout << "\n";
    }
    if (const std::optional<ErrorMetrics>& error = run.metrics.error) {
        std::cout << "  error vs reference: rmse " << std::scientific << error->rmse << ", max_abs "
                  << error->maxAbs << ", p99_abs " << error->p99Abs << ", relative rmse "
                  << error->relativeRmse << "\n";
        if (const std::string note = errorConcentrationNote(*error); !note.empty())
            std::cout << "    (" << note << ")\n";
        if (const std::string note = nonFiniteNote(*error); !note.empty())
            std::cout << "  WARNING: " << note << "\n";
        if (error->flip)
            std::cout << "  HDR-FLIP: mean " << std::fixed << std::setprecision(4) << *error->flip
                      << ", weighted median " << error->flipWeightedMedian.value_or(0.0) << ", p95 "
                      << error->flipP95.value_or(0.0) << ", p99 " << error->flipP99.value_or(0.0)
                      << std::defaultfloat << "\n";
        else
            std::cout << "  HDR-FLIP: unavailable: " << error->flipUnavailable << "\n";
    }
    if (!run.metrics.lightCountsNote.empty())
        std::cout << "  light counts: " << run.metrics.lightCountsNote << "\n";
    if (!run.coverage.warning.empty())
        std::cout << "  WARNING: " << scenes::escapeControlCharacters(run.coverage.warning) << "\n";
    std::cout << "outputs in "
              << scenes::escapeControlCharacters(std::filesystem::absolute(out).string()) << ":\n";
    for (const std::string& file : renderOutputNames())
        if (std::find(written.begin(), written.end(), file) != written.end())
            std::cout << "  " << scenes::escapeControlCharacters((out / file).string()) << "\n";
}

// shadow-error.png: the render's luminance dimmed to grey, with the pixels where the shadow maps
// disagree with the ray-traced truth for at least one casting light painted over: red where a
// light reaches that should be shadowed (leaks, peter-panning, missing casters), blue where a
// light is shadowed that should reach (acne, over-filtering), magenta where both.
void writeShadowErrorPng(const std::filesystem::path& path, const RenderRun& run) {
    const int w = run.options.width, h = run.options.height;
    const lighting::shadows::ShadowErrorCounts& error = *run.shadowError;
    std::vector<float> planes[3];
    for (std::vector<float>& plane : planes)
        plane.resize(size_t(w) * size_t(h));
    for (size_t i = 0; i < planes[0].size(); ++i) {
        const float grey =
            0.25f * (0.2126f * run.result.radiance[0][i] + 0.7152f * run.result.radiance[1][i] +
                     0.0722f * run.result.radiance[2][i]);
        const float shown = std::isfinite(grey) ? std::min(grey, 0.25f) : 0.0f;
        const bool leak = error.litShouldBeShadowedAt[i] > 0;
        const bool acne = error.shadowedShouldBeLitAt[i] > 0;
        planes[0][i] = leak ? 8.0f : shown;
        planes[1][i] = leak || acne ? 0.0f : shown;
        planes[2][i] = acne ? 8.0f : shown;
    }
    writePreviewPng(path, w, h, planes[0].data(), planes[1].data(), planes[2].data());
}

// The shadows block of stats.json (`--shadows maps`): the settings, the maps' cost (faces, bytes,
// render time of the last repetition per light and in all; the pass shadow_maps in the timings is
// the median over repetitions) and, for compared runs, the misclassification against the rays.
nlohmann::json shadowsJson(const RenderRun& run) {
    if (!run.shadowMaps)
        return {{"mode", "off"}};
    const lighting::ShadowMaps& maps = *run.shadowMaps;
    const lighting::ShadowSettings& settings = maps.settings();
    const lighting::ShadowStats& stats = maps.stats();
    nlohmann::json lights = nlohmann::json::array();
    for (const lighting::ShadowLightStats& light : stats.lights)
        lights.push_back({{"light", light.lightIndex},
                          {"faces", light.faceCount},
                          {"faces_outside_view", light.facesOutsideView},
                          {"bytes", light.bytes},
                          {"triangles_drawn", light.trianglesDrawn},
                          {"caster_objects", light.casterObjects},
                          {"light_in_frustum", light.lightInFrustum},
                          {"render_ms", light.renderMs},
                          // The light's effective settings: the global ones below, with a
                          // scene light's own "shadow" over them.
                          {"map_size", light.settings.mapSize},
                          {"bias_constant_m", light.settings.biasConstant},
                          {"bias_slope_texels", light.settings.biasSlope},
                          {"normal_offset_texels", light.settings.normalOffset},
                          {"filter", lighting::formatShadowFilter(light.settings.filter)}});
    uint64_t casterObjects = 0;
    for (const lighting::ShadowLightStats& light : stats.lights)
        casterObjects += light.casterObjects;
    nlohmann::json shadows = {
        {"mode", "maps"},
        {"map_size", settings.mapSize},
        {"bias_constant_m", settings.biasConstant},
        {"bias_slope_texels", settings.biasSlope},
        {"normal_offset_texels", settings.normalOffset},
        {"filter", lighting::formatShadowFilter(settings.filter)},
        {"point_projection", lighting::formatShadowPointProjection(settings.pointProjection)},
        {"depth_format", lighting::formatShadowDepthFormat(settings.depthFormat)},
        {"cascades", settings.cascades},
        {"shadow_lights", run.options.shadowLights},
        {"casting_lights", stats.castingLightCount},
        {"lights_with_maps", maps.shadowCount()},
        {"faces", stats.faceCount},
        {"faces_outside_view", stats.facesOutsideView},
        {"caster_sets", settings.casterSets},
        {"objects", stats.objectCount},
        {"caster_objects_per_light",
         stats.lights.empty() ? 0.0 : double(casterObjects) / double(stats.lights.size())},
        // The same as a fraction of the scene's objects (issue 29's target: <= 10% on average).
        {"caster_objects_fraction",
         stats.lights.empty() || stats.objectCount == 0
             ? 0.0
             : double(casterObjects) / (double(stats.lights.size()) * double(stats.objectCount))},
        {metric::kShadowMapBytes, stats.totalBytes},
        {"render_ms", stats.renderMs},
        {"per_light", lights}};
    if (run.rayShadows)
        shadows["ray_bvh"] = {
            {"triangles", run.rayShadows->rays().triangleCount()},
            {"alpha_tested_triangles", run.rayShadows->rays().alphaTestedTriangleCount()},
            {"build_ms", run.rayShadows->rays().buildMilliseconds()},
            {"bytes", run.rayShadows->rays().embreeBytes()}};
    if (run.shadowError) {
        const lighting::shadows::ShadowErrorCounts& error = *run.shadowError;
        const double pairs = double(std::max<uint64_t>(error.pairs, 1));
        shadows["misclassification"] = {
            {"pixel_light_pairs", error.pairs},
            {"truth_shadowed_pairs", error.truthShadowed},
            {"lit_should_be_shadowed", error.litShouldBeShadowed},
            {"shadowed_should_be_lit", error.shadowedShouldBeLit},
            {"lit_should_be_shadowed_fraction", double(error.litShouldBeShadowed) / pairs},
            {"shadowed_should_be_lit_fraction", double(error.shadowedShouldBeLit) / pairs},
            {metric::kShadowMisclassified, error.misclassifiedFraction()}};
    }
    return shadows;
}

// Per pixel of a multisampled frame, the surfaces shaded there when the pixel is complex (a
// background sample counts as none), 0 at simple and background pixels; empty without MSAA.
std::vector<float> complexMap(const RenderRun& run) {
    const gbuffer::MultisampleTarget* target = run.prepared->multisample.get();
    if (!target)
        return {};
    const gbuffer::FragmentLayers& layers = target->layers;
    std::vector<float> map(layers.pixelCount(), 0.0f);
    for (size_t pixel = 0; pixel < map.size(); ++pixel) {
        if (!layers.complex(pixel))
            continue;
        for (int k = 0; k < layers.layerCount(); ++k)
            map[pixel] += layers.codes(k)[pixel] != gbuffer::VisibilityPass::kNoTriangle;
    }
    return map;
}

} // namespace

ScalarMapStyle errorMapStyle(const RenderOutputScales& scales) {
    ScalarMapStyle style;
    style.scale = scales.errorScale;
    style.max = scales.errorMax;
    style.colourMap = "turbo";
    style.title = std::string("|render - reference|, largest of R,G,B (") +
                  mapScaleName(scales.errorScale) + " scale)";
    return style;
}

void checkOutputScales(const RenderOutputScales& scales) {
    if (const std::string problem = scaleMaximumProblem(scales.errorMax); !problem.empty())
        throw UsageError("--error-max " + (std::ostringstream() << scales.errorMax).str() +
                         " refused: " + problem);
}

const std::vector<std::string>& renderOutputNames() {
    static const std::vector<std::string> names = {"render.exr",  "preview.png",      "heatmap.png",
                                                   "error.png",   "reference.png",    "flip.png",
                                                   "complex.png", "shadow-error.png", "stats.json"};
    return names;
}

std::vector<std::string> writeRenderOutputs(const RenderRun& run, const std::filesystem::path& dir,
                                            const RenderOutputScales& scales) {
    checkOutputScales(scales);
    std::vector<std::string> written;
    const gbuffer::GBuffer& gb = run.gbuffer();
    const int w = gb.width(), h = gb.height();
    const nlohmann::json stats = statsJson(run);
    const DecodedLayers layers = decodeLayers(gb);
    const std::vector<float> evaluated = toFloat(run.result.lightsEvaluated);
    const std::vector<float> oracle = toFloat(run.oracle);
    // Evaluations that added nothing: the culling stage's waste at each pixel it lit (a
    // reduced-resolution stage lights only its samples: 0 at the pixels it filtered).
    const std::vector<uint8_t>& lit = run.result.lightingSamples;
    std::vector<float> wasted(evaluated.size());
    for (size_t pixel = 0; pixel < wasted.size(); ++pixel)
        wasted[pixel] = lit.empty() || lit[pixel] ? evaluated[pixel] - oracle[pixel] : 0.0f;
    const std::array<std::vector<float>, 3> error = errorPlanes(run);
    std::vector<ImagePlane> planes = {
        {"R", run.result.radiance[0].data()},   {"G", run.result.radiance[1].data()},
        {"B", run.result.radiance[2].data()},   {"Z", layers.z.data()},
        {"lights.evaluated", evaluated.data()}, {"lights.oracle", oracle.data()},
        {"lights.wasted", wasted.data()},
    };
    const char* xyz[] = {"X", "Y", "Z"};
    const char* rgb[] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        if (!layers.normal[c].empty())
            planes.push_back({std::string("N.") + xyz[c], layers.normal[c].data()});
        if (!layers.albedo[c].empty())
            planes.push_back({std::string("albedo.") + rgb[c], layers.albedo[c].data()});
        if (!error[size_t(c)].empty())
            planes.push_back({std::string("error.") + rgb[c], error[size_t(c)].data()});
    }
    if (!run.flipMap.empty())
        planes.push_back({"flip", run.flipMap.data()});
    const std::vector<float> complex = complexMap(run);
    if (!complex.empty())
        planes.push_back({"msaa.complex", complex.data()});
    if (!run.postAaEdges.empty())
        planes.push_back({"post_aa.edges", run.postAaEdges.data()});
    std::vector<std::pair<std::string, std::string>> metadata = {
        {"testbed:scene", run.options.scene},
        {"testbed:stage", run.options.stage},
        {"testbed:layout", gb.layout().name},
        {"testbed:commit", kBuildCommit},
        {"testbed:stats", stats.dump()},
        {"testbed:Z", "view-space depth in metres decoded from the G-buffer, 0 = background"},
        {"testbed:error", "error.R,G,B = |R,G,B - reference| (double-precision reference)"},
        {"testbed:flip", "flip = HDR-FLIP per pixel against the reference, 0..1"},
        {"testbed:post_aa.edges",
         "post_aa.edges = the post-process anti-aliasing's edge plane, 0..1: edge weight "
         "(edge-blur) or the neighbour's blend weight (fxaa); absent for --post-aa none"},
        {"testbed:lights.wasted",
         "lights.evaluated - lights.oracle at the pixels the stage lit; 0 at pixels a "
         "reduced-resolution stage only filtered"},
    };
    writeMultiLayerExr(dir / "render.exr", w, h, planes, metadata);
    written.push_back("render.exr");
    writePreviewPng(dir / "preview.png", w, h, run.result.radiance[0].data(),
                    run.result.radiance[1].data(), run.result.radiance[2].data());
    written.push_back("preview.png");
    writeHeatmapPng(dir / "heatmap.png", w, h, run.result.lightsEvaluated.data(),
                    scales.heatmapMax);
    written.push_back("heatmap.png");
    if (run.metrics.error) {
        writeScalarMapPng(dir / "error.png", w, h, largestChannelError(error).data(),
                          errorMapStyle(scales));
        // What the image is measured against (the supersampled reference by default), with the
        // preview's tone map: the two side by side show what the error maps quantify.
        writePreviewPng(dir / "reference.png", w, h, run.reference.radiance[0].data(),
                        run.reference.radiance[1].data(), run.reference.radiance[2].data());
        written.push_back("error.png");
        written.push_back("reference.png");
    }
    if (!run.flipMap.empty()) {
        writeScalarMapPng(dir / "flip.png", w, h, run.flipMap.data(), flipMapStyle());
        written.push_back("flip.png");
    }
    if (!complex.empty()) {
        ScalarMapStyle style;
        style.max = float(run.prepared->multisample->layers.samples());
        style.colourMap = "magma";
        style.title = "surfaces shaded at complex pixels (black: simple or background), " +
                      std::to_string(run.prepared->multisample->layers.samples()) + "x MSAA";
        writeScalarMapPng(dir / "complex.png", w, h, complex.data(), style);
        written.push_back("complex.png");
    }
    if (run.shadowError) {
        writeShadowErrorPng(dir / "shadow-error.png", run);
        written.push_back("shadow-error.png");
    }
    // The peak after every image was written (the EXR header's copy was taken before).
    nlohmann::json finalStats = stats;
    finalStats["memory"]["measured_peak_rss_bytes"] = peakResidentBytes();
    writeTextAtomically(dir / "stats.json", finalStats.dump(2) + "\n");
    written.push_back("stats.json");
    return written;
}

namespace {

nlohmann::json layoutJson(const gbuffer::GBufferLayout& layout, const RunMetrics& metrics) {
    nlohmann::json planes = nlohmann::json::array();
    for (const gbuffer::PlaneDesc& plane : layout.planes())
        planes.push_back({{"name", plane.name},
                          {"channel", plane.channel},
                          {"format", plane.format},
                          {"bits", plane.bits},
                          {"allocated", !plane.unmodelled}});
    nlohmann::json reasons = nlohmann::json::object();
    for (const auto& [channel, reason] : layout.reasons)
        reasons[gbuffer::channelName(channel)] = reason;
    return {
        {"name", layout.name},
        {"depth", layout.depth.text()},
        {"position", gbuffer::positionMethodName(layout.position)},
        {"normals", layout.hasNormals ? layout.normals.text() : "none"},
        {"normal_space", gbuffer::normalSpaceName(layout.normalSpace)},
        {"albedo", gbuffer::albedoEncodingName(layout.albedo)},
        {"specular", gbuffer::specularEncodingName(layout.specular)},
        {"roughness_metallic", gbuffer::roughnessMetallicEncodingName(layout.roughnessMetallic)},
        {"occlusion", gbuffer::roughnessMetallicEncodingName(layout.occlusion)},
        {"emission", gbuffer::emissionEncodingName(layout.emission)},
        {"planes", planes},
        {"reasons", reasons},
        {"notes", layout.notes},
        {metric::kBytesPerPixel, metrics.bytesPerPixel},
        {metric::kAllocatedBytesPerPixel, metrics.allocatedBytesPerPixel}};
}

// timings_ms (the medians) and timings (warm-up, repetitions, every pass's spread and samples).
void addTimings(nlohmann::json& stats, const RenderRun& run) {
    nlohmann::json medians = nlohmann::json::object();
    nlohmann::json spread = nlohmann::json::object();
    for (const PassTiming& timing : run.metrics.passes) {
        medians[timing.pass] = timing.medianMs();
        spread[timing.pass] = {{"median", timing.medianMs()},
                               {"min", timing.minMs()},
                               {"max", timing.maxMs()},
                               {"samples", timing.samplesMs}};
    }
    stats["timings_ms"] = medians;
    stats["timings"] = {{"warmup", run.options.warmup},
                        {"repetitions", run.options.repetitions},
                        {"figure", timingFigure(run.options)},
                        {"passes_ms", spread}};
    const gbuffer::GBufferPassTimings& steps = run.prepared->gbufferTimings;
    stats["gbuffer_steps_ms"] = {{"transform", steps.transformMs},
                                 {"raster", steps.rasterMs},
                                 {"resolve", steps.resolveMs},
                                 {lighting::pass::kExactSurface, steps.exactMs}};
    stats["cpu_load"] = run.metrics.cpuLoad.toJson();
    stats["measurement_ms"] = {{"oracle", run.metrics.oracleMs},
                               {"reference", run.metrics.referenceMs},
                               {"flip", run.metrics.flipMs}};
}

// The error figures; psnr is +inf for identical images, written as "inf" (JSON has no infinity);
// flip (and its percentiles) is null when it could not be computed, with flip_unavailable saying
// why, else flip_parameters say what was assumed (exposures, pixels per degree, warnings).
nlohmann::json errorJson(const RenderRun& run) {
    const RunMetrics& metrics = run.metrics;
    nlohmann::json error = {
        {"reference", "reference"},
        {"reference_spp", run.options.referenceSpp},
        {"reference_pattern", lighting::referenceSamplePattern(run.options.referenceSpp)}};
    for (const NamedFigure& figure : metrics.errorFigures())
        error[figure.name] = std::isinf(figure.value)
                                 ? nlohmann::json(figure.value > 0 ? "inf" : "-inf")
                             : std::isnan(figure.value) ? nlohmann::json()
                                                        : nlohmann::json(figure.value);
    error[metric::kNonFinitePixels] = metrics.error->nonFinitePixels;
    error[metric::kReferenceNonFinitePixels] = metrics.error->referenceNonFinitePixels;
    if (const std::string note = nonFiniteNote(*metrics.error); !note.empty())
        error["unreliable"] = note;
    error[metric::kFlipUnavailable] = metrics.error->flipUnavailable;
    if (!run.flipParameters.is_null())
        error["flip_parameters"] = run.flipParameters;
    if (const std::string note = errorConcentrationNote(*metrics.error); !note.empty())
        error["note"] = note;
    return error;
}

nlohmann::json rasterJson(const raster::RasterStats& raster) {
    return {{"triangles_in", raster.trianglesIn},
            {"triangles_culled", raster.trianglesCulled},
            {"triangles_clipped", raster.trianglesClipped},
            {"triangles_set_up", raster.trianglesSetUp},
            {"samples_covered", raster.samplesCovered},
            {"samples_passed", raster.samplesPassed}};
}

// The anti-aliasing block of stats.json: samples, complex-pixel detection and counts, and the
// G-buffer's bytes (FragmentLayers.h: stored = as a compressed store holds them; allocated = the
// full planes of every layer; per_sample_buffers = the multisampled depth and visibility buffers
// the rasterizer fills before the layers are built).
nlohmann::json msaaJson(const RenderRun& run) {
    const RunMetrics& metrics = run.metrics;
    nlohmann::json msaa = {{"samples", metrics.msaaSamples},
                           {"complex_detect", run.options.complexDetect},
                           {"alpha_to_coverage", run.options.alphaToCoverage},
                           {metric::kComplexFraction, metrics.complexFraction},
                           {metric::kSurfacesPerPixel, metrics.surfacesPerCoveredPixel},
                           {metric::kGBufferBytes, metrics.gbufferBytes},
                           {metric::kGBufferAllocatedBytes, metrics.gbufferAllocatedBytes}};
    const gbuffer::MultisampleTarget* target = run.prepared->multisample.get();
    if (target) {
        const gbuffer::FragmentLayers& layers = target->layers;
        msaa["layers"] = layers.layerCount();
        msaa["covered_pixels"] = layers.counts().coveredPixels;
        msaa["complex_pixels"] = layers.counts().complexPixels;
        msaa["partial_pixels"] = layers.counts().partialPixels;
        msaa["merged_fragments"] = layers.counts().mergedFragments;
        msaa["shaded_surfaces"] = layers.counts().fragments;
        msaa["per_sample_buffers_bytes"] =
            double(layers.pixelCount()) * layers.samples() * (sizeof(float) * 2 + sizeof(uint32_t));
        msaa["gbuffer_bytes_per_pixel"] = metrics.gbufferBytes / double(layers.pixelCount());
        msaa["gbuffer_bytes_ratio_to_1x"] =
            metrics.gbufferBytes / (metrics.bytesPerPixel * double(layers.pixelCount()));
    }
    return msaa;
}

} // namespace

nlohmann::json statsJson(const RenderRun& run) {
    const RunMetrics& metrics = run.metrics;
    nlohmann::json stats;
    // Names and paths as reversible escapes (output/JsonText.h): a file name need not be UTF-8.
    stats["scene"] = bytesForJson(run.scene().name);
    stats["scene_source"] = bytesForJson(run.options.scene);
    stats["brdf"] = run.options.brdf;
    stats["scene_options"] = run.options.sceneOptions;
    stats["view"] = run.scene().cameras.front().name;
    stats["stage"] = run.options.stage;
    // Every option of the stage's table, defaults filled in (StageOptions.h); the spec was
    // checked when the stage was made, so this cannot throw.
    stats["stage_options"] = lighting::resolvedStageOptions(run.options.stage);
    stats["stage_parameters"] = run.result.parameters;
    stats["width"] = run.options.width;
    stats["height"] = run.options.height;
    stats["threads"] = run.threads;
    // The kernel's instruction set as requested, and as dispatched: what the stage's shading
    // loop ran (LightAccumulation.h), "scalar" for stages that do not use the kernel or frames
    // it falls back to evaluateLight per pixel on.
    stats["isa_requested"] = run.options.isa;
    const auto dispatched = run.result.parameters.find("isa");
    stats["isa"] = dispatched != run.result.parameters.end() ? dispatched->second : "scalar";
    stats["reference_spp"] = run.options.referenceSpp;
    // The post-process anti-aliasing applied to the image after the stage (before the error was
    // measured), with every parameter of the filter.
    lighting::postaa::PostAaPass postAa(lighting::postaa::parsePostAa(run.options.postAa));
    const size_t filtered = size_t(std::count_if(run.postAaEdges.begin(), run.postAaEdges.end(),
                                                 [](float edge) { return edge > 0.0f; }));
    stats["post_aa"] = {{"mode", run.options.postAa},
                        {"parameters", postAa.describe()},
                        {"filtered_pixels", filtered}};
    stats["hardware_threads"] = std::thread::hardware_concurrency();
    stats["commit"] = kBuildCommit;
    stats["triangles"] = run.scene().triangleCount();
    stats["lights"] = run.scene().lights.size();
    const LightOrigins origins = lightOrigins(run.options, run.scene());
    stats["generated_lights"] = origins.generated;
    stats["light_origins"] = origins.toJson();
    stats["seed"] = run.options.seed;
    stats["layout"] = layoutJson(run.gbuffer().layout(), metrics);
    stats[metric::kBytesPerPixel] = metrics.bytesPerPixel;
    stats["msaa"] = msaaJson(run);
    stats["shadows"] = shadowsJson(run);
    stats["oracle_mode"] = run.options.oracle;
    // The G-buffer pass's phases in the last timed repetition (GBufferPass.h).
    const gbuffer::GBufferPassTimings& phases = run.prepared->gbufferTimings;
    stats["gbuffer_phases_ms"] = {{"transform", phases.transformMs},
                                  {"raster", phases.rasterMs},
                                  {"layers", phases.layersMs},
                                  {"resolve", phases.resolveMs}};
    // The raster phase broken down (raster::RasterPhaseTimes; the rest of "raster" is the
    // visibility buffer's clear).
    stats["gbuffer_phases_ms"]["raster_phases"] = {{"project", phases.rasterPhases.projectMs},
                                                   {"setup", phases.rasterPhases.setupMs},
                                                   {"bin_sort", phases.rasterPhases.binSortMs},
                                                   {"traversal", phases.rasterPhases.traversalMs}};
    addTimings(stats, run);
    stats["oracle_surface"] = run.oracleFromLosslessGBuffer
                                  ? "lossless G-buffer (the layout lacks BRDF channels)"
                                  : "the stage's G-buffer";
    stats[metric::kLightEvaluations] = metrics.lightEvaluations;
    stats[metric::kOracleLightEvaluations] = metrics.oracleLightEvaluations;
    stats["lights_per_covered_pixel"] = {
        {"mean", metrics.oracleLightsPerCoveredPixelMean},
        {"p99", metrics.oracleLightsPerCoveredPixelP99},
        {"light_density", scenes::lightDensityName(run.options.lightDensity)}};
    stats[metric::kCullingEfficiency] = metrics.cullingEfficiency;
    stats[metric::kCountedPixels] = metrics.countedPixels;
    if (!metrics.lightCountsNote.empty())
        stats["light_counts_note"] = metrics.lightCountsNote;
    stats[metric::kSimtLaneSlots] =
        metrics.simtLaneSlots ? nlohmann::json(*metrics.simtLaneSlots) : nlohmann::json(nullptr);
    stats[metric::kSimtEfficiency] =
        metrics.simtEfficiency ? nlohmann::json(*metrics.simtEfficiency) : nlohmann::json(nullptr);
    stats["raster"] = rasterJson(run.prepared->rasterStats);
    if (metrics.error)
        stats["error"] = errorJson(run);
    stats["coverage"] = run.coverage.toJson();
    nlohmann::json warnings = nlohmann::json::array();
    for (const std::string& warning : run.scene().warnings) // messages: may quote a file name
        warnings.push_back(scenes::escapeControlCharacters(warning));
    if (!run.coverage.warning.empty())
        warnings.push_back(scenes::escapeControlCharacters(run.coverage.warning));
    stats["warnings"] = warnings;
    stats["memory"] = run.memory.toJson();
    stats["memory"]["measured_peak_rss_bytes"] = peakResidentBytes();
    return stats;
}

namespace {

// A view name as a folder name: letters, digits, '.', '-' and '_' are kept, anything else
// (spaces, '/', ...) becomes '_'; a name that collides with an earlier one gets "-N".
std::vector<std::string> viewFolderNames(const std::vector<std::string>& views) {
    std::vector<std::string> folders;
    for (const std::string& view : views) {
        std::string folder;
        for (char c : view)
            folder +=
                std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_'
                    ? c
                    : '_';
        if (folder.empty() || folder == "." || folder == "..")
            folder = "view";
        const std::string base = folder;
        for (int n = 2; std::find(folders.begin(), folders.end(), folder) != folders.end(); ++n)
            folder = base + "-" + std::to_string(n);
        folders.push_back(folder);
    }
    return folders;
}

// `render --view all`: one render per view of the scene into OUT/views/FOLDER/, each exactly
// what `render --view NAME --out OUT/views/FOLDER` writes (its stats.json holds its figures), and
// OUT/views.json listing the views and their folders in the scene's order. The scene is loaded
// once, and every view is planned (options, layout, memory estimate) before the first is
// rendered, so that an error in any view stops the command before any work.
int renderEveryView(const RenderCommandOptions& options) {
    checkOutputScales(options.scales);
    RenderOptions sceneOnly = options.render;
    sceneOnly.view.clear();
    checkOptions(sceneOnly); // every input error before the scene is loaded
    checkSceneLoadMemory(sceneOnly);
    const scenes::Scene scene = loadRequestedScene(sceneOnly);
    const std::vector<std::string> views = scenes::viewNames(scene);
    const std::vector<std::string> folders = viewFolderNames(views);
    auto planView = [&](const std::string& view) {
        RenderOptions one = options.render;
        one.view = view;
        scenes::Scene viewed = scene;
        scenes::selectView(viewed, view);
        return planRenderWithScene(one, std::move(viewed));
    };
    for (const std::string& view : views)
        checkMemoryEstimate(planView(view).memory);
    // Every view into one staging folder, committed when the last one is written: a view that
    // fails leaves OUT as it was, the views rendered before it included.
    StagedFolder staged(options.out);
    nlohmann::json index = nlohmann::json::array();
    for (size_t i = 0; i < views.size(); ++i) {
        RenderCommandOptions one = options;
        one.render.view = views[i];
        one.out = options.out / "views" / folders[i];
        std::cout << "testbed: view " << (i + 1) << "/" << views.size() << " '"
                  << scenes::escapeControlCharacters(views[i]) << "'\n";
        const std::filesystem::path dir = staged.path() / "views" / folders[i];
        std::filesystem::create_directories(dir);
        const RenderRun run = runRender(planView(views[i]));
        const std::vector<std::string> written = writeRenderOutputs(run, dir, one.scales);
        printSummary(run, one.out, written);
        if (run.metrics.cpuLoad.loaded)
            reportWarning(run.metrics.cpuLoad.warning);
        index.push_back({{"view", views[i]}, {"folder", "views/" + folders[i]}});
    }
    writeTextAtomically(staged.path() / "views.json", index.dump(2) + "\n");
    staged.commit({"views.json"});
    return 0;
}

} // namespace

// What --explain-layout adds for anti-aliasing: the G-buffer's bytes at each sample count, as
// the fragment layers store them (gbuffer/msaa/FragmentLayers.h), bounds before rendering.
std::string explainMultisampleBytes(const RenderPlan& plan) {
    const double surface = plan.layout.bytesPerPixel();
    std::ostringstream out;
    out << "anti-aliasing (--msaa N, --complex-detect " << plan.options.complexDetect
        << "): one surface per pixel (" << surface
        << " bytes) at simple pixels, one per distinct surface at complex ones; per pixel:\n";
    for (int samples : {1, 2, 4, 8}) {
        out << "  " << samples << "x: ";
        if (samples == 1) {
            out << surface << " bytes\n";
            continue;
        }
        out << "stored " << surface + 1 << " bytes + " << surface + 1
            << " per extra surface at a complex pixel (at most " << samples - 1 << ": "
            << samples * (surface + 1) << " bytes); allocated " << surface
            << " per layer; during the pass " << samples * 12
            << " bytes of per-sample depth, centre depth and visibility"
            << (samples == plan.options.msaa ? "  <- this render" : "") << "\n";
    }
    return out.str();
}

int runRenderCommand(const RenderCommandOptions& options) {
    if (options.render.view == kEveryView && !options.explainLayout) {
        try {
            return renderEveryView(options);
        } catch (const std::exception& e) {
            return reportError(e);
        }
    }
    try {
        // Progress on stderr as sweeps print it, but only for a render longer than 2 s.
        DelayedProgress delayed(std::cerr, kLongRenderSeconds);
        auto progress = [&](const std::string& step) { delayed.step(step); };
        checkOutputScales(options.scales); // every option before any work
        progress("loading scene " + options.render.scene);
        RenderPlan plan = planRender(options.render); // every input error stops here
        if (options.explainLayout) {
            std::cout << "stage " << options.render.stage << " on " << options.render.scene << ":\n"
                      << plan.layout.explain() << explainMultisampleBytes(plan)
                      << plan.memory.explain();
            return 0;
        }
        StagedFolder staged(options.out); // before the G-buffer pass and the stage
        const RenderRun run = runRender(std::move(plan), progress);
        progress("writing outputs");
        const std::vector<std::string> written =
            writeRenderOutputs(run, staged.path(), options.scales);
        staged.commit(renderOutputNames());
        delayed.finish();
        printSummary(run, options.out, written);
        if (!run.coverage.warning.empty())
            reportWarning(run.coverage.warning);
        if (run.metrics.cpuLoad.loaded)
            reportWarning(run.metrics.cpuLoad.warning);
        return 0;
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

} // namespace experiments
