#include "lighting/MultisampleShading.h"

#include <algorithm>
#include <string>

#include <tbb/parallel_for.h>

#include "lighting/Oracle.h"
#include "lighting/passes/KernelWork.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

bool hasBlendedMaterial(const scenes::Scene& scene) {
    return std::any_of(scene.materials.begin(), scene.materials.end(), [](const auto& material) {
        return material.alphaMode == scenes::AlphaMode::Blend;
    });
}

// Adds `run`'s passes to `total`'s of the same name (appended when new), in order.
void addTimings(std::vector<std::pair<std::string, double>>& total,
                const std::vector<std::pair<std::string, double>>& run) {
    for (const auto& pass : run) {
        auto it = std::find_if(total.begin(), total.end(),
                               [&](const auto& entry) { return entry.first == pass.first; });
        if (it == total.end())
            total.push_back(pass);
        else
            it->second += pass.second;
    }
}

// Runs `run` and appends its wall time in milliseconds (the stages' Stopwatch) to `runMs`.
template <class Run> void timed(std::vector<double>& runMs, const Run& run) {
    const Stopwatch clock;
    run();
    runMs.push_back(clock.milliseconds());
}

} // namespace

void MultisampleShading::shade(ShadingStage& stage, const PreparedScene& prepared,
                               StageResult& result) {
    mRunMs.clear();
    timed(mRunMs, [&] { stage.shade(prepared.inputs, result); });
    if (!prepared.multisample)
        return;
    const gbuffer::FragmentLayers& layers = prepared.multisample->layers;
    if (stage.multisamplesNatively()) {
        // Shaded and resolved by the stage itself, once, at inputs.samples.
        result.parameters["msaa"] = std::to_string(prepared.inputs.samples);
        result.parameters["msaa_shading"] = "native";
        return;
    }
    const int width = layers.width();
    const bool blendedScene = hasBlendedMaterial(prepared.scene);
    // The other fragments: in one packed run when the stage has one (PackedFragments.h; not with
    // blended surfaces, which each layer's run composites over its own samples, nor for a stage
    // that counts the oracle itself), else one run per layer.
    bool packed = false;
    auto* packedStage = dynamic_cast<PackedFragmentShading*>(&stage);
    if (packedStage && layers.layerCount() > 1 && !blendedScene && result.lightsOracle.empty()) {
        mFragments.build(layers);
        PackedFragmentRun run;
        run.frame = &prepared.inputs;
        run.fragments = &mFragments;
        for (int k = 0; k < layers.layerCount(); ++k)
            run.layerGBuffers.push_back(prepared.layerInputs(k).gbuffer);
        mPacked.traceLights = result.traceLights;
        timed(mRunMs, [&] { packed = packedStage->shadeFragments(run, mPacked); });
        if (packed) {
            addTimings(result.timingsMs, mPacked.timingsMs);
            KernelWork::addRecorded(mPacked, result);
        } else {
            mRunMs.pop_back(); // it did nothing
        }
    }
    std::vector<StageResult>& upper = mUpper;
    upper.resize(packed ? 0 : size_t(layers.layerCount() - 1));
    for (int k = 1; !packed && k < layers.layerCount(); ++k) {
        upper[size_t(k - 1)].traceLights = result.traceLights;
        timed(mRunMs, [&] { stage.shade(prepared.layerInputs(k), upper[size_t(k - 1)]); });
        addTimings(result.timingsMs, upper[size_t(k - 1)].timingsMs);
        KernelWork::addRecorded(upper[size_t(k - 1)], result);
    }
    // Blended surfaces over the background samples of partially covered pixels.
    StageResult& background = mBackground;
    const bool blended = blendedScene && layers.counts().partialPixels > 0;
    if (blended) {
        if (!mEmpty || mEmpty->width() != prepared.view.width ||
            mEmpty->height() != prepared.view.height)
            mEmpty = std::make_unique<gbuffer::GBuffer>(prepared.gbuffer->layout(), prepared.view);
        StageInputs frame = prepared.inputs;
        frame.gbuffer = mEmpty.get();
        frame.fragmentLayer = StageInputs::kBackgroundRun;
        timed(mRunMs, [&] { stage.shade(frame, background); });
        addTimings(result.timingsMs, background.timingsMs);
        KernelWork::addRecorded(background, result);
    }

    PassTimer resolve(result, pass::kResolve);
    const bool oracle = !result.lightsOracle.empty();
    // Per pixel the same sum in the same order as the definition (layer 0, the layers above, the
    // background run), but written only where it changes the pixel. A pixel whose main fragment
    // covers every sample or none (weight exactly 1, so 1 x radiance is the radiance; no
    // background samples beside a surface) and that has no fragment above keeps layer 0's
    // values: one byte read. The layers above hold nothing (radiance, evaluations, oracle all
    // zero) outside their fragments, which lie at upperColumns only, so the walk over them
    // follows the complex pixels, not the screen.
    const std::span<const uint8_t> mainCoverage = layers.coverage(0);
    const uint8_t allSamples = uint8_t((1u << layers.samples()) - 1u);
    tbb::parallel_for(0, layers.height(), [&](int y) {
        const std::span<const uint32_t> columns = layers.upperColumns(y);
        size_t nextColumn = 0;
        size_t nextFragment = packed ? mFragments.rowFirst(y) : 0; // packed: the row's first
        const size_t rowStart = size_t(y) * size_t(width);
        for (int x = 0; x < width; ++x) {
            const size_t pixel = rowStart + size_t(x);
            if (blended)
                result.lightsEvaluated[pixel] += background.lightsEvaluated[pixel];
            const bool upperHere =
                nextColumn < columns.size() && columns[nextColumn] == uint32_t(x);
            const uint8_t mask = mainCoverage[pixel];
            if (!upperHere && (mask == allSamples || mask == 0))
                continue;
            nextColumn += upperHere ? 1 : 0;
            const float w0 = layers.weight(0, pixel);
            const bool partial = blended && mask != 0 && layers.backgroundWeight(pixel) > 0.0f;
            float rgb[3];
            for (int c = 0; c < 3; ++c)
                rgb[c] = w0 * result.radiance[c][pixel];
            // The pixel's other fragments in layer order: the packed run's (the list holds them
            // in this order), or each layer's run.
            for (; packed && upperHere && nextFragment < mFragments.size() &&
                   mFragments.pixel(nextFragment) == pixel;
                 ++nextFragment) {
                result.lightsEvaluated[pixel] += mPacked.lightsEvaluated[nextFragment];
                const float w = layers.weight(mFragments.layer(nextFragment), pixel);
                for (int c = 0; c < 3; ++c)
                    rgb[c] += w * mPacked.radiance[c][nextFragment];
            }
            for (int k = 1; !packed && upperHere && k < layers.layerCount(); ++k) {
                const StageResult& layer = upper[size_t(k - 1)];
                if (layers.codes(k)[pixel] == gbuffer::VisibilityPass::kNoTriangle)
                    continue;
                result.lightsEvaluated[pixel] += layer.lightsEvaluated[pixel];
                const float w = layers.weight(k, pixel);
                for (int c = 0; c < 3; ++c)
                    rgb[c] += w * layer.radiance[c][pixel];
                if (oracle)
                    result.lightsOracle[pixel] += layer.lightsOracle[pixel];
            }
            if (partial)
                for (int c = 0; c < 3; ++c)
                    rgb[c] += layers.backgroundWeight(pixel) * background.radiance[c][pixel];
            for (int c = 0; c < 3; ++c)
                result.radiance[c][pixel] = rgb[c];
        }
    });
    resolve.stop();
    const gbuffer::FragmentLayers::Counts& counts = layers.counts();
    result.parameters["msaa"] = std::to_string(layers.samples());
    result.parameters["msaa_shading"] = packed ? "packed" : "layers";
    result.parameters["msaa_layers"] = std::to_string(layers.layerCount());
    result.parameters["msaa_complex_pixels"] = std::to_string(counts.complexPixels);
    result.parameters["msaa_shaded_fragments"] = std::to_string(counts.fragments);
    result.parameters["msaa_background_run"] = blended ? "1" : "0";
}

std::vector<uint32_t> countContributingLightsOverLayers(const PreparedScene& prepared) {
    std::vector<uint32_t> total = countContributingLights(prepared.inputs);
    if (!prepared.multisample)
        return total;
    const gbuffer::FragmentLayers& layers = prepared.multisample->layers;
    for (int k = 1; k < layers.layerCount(); ++k) {
        const std::vector<uint32_t> layer = countContributingLights(prepared.layerInputs(k));
        for (size_t pixel = 0; pixel < total.size(); ++pixel)
            total[pixel] += layer[pixel];
    }
    return total;
}

} // namespace lighting
