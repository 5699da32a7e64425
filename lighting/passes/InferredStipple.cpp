#include "lighting/passes/InferredStipple.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/parallel_for.h>

#include "lighting/brdf/SplitLighting.h"
#include "lighting/culling/BlendedTileLists.h"
#include "lighting/passes/DsfFilter.h"
#include "lighting/passes/LightAccumulation.h"

namespace lighting {

void InferredStipple::stipple(const StageInputs& inputs, BlendedPass& blended,
                              std::span<const float> opaqueDepth, const Lattice& lattice) {
    mLattice = lattice;
    mGeometry = inputs.geometry;
    const scenes::Scene& scene = *inputs.scene;
    const gbuffer::SceneGeometry& geometry = *inputs.geometry;
    const gbuffer::CameraView& view = *inputs.view;

    // Patterns: blended instances front to back by the view depth of their box centre.
    const size_t instanceCount = scene.instances.size();
    std::vector<float> nearest(instanceCount, std::numeric_limits<float>::infinity());
    std::vector<float> farthest(instanceCount, -std::numeric_limits<float>::infinity());
    for (uint32_t t = 0; t < geometry.triangleCount(); ++t) {
        if (scene.materials[geometry.triangleMaterial[t]].alphaMode != scenes::AlphaMode::Blend)
            continue;
        const uint32_t instance = geometry.triangleInstance[t];
        for (int c = 0; c < 3; ++c) {
            const glm::vec3 p = geometry.positionWorld[geometry.indices[3 * size_t(t) + c]];
            const float depth = -(view.viewFromWorld * glm::vec4(p, 1.0f)).z;
            nearest[instance] = std::min(nearest[instance], depth);
            farthest[instance] = std::max(farthest[instance], depth);
        }
    }
    std::vector<uint32_t> ranked;
    for (uint32_t i = 0; i < instanceCount; ++i)
        if (nearest[i] <= farthest[i])
            ranked.push_back(i);
    std::stable_sort(ranked.begin(), ranked.end(), [&](uint32_t a, uint32_t b) {
        return nearest[a] + farthest[a] < nearest[b] + farthest[b];
    });
    mPatternOfInstance.assign(instanceCount, -1);
    for (size_t rank = 0; rank < ranked.size(); ++rank)
        mPatternOfInstance[ranked[rank]] = int(rank % kTransparentLayers);

    // Which sample each full-res column and row holds (-1: none).
    std::vector<int> sampleOfColumn(size_t(lattice.width), -1),
        sampleOfRow(size_t(lattice.height), -1);
    for (int i = 0; i < lattice.lowWidth; ++i)
        sampleOfColumn[size_t(lattice.sampleX(i))] = i;
    for (int j = 0; j < lattice.lowHeight; ++j)
        sampleOfRow[size_t(lattice.sampleY(j))] = j;

    const size_t sampleCount = size_t(lattice.lowWidth) * size_t(lattice.lowHeight);
    mSamples.assign(sampleCount, Sample{});
    mSampleDepth.assign(sampleCount, std::numeric_limits<float>::infinity());
    blended.forEachFragment(opaqueDepth, [&](const raster::Fragment& fragment, uint32_t triangle,
                                             const gbuffer::Surface& surface, float) {
        const int i = sampleOfColumn[size_t(fragment.x)], j = sampleOfRow[size_t(fragment.y)];
        if (i < 0 || j < 0)
            return;
        const int pattern = patternOf(i, j);
        const uint32_t instance = geometry.triangleInstance[triangle];
        if (pattern >= kTransparentLayers || mPatternOfInstance[instance] != pattern)
            return;
        const size_t index = size_t(j) * size_t(lattice.lowWidth) + size_t(i);
        const float depth = -surface.positionView.z;
        if (!(depth < mSampleDepth[index])) // the nearest; the first drawn among equals
            return;
        mSampleDepth[index] = depth;
        Sample& sample = mSamples[index];
        sample.covered = true;
        sample.instance = instance;
        sample.surface = surface;
    });
}

void InferredStipple::light(const StageInputs& inputs, std::span<const float> opaqueDepth,
                            int tileSizeSamples, StageResult& result) {
    const Lattice& l = mLattice;
    const TileGrid grid = TileGrid::make(l.width, l.height, tileSizeSamples * l.scale);
    LightIndexLists lists;
    lists.assign(blendedTileLightLists(inputs, opaqueDepth, grid, true));
    const SplitLightSinkOf sink([&](const kernel::ShadingPacket& packet,
                                    const kernel::SplitPacketAccumulator& sums) {
        for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
            const int lane = __builtin_ctz(lanes);
            Sample& sample = mSamples[size_t(packet.y0 + kernel::laneY(lane)) * size_t(l.lowWidth) +
                                      size_t(packet.x0 + kernel::laneX(lane))];
            for (int c = 0; c < 3; ++c) {
                sample.light.diffuse[c] = sums.diffuse[c][lane];
                sample.light.specular[c] = sums.specular[c][lane];
                sample.light.specularEdge[c] = sums.specularEdge[c][lane];
            }
        }
    });
    SplitLightingOptions options;
    options.scale = l.scale;
    options.sampleSurfaces = [&](size_t index) -> const gbuffer::Surface* {
        return mSamples[index].covered ? &mSamples[index].surface : nullptr;
    };
    // Sample tile (tx, ty) is full-res tile (tx, ty) of `grid` (as the stage's own light pass).
    accumulateSplitLights(inputs, options, TileListSource(tileSizeSamples, grid.tileCountX, lists),
                          sink, result);
}

InferredStipple::Counts InferredStipple::composite(BlendedPass& blended,
                                                   std::span<const float> opaqueDepth,
                                                   const DsfOptions& options,
                                                   StageResult& result) const {
    const Lattice& l = mLattice;
    const size_t pixelCount = size_t(l.width) * size_t(l.height);
    // Per pixel, so that each count is written by the thread owning the pixel.
    std::vector<uint32_t> fragments(pixelCount, 0), fallbacks(pixelCount, 0), unlit(pixelCount, 0);
    const float halfScale = float(l.scale / 2);
    // The two lattice indices of pattern offset `offset` around sample coordinate `u` (in
    // samples) and the weight of the second; -1 for an index outside the L-buffer.
    auto taps = [](float u, int offset, int count, int& a, int& b, float& f) {
        const float m = (u - float(offset)) / 2.0f;
        const int m0 = int(std::floor(m));
        f = m - float(m0);
        a = 2 * m0 + offset;
        b = a + 2;
        // Clamp to the pattern's first and last index (keeping the parity).
        const int last = (count - 1 - offset) >= 0 ? offset + 2 * ((count - 1 - offset) / 2) : -1;
        a = last < 0 ? -1 : std::clamp(a, offset, last);
        b = last < 0 ? -1 : std::clamp(b, offset, last);
    };
    blended.beginComposite(result);
    blended.forEachFragment(opaqueDepth, [&](const raster::Fragment& fragment, uint32_t triangle,
                                             const gbuffer::Surface& surface, float alpha) {
        const size_t pixel = size_t(fragment.y) * size_t(l.width) + size_t(fragment.x);
        ++fragments[pixel];
        const uint32_t instance = mGeometry->triangleInstance[triangle];
        const int pattern = mPatternOfInstance[instance];
        const int ox = pattern & 1, oy = pattern >> 1;
        int ia, ib, ja, jb;
        float fx, fy;
        taps((float(fragment.x) - halfScale) / float(l.scale), ox, l.lowWidth, ia, ib, fx);
        taps((float(fragment.y) - halfScale) / float(l.scale), oy, l.lowHeight, ja, jb, fy);
        const int tapI[4] = {ia, ib, ia, ib}, tapJ[4] = {ja, ja, jb, jb};
        const float bilinear[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
        const float depth = -surface.positionView.z;
        DsfFilter filter;
        for (int k = 0; k < 4; ++k) {
            if (tapI[k] < 0 || tapJ[k] < 0)
                continue;
            const Sample& t = mSamples[size_t(tapJ[k]) * size_t(l.lowWidth) + size_t(tapI[k])];
            if (!t.covered)
                continue;
            const bool passesSurface =
                !(std::abs(-t.surface.positionView.z - depth) > options.depthThreshold * depth ||
                  glm::dot(t.surface.normalView, surface.normalView) < options.normalThreshold);
            filter.add(bilinear[k], t.light, passesSurface,
                       !options.objectIds || t.instance == instance);
        }
        SplitLighting light;
        switch (filter.resolve(light)) {
        case DsfFilter::Source::Same:
            break;
        case DsfFilter::Source::Surface:
        case DsfFilter::Source::Nearest:
            ++fallbacks[pixel];
            break;
        case DsfFilter::Source::None:
            ++unlit[pixel];
            break;
        }
        // The material's half of the split (both models, as the opaque material pass), then the
        // fragment's own emission, at full resolution, composited with its light (BlendedPass.h,
        // "Emission").
        const glm::vec3 lit =
            combineSplitLighting(surface, light.diffuse, light.specular, light.specularEdge) +
            surface.emissive;
        blended.compositeOver(fragment, lit, alpha, result);
    });
    blended.endComposite(result);
    Counts counts;
    for (size_t p = 0; p < pixelCount; ++p) {
        counts.fragments += fragments[p];
        counts.fallbacks += fallbacks[p];
        counts.unlit += unlit[p];
    }
    return counts;
}

} // namespace lighting
