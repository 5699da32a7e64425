#include "lighting/culling/BlendedTileLists.h"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "gbuffer/GBufferLayout.h"
#include "lighting/culling/LightBounds.h"

namespace lighting {

std::vector<std::vector<uint32_t>> blendedTileLightLists(const StageInputs& inputs,
                                                         std::span<const float> opaqueDepth,
                                                         const TileGrid& grid,
                                                         bool viewFrustumCulling) {
    const gbuffer::CameraView& view = *inputs.view;
    const TileEdgePlanes edges = TileEdgePlanes::make(view, grid);
    const std::vector<LightSphere> spheres = boundingSpheresView(*inputs.lights);
    const std::vector<CandidateLight> candidates =
        candidateLights(view, grid, edges, spheres, viewFrustumCulling);
    // Blended fragments' positions come from their float depth through the lossless decoder
    // (BlendedPass.h); the opaque plane is read the same way.
    const gbuffer::DepthDecoder decoder =
        gbuffer::GBufferLayout::lossless(view.depthConvention, view.infiniteFar).depthDecoder(view);
    const float clear = view.clearDepth();
    const size_t samples = opaqueDepth.size() / (size_t(view.width) * size_t(view.height));
    std::vector<std::vector<uint32_t>> lists(size_t(grid.tileCount()));
    tbb::parallel_for(0, grid.tileCount(), [&](int tile) {
        const int tx = tile % grid.tileCountX, ty = tile / grid.tileCountX;
        float farthest = 0.0f;
        bool background = false;
        for (int y = grid.y0(ty); y < grid.y1(ty) && !background; ++y)
            for (int x = grid.x0(tx); x < grid.x1(tx) && !background; ++x)
                for (size_t s = 0; s < samples; ++s) {
                    const float depth =
                        opaqueDepth[(size_t(y) * size_t(view.width) + size_t(x)) * samples + s];
                    if (depth == clear) {
                        background = true;
                        break;
                    }
                    farthest = std::max(farthest, decoder.viewDepthMetres(x, y, depth));
                }
        TileSurfaceBounds bounds;
        bounds.covered = true;
        bounds.minDepthMetres = view.nearMetres;
        bounds.maxDepthMetres = background ? view.farMetres : std::max(farthest, view.nearMetres);
        const TileBox box =
            tileBox(edges, grid, tx, ty, bounds.minDepthMetres, bounds.maxDepthMetres);
        appendTileLights(candidates, tx, ty, bounds, box, {false, false}, lists[size_t(tile)]);
    });
    return lists;
}

} // namespace lighting
