// UniformPixels: the common case of FragmentLayers' row build (FragmentLayers.h) on SIMD lanes.
// Most pixels show one triangle, or none, at every sample; their layer-0 entry is sample 0's code
// and centre depth, and their byte planes are constants. writeUniformRow writes those values at
// EVERY pixel of a row, as if each were uniform, and lists the pixels whose samples differ
// (ascending): FragmentLayers then overwrites those one by one (fragment search, merge test,
// upper layers). Splitting the row this way takes the per-pixel branch off the common case, which
// is about 98% of atrium's pixels at 4x.
//
// Lanes through Google Highway with run-time dispatch (UniformPixels.cpp, one copy per
// instruction set): 2 and 4 samples are de-interleaved with LoadInterleaved2/4; 8 samples and the
// row's last partial vector run the scalar loop, which stays as the oracle
// (writeUniformRowScalar). Exact: the lanes copy and compare, they compute nothing, so both write
// bitwise the same planes, list and count (NaN depths included: a NaN centre depth is not the
// clear value in either).
#pragma once

#include <cstddef>
#include <cstdint>

namespace gbuffer {

// What writeUniformRow may write past the end of `mixed`: a vector's compress-store writes whole
// vectors (at most 64 lanes of uint32 on any target this builds).
inline constexpr size_t kMixedPixelSlack = 64;

struct UniformRowArgs {
    const uint32_t* codes = nullptr;     // `samples` codes per pixel, pixel-major
    const float* centreDepths = nullptr; // as codes: the sample's triangle's depth at the centre
    int pixels = 0;
    int samples = 0;               // 2, 4 or 8
    uint32_t noTriangle = 0;       // the code of a background sample
    float clear = 0.0f;            // the depth of a pixel no sample covers
    float nearerClear = 0.0f;      // a covered pixel's depth where its centre depth is `clear`
    uint32_t* mainCodes = nullptr; // out, per pixel: layer 0's code, depth, coverage mask,
    float* mainDepths = nullptr;   // background samples and complex flag
    uint8_t* mainCoverage = nullptr;
    uint8_t* background = nullptr;
    uint8_t* complex = nullptr;
    uint32_t* mixed = nullptr; // out: the pixels whose samples differ; room for pixels + slack
};

struct UniformRowResult {
    int mixedCount = 0;                // entries written to `mixed`
    uint64_t coveredUniformPixels = 0; // uniform pixels whose samples show a triangle
};

// Per pixel x: mainCodes = codes[x * samples]; mainDepths = clear where that code is noTriangle,
// else its centre depth, or nearerClear where that depth equals clear; mainCoverage = all samples
// (covered) or 0; background = 0 (covered) or samples; complex = 0. Pixels whose samples do not
// all show sample 0's code are listed in `mixed`. Cost O(pixels x samples).
UniformRowResult writeUniformRow(const UniformRowArgs& args);
// The scalar loop: the oracle of the lanes.
UniformRowResult writeUniformRowScalar(const UniformRowArgs& args);

} // namespace gbuffer
