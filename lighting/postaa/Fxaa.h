// Fxaa: luminance-edge anti-aliasing after Lottes' FXAA 3.11, the PC "quality" algorithm
// (Timothy Lottes, NVIDIA, FXAA 3.11, 2011; FxaaPixelShader with FXAA_PC = 1), on the CPU. It
// reads the shaded image only (no G-buffer), so it applies to every stage alike. README.md in this
// folder says what is Lottes' and what is ours.
//
// Per pixel, on a luma plane (below):
//   1. local contrast: the range of the luma of the pixel and its 4 neighbours; below
//      max(edgeThresholdMin, edgeThreshold * the largest luma) the pixel is copied (bitwise).
//   2. edge direction: horizontal or vertical, from the 3x3 second differences (Lottes' weights
//      1-2-1 across the centre row and column); the pixel's pair is the neighbour across the edge
//      with the steeper luma gradient.
//   3. end-of-edge search: from the point half-way between the pixel and its pair, step along the
//      edge in both directions (steps `kSearchSteps`, Lottes' quality preset 12) reading the pair
//      average by one bilinear fetch, until the luma leaves the edge's average by a quarter of the
//      gradient; the nearer end and whether its luma crosses the pixel's side decide the offset
//      towards the pair (0 .. 0.5 pixel).
//   4. sub-pixel aliasing: the 3x3 low-pass luma against the centre, relative to the range,
//      shaped (Lottes' subpixD..H) and scaled by `subpix`; the larger of the two offsets wins.
//   5. the colour: one bilinear fetch of the linear HDR radiance at the pixel moved by the offset
//      towards its pair, i.e. a blend of the pixel and its pair with the offset as weight.
//
// Luma: FXAA expects perceptual (gamma) luma of a displayable image, so each radiance channel is
// tone-mapped first, t = x / (1 + x) (Reinhard; HDR radiance is unbounded), then
// luma = sqrt(0.299 t_R + 0.587 t_G + 0.114 t_B) (Rec. 601 weights, gamma 2). Only the edge
// decisions see this; the blend weights apply to the linear HDR values.
//
// `edges` plane: the blend weight of the pair, the final offset in pixels (0 where the pixel was
// copied; at most 0.75 from the sub-pixel term).
//
// Threading: the luma plane, then tbb::parallel_for over rows; each output pixel depends on the
// inputs only, so the result is bitwise the same for any thread count.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "lighting/postaa/PostAaImage.h"

namespace lighting::postaa {

struct FxaaParameters {
    // Lottes' defaults (fxaaQualitySubpix, fxaaQualityEdgeThreshold, fxaaQualityEdgeThresholdMin).
    float subpix = 0.75f;             // amount of sub-pixel aliasing removal: 0 off .. 1 softest
    float edgeThreshold = 0.166f;     // minimum local contrast, relative to the largest luma
    float edgeThresholdMin = 0.0833f; // minimum local contrast in dark areas, absolute luma

    // Every parameter as text (the search steps included), for stats.json.
    std::map<std::string, std::string> describe() const;
};

// The end-of-edge search's step lengths in pixels: FXAA_QUALITY__PRESET 12, FXAA 3.11's default
// (5 fetches each way, reaching 20.5 pixels from the pixel).
inline constexpr float kSearchSteps[] = {1.0f, 1.5f, 2.0f, 4.0f, 12.0f};

// The luma FXAA decides on (above) of every pixel into `luma` (width x height).
void fxaaLuma(const RadianceIn& in, std::vector<float>& luma);

// The whole filter: the anti-aliased radiance into out.rgb and the blend weights into out.edges.
// `luma` is scratch (resized); `out` must not alias `in`. Parallel (TBB), deterministic.
void fxaa(const FxaaParameters& parameters, const RadianceIn& in, const RadianceOut& out,
          std::vector<float>& luma);

} // namespace lighting::postaa
