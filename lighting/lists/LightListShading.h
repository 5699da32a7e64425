// LightListShading: the per-pixel pieces shared by the stages that do not end in one light sum per
// pixel on the kernel: addEmission (deferred's light volumes, which accumulate light by light) and
// the split lighting of the light buffers (light-prepass, inferred). The per-pixel "sum the lights,
// store the pixel" loop it once held is gone: the G-buffer stages end in accumulateLights
// (LightAccumulation.h), the forward stages in FragmentShading (FragmentShading.h), both on the
// shared light kernel.
#pragma once

#include <cstdint>
#include <span>

#include <tbb/parallel_for.h>

#include "lighting/ShadingStage.h"
#include "lighting/brdf/Brdf.h"
#include "lighting/brdf/SplitLighting.h"

namespace lighting {

// Adds every covered pixel's emission (GBuffer::emission) to result.radiance, for the stages that
// accumulate light by light (deferred's volumes): once, after the last light, so the sum is the
// light sum plus the emission as in every other stage. Nothing to do when no material emits.
inline void addEmission(const gbuffer::GBuffer& gb, StageResult& result) {
    if (!gb.hasEmission())
        return;
    const int width = gb.width();
    tbb::parallel_for(0, gb.height(), [&](int y) {
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            if (!gb.covered(pixel))
                continue;
            const glm::vec3 emitted = gb.emission(pixel);
            for (int c = 0; c < 3; ++c)
                result.radiance[c][pixel] += emitted[c];
        }
    });
}

} // namespace lighting
