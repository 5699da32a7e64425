// SupersampledReference: the anti-aliased ground truth every stage is measured against. The
// `reference` stage (double precision, exact surface, every light) samples each pixel at its
// centre; this renders it N times with the camera jittered by a sub-pixel offset
// (gbuffer::CameraView::pixelOffset, a translation of the projection in clip space, so the
// rasterizer, the exact surface and position from depth agree on the sample point) and averages:
// a box filter over the pixel, accumulated in double, rounded to float once.
//
// Sample positions (offsets from the pixel centre in pixels, x right, y down; the same for every
// pixel, since a sub-frame is a whole jittered frame):
//   1        the centre: bitwise the `reference` stage's image (one unjittered frame).
//   16       the D3D 16x standard pattern (in 1/16 pixel: (1,1), (-1,-3), ... (-7,-8)).
//   k x k    (4, 9, 25, ... 256) a stratified grid: one sample per cell of a k x k grid, placed
//            uniformly inside its cell by a fixed-seed generator (splitmix64, seed
//            kStratifiedSeed), so every run and machine uses the same positions. Stratified
//            rather than regular so that edges aligned with the pixel grid do not alias into
//            k + 1 levels.
// Other counts are refused (referenceSppProblem): the grid needs a square, and above 256 the
// reference's time (N times a 1-sample reference) buys no visible accuracy.
//
// Coverage: a sample that sees the background contributes zero radiance (what the `reference`
// stage writes there), so edges against the background are anti-aliased too. Blended surfaces
// are composited per sub-frame by the `reference` stage itself.
//
// Counts: lightsEvaluated (and lightsOracle when the stage fills it) are the per-pixel mean over
// the sub-frames, rounded to nearest (the same unit as a 1-sample stage's). Timings are the
// sub-frames' passes summed per pass; parameters are the last sub-frame's plus `reference_spp`
// and `reference_pattern`.
//
// Cost: N times the 1-sample reference (each sub-frame rasterizes the G-buffer and the exact
// surface again); memory is one sub-frame plus a double accumulator (24 bytes per pixel).
// Deterministic: sub-frames are summed in sample order per pixel, whatever the thread count.
// Runs under the caller's tbb::task_arena.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "lighting/ShadingStage.h"
#include "lighting/shadows/ShadowSettings.h"
#include "scenes/Scene.h"

namespace lighting {

inline constexpr int kMaxReferenceSpp = 256;
inline constexpr int kDefaultReferenceSpp = 16;
inline constexpr uint64_t kStratifiedSeed = 0x5eed5eedULL;

// "" when `samplesPerPixel` is accepted, else why not (for the CLI's message).
std::string referenceSppProblem(int samplesPerPixel);
// The sample offsets from the pixel centre, pixels, y down, in the order they are summed; each in
// [-0.5, 0.5)^2. Throws std::invalid_argument for a count referenceSppProblem refuses.
std::vector<glm::dvec2> referenceSampleOffsets(int samplesPerPixel);
// "centre", "d3d16" or "stratified-KxK".
std::string referenceSamplePattern(int samplesPerPixel);

// The supersampled reference of `scene` (its first camera) at width x height: the lossless
// layout with reversed float depth, as the sweep's reference (experiments/render/RenderJob.h).
// shadowSettings: the frame's shadow settings (`--shadows maps`), or none: the reference then
// shadows the same casting lights by ray tracing (shadows/RayShadows.h), once per sub-frame sample.
StageResult renderSupersampledReference(scenes::Scene scene, int width, int height,
                                        int samplesPerPixel,
                                        const std::optional<ShadowSettings>& shadowSettings = {});

} // namespace lighting
