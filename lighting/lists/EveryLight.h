// shadeWithEveryLight: the brute-force loop of the `brute` and `reference` stages and the oracle,
// written once: every light at every covered pixel, in light order, rows in parallel (each pixel
// written by one task only, so the result is independent of the thread count). The stages differ
// only in where the surface comes from and in the scalar type: surfaceAt(x, y, surface) fills a
// gbuffer::BasicSurface<T> and returns false for background pixels (GBuffer::surfaceAt for the
// G-buffer in float, gbuffer::ExactSurface::surfaceAt for the exact surface in double).
#pragma once

#include <cstdint>
#include <vector>

#include <tbb/parallel_for.h>

#include "gbuffer/Surface.h"
#include "lighting/ShadingStage.h"
#include "lighting/brdf/Brdf.h"
#include "lighting/lists/LightGrid.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

// Resizes `result` to width x height with the oracle plane, shades, and records the loop as the
// pass "shading". Per covered pixel: radiance summed over `lights` in order plus the surface's
// emission (in T: the reference adds it in double), lightsEvaluated =
// every light, lightsOracle = the lights that contribute. With a grid (LightGrid.h, built over the
// covered surfaces from the same lights), only its candidates are evaluated: the image and the
// counts are bitwise those of the full loop (lightsEvaluated still says every light: the others
// were decided by the grid, exactly).
// With `shadows` (the reference: ray-traced, double), a casting light's radiance is multiplied by
// its visibility where it contributes; the counts stay the unshadowed ones, as in the kernel.
template <class T, class SurfaceAt>
void shadeWithEveryLight(int width, int height, const std::vector<LightInView<T>>& lights,
                         const SurfaceAt& surfaceAt, StageResult& result,
                         const LightGrid* grid = nullptr,
                         const shadows::ExactShadowLookup* shadows = nullptr) {
    result.resize(width, height, true);
    PassTimer shading(result, pass::kShading);
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            gbuffer::BasicSurface<T> point;
            if (!surfaceAt(x, y, point))
                continue;
            const size_t pixel = size_t(y) * width + x;
            const Vec3<T> toViewer = glm::normalize(-point.positionView);
            Vec3<T> sum(T(0));
            uint32_t contributing = 0;
            auto add = [&](size_t index) {
                const Vec3<T> radiance = evaluateLight(point, toViewer, lights[index]);
                const bool contributesHere = contributes(radiance);
                if (shadows && contributesHere && shadows->casts(index))
                    sum += radiance * T(shadows->visibility(index, glm::dvec3(point.positionView),
                                                            glm::dvec3(point.normalView)));
                else
                    sum += radiance;
                contributing += contributesHere ? 1u : 0u;
            };
            if (!grid) {
                for (size_t index = 0; index < lights.size(); ++index)
                    add(index);
            } else {
                // The grid's two ascending lists merged: the same lights in the same order as
                // the loop above, less lights whose radiance here is exactly zero (outside their
                // range), which leave the sum unchanged bit for bit.
                const std::span<const uint32_t> a = grid->everywhere();
                const std::span<const uint32_t> b =
                    grid->candidatesAt(glm::vec3(point.positionView));
                size_t i = 0, j = 0;
                while (i < a.size() || j < b.size())
                    add(j == b.size() || (i < a.size() && a[i] < b[j]) ? a[i++] : b[j++]);
            }
            sum += point.emissive; // once per pixel, after the lights; counts unaffected
            result.radiance[0][pixel] = float(sum.x);
            result.radiance[1][pixel] = float(sum.y);
            result.radiance[2][pixel] = float(sum.z);
            result.lightsEvaluated[pixel] = uint32_t(lights.size());
            result.lightsOracle[pixel] = contributing;
            result.traceEveryLight(pixel, lights.size());
        }
    });
    shading.stop();
}

} // namespace lighting
