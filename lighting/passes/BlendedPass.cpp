#include "lighting/passes/BlendedPass.h"

#include <algorithm>
#include <bit>
#include <numeric>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

#include "gbuffer/GBufferLayout.h"
#include "gbuffer/visibility/AlphaCoverage.h"
#include "gbuffer/visibility/ExactSurface.h"
#include "lighting/culling/BlendedTileLists.h"
#include "lighting/passes/ForwardGeometry.h"

namespace lighting {

bool BlendedPass::prepare(const StageInputs& inputs, SampleRadiance* samples) {
    mTarget = samples;
    mLayered = !samples && inputs.fragmentLayers && inputs.samples > 1;
    mSamples = samples ? samples->samples() : mLayered ? inputs.samples : 1;
    if (mLayered && !inputs.sampleDepths)
        throw std::invalid_argument(
            "BlendedPass: a layered multisampled frame needs inputs.sampleDepths");
    const scenes::Scene& scene = *inputs.scene;
    mActive = std::any_of(scene.materials.begin(), scene.materials.end(),
                          [](const auto& m) { return m.alphaMode == scenes::AlphaMode::Blend; });
    mSceneTriangle.clear();
    if (!mActive)
        return false;
    mInputs = &inputs;
    const gbuffer::SceneGeometry& geometry = *inputs.geometry;
    const gbuffer::CameraView& view = *inputs.view;
    mVisibility.transform(scene, geometry, view);
    mDepthDecoder =
        gbuffer::GBufferLayout::lossless(view.depthConvention, view.infiniteFar).depthDecoder(view);
    fitRasterizer(mRasterizer, view);

    // Back to front by the centroid's clip w (the view depth, for a perspective camera).
    const uint32_t triangleCount = geometry.triangleCount();
    std::vector<float> centroidDepth;
    for (uint32_t t = 0; t < triangleCount; ++t) {
        if (scene.materials[geometry.triangleMaterial[t]].alphaMode != scenes::AlphaMode::Blend)
            continue;
        const std::span<const glm::vec4> clip = mVisibility.clipPositions();
        const uint32_t* index = geometry.indices.data() + 3 * size_t(t);
        mSceneTriangle.push_back(t);
        centroidDepth.push_back((clip[index[0]].w + clip[index[1]].w + clip[index[2]].w) / 3.0f);
    }
    std::vector<uint32_t> order(mSceneTriangle.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return centroidDepth[a] > centroidDepth[b]; });
    std::vector<uint32_t> sorted(order.size());
    mSortedIndices.resize(3 * order.size());
    for (size_t i = 0; i < order.size(); ++i) {
        sorted[i] = mSceneTriangle[order[i]];
        for (int c = 0; c < 3; ++c)
            mSortedIndices[3 * i + size_t(c)] = geometry.indices[3 * size_t(sorted[i]) + size_t(c)];
    }
    mSceneTriangle = std::move(sorted);
    mEveryLight.resize(inputs.lights->lights.size());
    std::iota(mEveryLight.begin(), mEveryLight.end(), 0u);
    return true;
}

gbuffer::Surface BlendedPass::surfaceOf(const raster::Fragment& fragment, uint32_t triangle,
                                        float& alpha) const {
    gbuffer::Surface s = mVisibility.surfaceAt(
        gbuffer::VisibilityPass::code(triangle, fragment.frontFacing), fragment.x, fragment.y);
    s.positionView = mDepthDecoder->positionView(fragment.x, fragment.y, fragment.depth);
    alpha = gbuffer::AlphaCoverage::alphaAt(*mInputs->scene, *mInputs->geometry,
                                            mVisibility.clipPositions(), *mInputs->view, triangle,
                                            fragment.x, fragment.y);
    return s;
}

std::span<const float> BlendedPass::testedDepth(std::span<const float> opaqueDepth) const {
    const std::span<const float> tested =
        mLayered ? std::span<const float>(*mInputs->sampleDepths) : opaqueDepth;
    const size_t expected =
        size_t(mInputs->view->width) * size_t(mInputs->view->height) * size_t(mSamples);
    if (tested.size() != expected)
        throw std::invalid_argument("BlendedPass: the opaque depth holds " +
                                    std::to_string(tested.size()) + " floats, the frame " +
                                    std::to_string(expected) + " (" + std::to_string(mSamples) +
                                    " per pixel)");
    return tested;
}

uint8_t BlendedPass::runSamples(size_t pixel) const {
    const gbuffer::FragmentLayers& layers = *mInputs->fragmentLayers;
    const uint8_t all = uint8_t((1u << mSamples) - 1u);
    const int layer = mInputs->fragmentLayer;
    if (layer == StageInputs::kBackgroundRun) {
        // The background samples of a covered pixel (an uncovered one is layer 0's).
        if (layers.coverage(0)[pixel] == 0)
            return 0;
        uint8_t surfaces = 0;
        for (int k = 0; k < layers.layerCount(); ++k)
            surfaces |= layers.coverage(k)[pixel];
        return uint8_t(all & ~surfaces);
    }
    const uint8_t mask = layers.coverage(layer)[pixel];
    return layer == 0 && mask == 0 ? all : mask;
}

std::span<const float> BlendedPass::listBounds(std::span<const float> opaqueDepth) {
    if (mSamples == 1)
        return opaqueDepth;
    const std::span<const float> tested = testedDepth(opaqueDepth);
    const size_t width = size_t(mInputs->view->width);
    const size_t pixelCount = width * size_t(mInputs->view->height);
    const size_t samples = size_t(mSamples);
    const bool reversed = mInputs->view->reversedZ();
    auto farther = [reversed](float a, float b) {
        return reversed ? std::min(a, b) : std::max(a, b);
    };
    mBounds.resize(pixelCount);
    tbb::parallel_for(size_t(0), pixelCount, [&](size_t pixel) {
        const float* sample = tested.data() + pixel * samples;
        float bound = sample[0];
        for (size_t s = 1; s < samples; ++s)
            bound = farther(bound, sample[s]);
        mBounds[pixel] = bound;
    });
    draw(opaqueDepth, [&](const raster::Fragment& fragment) {
        float& bound = mBounds[size_t(fragment.y) * width + size_t(fragment.x)];
        bound = farther(bound, fragment.depth);
    });
    return mBounds;
}

void BlendedPass::beginComposite(StageResult& result) {
    mComposite = mTarget;
    if (mLayered) {
        mLayerSamples.resetUnfilled(result.width, result.height, mSamples);
        mComposite = &mLayerSamples;
    }
}

void BlendedPass::compositeOver(const raster::Fragment& fragment, const glm::vec3& lit, float alpha,
                                StageResult& result) {
    const size_t pixel = size_t(fragment.y) * size_t(result.width) + size_t(fragment.x);
    if (!mComposite) {
        for (int c = 0; c < 3; ++c)
            result.radiance[c][pixel] = alpha * lit[c] + (1.0f - alpha) * result.radiance[c][pixel];
        return;
    }
    mComposite->over(pixel, fragment.coverage, lit, alpha, result);
}

void BlendedPass::endComposite(StageResult& result) {
    if (!mLayered)
        return;
    // Each pixel a fragment reached: the mean of the run's own samples.
    const size_t width = size_t(result.width);
    tbb::parallel_for(0, result.height, [&](int y) {
        for (size_t pixel = size_t(y) * width; pixel < size_t(y + 1) * width; ++pixel) {
            if (!mLayerSamples.filled(pixel))
                continue;
            const uint8_t own = runSamples(pixel);
            const float count = float(std::popcount(own));
            for (int c = 0; c < 3; ++c) {
                const float* sample = mLayerSamples.pixel(c, pixel);
                float sum = 0.0f;
                for (int s = 0; s < mSamples; ++s)
                    if (own >> s & 1u)
                        sum += sample[s];
                result.radiance[c][pixel] = sum / count;
            }
        }
    });
    mComposite = nullptr;
}

std::span<const uint32_t> BlendedPass::contributingLights(const gbuffer::Surface& point) const {
    thread_local std::vector<uint32_t> list;
    list.clear();
    const glm::vec3 toViewer = glm::normalize(-point.positionView);
    const std::vector<LightInView<float>>& lights = mInputs->lights->lights;
    for (uint32_t l = 0; l < lights.size(); ++l)
        if (contributes(evaluateLight(point, toViewer, lights[l])))
            list.push_back(l);
    return list;
}

void BlendedPass::shadeWithContributingLights(std::span<const float> opaqueDepth,
                                              StageResult& result) {
    PassTimer blendPass(result, pass::kBlend);
    beginComposite(result);
    mShading.begin(*mInputs, FragmentApply::Over, result, mComposite);
    draw(opaqueDepth, [&](const raster::Fragment& fragment) {
        const uint32_t triangle = mSceneTriangle[fragment.triangle];
        float alpha = 0.0f;
        const gbuffer::Surface point = surfaceOf(fragment, triangle, alpha);
        mShading.addCopyingList(fragment, triangle, point, contributingLights(point), alpha);
    });
    mShading.flush();
    mShading.end();
    endComposite(result);
    blendPass.stop();
}

void BlendedPass::shadeWithTileLists(std::span<const float> opaqueDepth, int tileSizePixels,
                                     bool viewFrustumCulling, StageResult& result) {
    PassTimer blendPass(result, pass::kBlend);
    const TileGrid grid = TileGrid::make(result.width, result.height, tileSizePixels);
    const std::vector<std::vector<uint32_t>> lists =
        blendedTileLightLists(*mInputs, listBounds(opaqueDepth), grid, viewFrustumCulling);
    shade(
        opaqueDepth,
        [&](int x, int y, const gbuffer::Surface&, uint32_t) {
            return std::span<const uint32_t>(
                lists[size_t((y / tileSizePixels) * grid.tileCountX + x / tileSizePixels)]);
        },
        result, blendPass);
}

void BlendedPass::compositeExact(std::span<const float> opaqueDepth, StageResult& result) {
    if (opaqueDepth.size() != size_t(result.width) * size_t(result.height))
        throw std::invalid_argument("BlendedPass::compositeExact: one depth sample per pixel");
    PassTimer blendPass(result, pass::kBlend);
    const size_t width = size_t(result.width);
    // Every blended fragment of each pixel (scene triangle, back face), in any order: sorted per
    // pixel below. Each list is written by the thread owning the pixel's raster tile.
    struct Layer {
        uint32_t triangle;
        bool backFace;
        double distance;
    };
    std::vector<std::vector<Layer>> layers(width * size_t(result.height));
    draw(opaqueDepth, [&](const raster::Fragment& fragment) {
        layers[size_t(fragment.y) * width + size_t(fragment.x)].push_back(
            {mSceneTriangle[fragment.triangle], !fragment.frontFacing, 0.0});
    });
    const std::vector<LightInView<double>>& lights = mInputs->lights->lightsExact;
    const scenes::Scene& scene = *mInputs->scene;
    const gbuffer::SceneGeometry& geometry = *mInputs->geometry;
    const gbuffer::CameraView& view = *mInputs->view;
    tbb::parallel_for(0, result.height, [&](int y) {
        for (int x = 0; x < result.width; ++x) {
            const size_t pixel = size_t(y) * width + size_t(x);
            std::vector<Layer>& list = layers[pixel];
            if (list.empty())
                continue;
            std::vector<gbuffer::BasicSurface<double>> surfaces(list.size());
            std::vector<double> alphas(list.size());
            for (size_t i = 0; i < list.size(); ++i) {
                raster::Fragment fragment;
                fragment.x = x;
                fragment.y = y;
                fragment.triangle = list[i].triangle;
                fragment.frontFacing = !list[i].backFace;
                float alpha = 0.0f;
                // Material values (albedo, specular, model) and alpha as the stages read them;
                // position and normal from the exact hit (the float ones if the ray is edge-on).
                const gbuffer::Surface material = surfaceOf(fragment, list[i].triangle, alpha);
                alphas[i] = double(alpha);
                gbuffer::BasicSurface<double>& s = surfaces[i];
                s.positionView = glm::dvec3(material.positionView);
                s.normalView = glm::dvec3(material.normalView);
                gbuffer::ExactSurface::hit(scene, geometry, view, list[i].triangle,
                                           list[i].backFace, x, y, s.positionView, s.normalView);
                s.albedo = glm::dvec3(material.albedo);
                s.specularIntensity = double(material.specularIntensity);
                s.specularPower = double(material.specularPower);
                s.roughness = double(material.roughness);
                s.metallic = double(material.metallic);
                s.occlusion = double(material.occlusion);
                s.emissive = glm::dvec3(material.emissive);
                s.model = material.model;
                s.material = material.material;
                list[i].distance = glm::length(s.positionView);
            }
            std::vector<size_t> order(list.size());
            std::iota(order.begin(), order.end(), size_t(0));
            std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
                if (list[a].distance != list[b].distance)
                    return list[a].distance > list[b].distance; // farthest first
                return list[a].triangle < list[b].triangle;
            });
            glm::dvec3 colour(result.radiance[0][pixel], result.radiance[1][pixel],
                              result.radiance[2][pixel]);
            for (const size_t i : order) {
                const gbuffer::BasicSurface<double>& s = surfaces[i];
                const glm::dvec3 toViewer = glm::normalize(-s.positionView);
                glm::dvec3 sum(0.0);
                uint32_t contributing = 0;
                const shadows::ExactShadowLookup* shadows = mInputs->exactShadows;
                for (size_t l = 0; l < lights.size(); ++l) {
                    const glm::dvec3 radiance = evaluateLight(s, toViewer, lights[l]);
                    const bool contributesHere = contributes(radiance);
                    // The reference's shadows (ray-traced), as for its opaque surfaces
                    // (EveryLight.h): the stages shade blended fragments through the kernel,
                    // whose shadow maps apply to them alike.
                    if (shadows && contributesHere && shadows->casts(l))
                        sum += radiance * shadows->visibility(l, s.positionView, s.normalView);
                    else
                        sum += radiance;
                    contributing += contributesHere ? 1u : 0u;
                }
                sum += s.emissive; // as shade(): emitted plus lit, then "over"
                colour = alphas[i] * sum + (1.0 - alphas[i]) * colour;
                result.lightsEvaluated[pixel] += uint32_t(lights.size());
                result.traceBlendedFragment(pixel, list[i].triangle, !list[i].backFace,
                                            mEveryLight);
                if (!result.lightsOracle.empty())
                    result.lightsOracle[pixel] += contributing;
            }
            for (int c = 0; c < 3; ++c)
                result.radiance[c][pixel] = float(colour[c]);
        }
    });
    blendPass.stop();
}

void BlendedPass::addOracle(std::span<const float> opaqueDepth, std::vector<uint32_t>& oracle) {
    const std::vector<LightInView<float>>& lights = mInputs->lights->lights;
    const size_t width = size_t(mInputs->view->width);
    draw(opaqueDepth, [&](const raster::Fragment& fragment) {
        float alpha = 0.0f;
        const gbuffer::Surface point =
            surfaceOf(fragment, mSceneTriangle[fragment.triangle], alpha);
        const glm::vec3 toViewer = glm::normalize(-point.positionView);
        uint32_t contributing = 0;
        for (const LightInView<float>& light : lights)
            contributing += contributes(evaluateLight(point, toViewer, light)) ? 1u : 0u;
        oracle[size_t(fragment.y) * width + size_t(fragment.x)] += contributing;
    });
}

} // namespace lighting
