// ShadowError: how far a frame's shadow maps are from the ray-traced truth (issue 29 item 5), as
// visibility misclassification of pixel-light pairs: at every covered pixel of the G-buffer and
// every casting light that reaches it (range, cone and facing passed, so the pair would be lit
// without shadows), the map's visibility (>= 0.5 counts as lit) against one exact shadow ray from
// the same point. Two kinds of error, counted apart: lit but should be shadowed (light leaks,
// peter-panning, a caster missing from the map) and shadowed but should be lit (acne, too much
// filtering, a bias too small).
// Cost: one shadow ray and one map lookup per pair; rows in parallel, counts independent of the
// thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "lighting/ShadingStage.h"
#include "lighting/shadows/ShadowLookup.h"

namespace lighting::shadows {

struct ShadowErrorCounts {
    uint64_t pairs = 0;               // pixel-light pairs that a casting light reaches
    uint64_t truthShadowed = 0;       // of them, blocked according to the rays
    uint64_t litShouldBeShadowed = 0; // map >= 0.5, ray blocked
    uint64_t shadowedShouldBeLit = 0; // map < 0.5, ray clear
    // Per pixel (width x height): the two kinds of error, for shadow-error.png.
    std::vector<uint16_t> litShouldBeShadowedAt;
    std::vector<uint16_t> shadowedShouldBeLitAt;

    double misclassifiedFraction() const {
        return pairs ? double(litShouldBeShadowed + shadowedShouldBeLit) / double(pairs) : 0.0;
    }
};

// frame: its G-buffer (decoded per pixel; must store normals: a forward stage's depth-only
// G-buffer does not, measure on a lossless one), its view-space lights and its shadow maps
// (frame.shadows, not null); truth: the same lights' exact visibility.
ShadowErrorCounts measureShadowError(const StageInputs& frame, const ExactShadowLookup& truth);

} // namespace lighting::shadows
