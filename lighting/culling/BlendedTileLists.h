// BlendedTileLists: the tile light lists of the tiled stages' blended pass (BlendedPass.h). The
// opaque pass's tile lists are bounded by the tile's opaque depth range, which a blended surface in
// front of it leaves; Forward+ therefore culls a second set of lists for transparent geometry
// over [near plane, the tile's farthest opaque depth] (the far plane where the tile shows
// background), which is what this builds, with the same per-tile test (appendTileLights: tile
// columns and rows, depth range, box distance; no 2.5D mask and no normal cone, which describe
// the opaque samples only). Ascending lists, conservative for every blended fragment in front of
// the opaque depth, so the blended composite stays bitwise brute's.
// Cost O(pixels + tiles x candidate lights), parallel over tiles; deterministic.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lighting/ShadingStage.h"
#include "lighting/culling/TileFrusta.h"

namespace lighting {

// Lists of every tile of `grid` (indexed ty * tileCountX + tx) for the frame of `inputs`, with
// opaqueDepth the frame's opaque depth plane (the view's convention; one or several samples per
// pixel, pixel-major, every sample bounded) and viewFrustumCulling as the stage's `vfc` option.
std::vector<std::vector<uint32_t>> blendedTileLightLists(const StageInputs& inputs,
                                                         std::span<const float> opaqueDepth,
                                                         const TileGrid& grid,
                                                         bool viewFrustumCulling);

} // namespace lighting
