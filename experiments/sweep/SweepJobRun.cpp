#include "experiments/sweep/SweepJobRun.h"

#include <cmath>

#include <OpenImageIO/imagebuf.h>

#include "experiments/output/ImageOutput.h"
#include "experiments/output/StagedFolder.h"
#include "experiments/render/MemoryEstimate.h"
#include "experiments/render/RenderCommand.h"
#include "experiments/render/RenderJob.h"

namespace experiments {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

Json number(double value) {
    return std::isfinite(value) ? Json(value) : Json(nullptr);
}

void writeReferenceExr(const fs::path& path, const std::string& key,
                       const lighting::StageResult& image) {
    writeMultiLayerExr(path, image.width, image.height,
                       {{"R", image.radiance[0].data()},
                        {"G", image.radiance[1].data()},
                        {"B", image.radiance[2].data()}},
                       {{"testbed:reference_key", key},
                        {"testbed:what", "double-precision reference, stored as float32"}});
}

// Reads a cached reference; nullopt when absent or not the expected image (then it is rendered).
std::optional<lighting::StageResult> readReferenceExr(const fs::path& path, const std::string& key,
                                                      int width, int height) {
    if (!fs::is_regular_file(path))
        return std::nullopt;
    runImageLibraryOnTheCallingThread();
    OIIO::ImageBuf buffer;
    if (!readFloatImage(path, buffer))
        return std::nullopt;
    const OIIO::ImageSpec& spec = buffer.spec();
    if (spec.width != width || spec.height != height ||
        spec.get_string_attribute("testbed:reference_key") != key)
        return std::nullopt;
    lighting::StageResult image;
    image.width = width;
    image.height = height;
    const size_t pixels = size_t(width) * size_t(height);
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        const int channel = spec.channelindex(names[c]);
        if (channel < 0)
            return std::nullopt;
        image.radiance[c].resize(pixels);
        OIIO::ROI roi = buffer.roi();
        roi.chbegin = channel;
        roi.chend = channel + 1;
        if (!buffer.get_pixels(roi, OIIO::TypeDesc::FLOAT, image.radiance[c].data()))
            return std::nullopt;
    }
    return image;
}

} // namespace

fs::path ReferenceStore::cachePath(const std::string& key) const {
    return mFolder / (key + ".exr");
}

void ReferenceStore::markFailed(const std::string& key, const std::string& message) {
    mErrors[key] = message;
    if (mKey == key) {
        mImage.reset();
        mKey.clear();
    }
}

const lighting::StageResult& ReferenceStore::get(const SweepJob& job, const Listener& listener) {
    const std::string& key = job.referenceKey;
    if (mKey == key && mImage)
        return *mImage;
    if (const auto failed = mErrors.find(key); failed != mErrors.end())
        throw std::runtime_error(failed->second);
    mImage.reset();
    mKey = key;
    const fs::path path = cachePath(key);
    if (auto loaded = readReferenceExr(path, key, job.options.width, job.options.height)) {
        mImage = std::move(*loaded);
        if (listener)
            listener(Event::Loaded, key);
        return *mImage;
    }
    if (listener)
        listener(Event::Rendering, key);
    try {
        mImage = renderReference(job.options);
    } catch (const std::exception& e) {
        const std::string message = "reference " + key + ": " + e.what();
        markFailed(key, message);
        throw std::runtime_error(message);
    }
    writeReferenceExr(path, key, *mImage);
    if (listener)
        listener(Event::Rendered, key);
    return *mImage;
}

Json metricColumnsOf(const RunMetrics& metrics) {
    Json row = Json::object();
    std::vector<PassTiming> passes = metrics.passes;
    if (!metrics.stage.samplesMs.empty())
        passes.push_back(metrics.stage);
    for (const PassTiming& timing : passes) {
        row["time_" + timing.pass + "_median_ms"] = number(timing.medianMs());
        row["time_" + timing.pass + "_min_ms"] = number(timing.minMs());
        row["time_" + timing.pass + "_max_ms"] = number(timing.maxMs());
    }
    row[metric::kLightEvaluations] = metrics.lightEvaluations;
    row[metric::kOracleLightEvaluations] = metrics.oracleLightEvaluations;
    row[metric::kCullingEfficiency] = metrics.cullingEfficiency;
    row[metric::kCountedPixels] = metrics.countedPixels;
    // The SIMT cost model (null for stages without it), as stats.json has it.
    row[metric::kSimtLaneSlots] =
        metrics.simtLaneSlots ? Json(*metrics.simtLaneSlots) : Json(nullptr);
    row[metric::kSimtEfficiency] =
        metrics.simtEfficiency ? number(*metrics.simtEfficiency) : Json(nullptr);
    row[metric::kBytesPerPixel] = metrics.bytesPerPixel;
    row[metric::kComplexFraction] = metrics.complexFraction;
    row[metric::kSurfacesPerPixel] = metrics.surfacesPerCoveredPixel;
    row[metric::kGBufferBytes] = metrics.gbufferBytes;
    row[metric::kGBufferAllocatedBytes] = metrics.gbufferAllocatedBytes;
    row[metric::kShadowMapBytes] =
        metrics.shadowMapBytes ? number(*metrics.shadowMapBytes) : Json(nullptr);
    row[metric::kShadowMisclassified] =
        metrics.shadowMisclassified ? number(*metrics.shadowMisclassified) : Json(nullptr);
    for (const NamedFigure& figure : metrics.errorFigures())
        row[figure.name] = number(figure.value); // psnr +inf (identical images) -> null
    if (metrics.error)
        row[metric::kFlipUnavailable] = metrics.error->flipUnavailable;
    // The non-finite pixels behind inf (here null) error figures, as stats.json counts them;
    // null without a reference.
    row[metric::kNonFinitePixels] =
        metrics.error ? Json(metrics.error->nonFinitePixels) : Json(nullptr);
    row[metric::kReferenceNonFinitePixels] =
        metrics.error ? Json(metrics.error->referenceNonFinitePixels) : Json(nullptr);
    return row;
}

Json runSweepJob(const SweepJob& job, const fs::path& jobDir, ReferenceStore& references,
                 const ReferenceStore::Listener& listener) {
    const lighting::StageResult* referenceImage =
        job.compareReference ? &references.get(job, listener) : nullptr;
    RenderOptions options = job.options;
    options.compareReference = job.compareReference;
    const bool peakIsTheRenders = resetPeakResident(); // the reference's peak is not the job's
    const RenderRun run = runRender(planRender(options), {}, referenceImage);
    const uint64_t peakBytes = peakResidentBytes();
    // Staged, as `testbed render` writes: a job that fails while writing leaves its folder as it
    // was (its marker, written by the runner, says why).
    StagedFolder staged(jobDir);
    writeRenderOutputs(run, staged.path(), {job.heatmapMax, job.errorScale, float(job.errorMax)});
    staged.commit(renderOutputNames());
    Json row = metricColumnsOf(run.metrics);
    row[metric::kMemoryEstimateBytes] = run.memory.totalBytes();
    row[metric::kPeakRssBytes] = peakIsTheRenders ? Json(peakBytes) : Json(nullptr);
    row[metric::kCoveredFraction] =
        run.coverage.pixels
            ? number(double(run.coverage.coveredPixels) / double(run.coverage.pixels))
            : Json(nullptr);
    return row;
}

} // namespace experiments
