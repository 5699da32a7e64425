// shadeWithEveryLight: the brute-force loop shared by the `brute` and `reference` stages and
// the oracle: every light at every covered pixel, in light order, rows in parallel (each pixel
// written by one task only, so the result is independent of the thread count).
// surfaceAt(x, y, point) fills a gbuffer::BasicSurface<T> and returns false for background pixels.
#pragma once

#include <cstdint>
#include <vector>

#include <tbb/parallel_for.h>

#include "lighting/Brdf.h"
#include "lighting/ShadingStage.h"

namespace lighting {

template <class T, class SurfaceAt>
void shadeWithEveryLight(int width, int height, const std::vector<LightInView<T>>& lights,
                         SurfaceAt&& surfaceAt, StageResult& result) {
    const bool countOracle = !result.lightsOracle.empty();
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            gbuffer::BasicSurface<T> point;
            if (!surfaceAt(x, y, point))
                continue;
            const size_t pixel = size_t(y) * width + x;
            const Vec3<T> toViewer = glm::normalize(-point.positionView);
            Vec3<T> sum(T(0));
            uint32_t contributing = 0;
            for (const LightInView<T>& light : lights) {
                const Vec3<T> radiance = evaluateLight(point, toViewer, light);
                sum += radiance;
                contributing += contributes(radiance) ? 1u : 0u;
            }
            result.radiance[0][pixel] = float(sum.x);
            result.radiance[1][pixel] = float(sum.y);
            result.radiance[2][pixel] = float(sum.z);
            result.lightsEvaluated[pixel] = uint32_t(lights.size());
            if (countOracle)
                result.lightsOracle[pixel] = contributing;
        }
    });
}

// The G-buffer's decoded surface at (x, y); false for background.
inline bool gbufferSurfaceAt(const gbuffer::GBuffer& gb, int x, int y, gbuffer::Surface& point) {
    if (!gb.covered(size_t(y) * gb.width() + x))
        return false;
    point = gb.decode(x, y);
    return true;
}

} // namespace lighting
