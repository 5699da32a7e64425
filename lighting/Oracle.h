// Oracle: how many lights contribute at each pixel (a light contributes where its radiance at the
// pixel's surface from the G-buffer is non-zero: Brdf.h contributes()). Culling stages are
// checked against it: at every pixel a stage must evaluate at least this many lights. Blended
// fragments (BlendedPass.h) add their contributing lights at their pixel, as the stages add the
// lights they evaluate there.
//
// countContributingLights is exact and fast: it evaluates only the candidates of a LightGrid
// (lists/LightGrid.h) over the visible surfaces, a superset of the contributing lights, so its
// cost grows with the lights near each surface, not with the scene's light count.
// countContributingLightsBrute evaluates every light at every pixel; the tests hold the two
// equal pixel by pixel (tests/lighting/stages/stage_exactness_test.cpp).
// Threads: rows in parallel, each pixel written by one task: no dependence on the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "lighting/ShadingStage.h"

namespace lighting {

std::vector<uint32_t> countContributingLights(const StageInputs& inputs);

// The occlusion-aware oracle (`--oracle visibility`): the lights that contribute AND reach the
// pixel's surface according to `visibility` (a light it does not cast for counts as reaching;
// the runner passes ray-traced visibility of every light, shadows/RayShadows.h). Culling
// efficiency against it says how much of a stage's work a perfect, occlusion-aware culling would
// still save. Blended fragments are counted unshadowed. Cost: one shadow ray per contributing
// pixel-light pair.
std::vector<uint32_t> countVisibleLights(const StageInputs& inputs,
                                         const shadows::ExactShadowLookup& visibility);
// The same counts by brute force over every light (the grid's check).
std::vector<uint32_t> countContributingLightsBrute(const StageInputs& inputs);

} // namespace lighting
