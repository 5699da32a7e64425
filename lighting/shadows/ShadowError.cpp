#include "lighting/shadows/ShadowError.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "lighting/brdf/Brdf.h"
#include "lighting/shadows/LightReaches.h"

namespace lighting::shadows {

ShadowErrorCounts measureShadowError(const StageInputs& frame, const ExactShadowLookup& truth) {
    if (!frame.shadows)
        throw std::invalid_argument("measureShadowError: the frame has no shadow maps");
    const gbuffer::GBuffer& gbuffer = *frame.gbuffer;
    // Without normals every pair's facing test and slope bias would read a made-up normal.
    if (!gbuffer.layout().provides(gbuffer::Channel::Normal))
        throw std::invalid_argument(
            "measureShadowError: the G-buffer stores no normals (give it a lossless one)");
    const int width = frame.view->width, height = frame.view->height;
    const std::vector<LightInView<float>>& lights = frame.lights->lights;
    std::vector<uint32_t> casting;
    for (uint32_t i = 0; i < lights.size(); ++i)
        if (lights[i].type != scenes::LightType::Ambient &&
            frame.shadows->shadowOf(i) != kNoShadow && truth.casts(i))
            casting.push_back(i);
    ShadowErrorCounts counts;
    const size_t pixels = size_t(width) * size_t(height);
    counts.litShouldBeShadowedAt.assign(pixels, 0);
    counts.shadowedShouldBeLitAt.assign(pixels, 0);
    struct Sums {
        uint64_t pairs = 0, truthShadowed = 0, litWrong = 0, shadowWrong = 0;
    };
    const Sums total = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, height), Sums{},
        [&](const tbb::blocked_range<int>& rows, Sums sums) {
            for (int y = rows.begin(); y < rows.end(); ++y)
                for (int x = 0; x < width; ++x) {
                    gbuffer::Surface s;
                    if (!gbuffer.surfaceAt(x, y, s))
                        continue;
                    const size_t pixel = size_t(y) * size_t(width) + size_t(x);
                    for (uint32_t light : casting) {
                        if (!lightReaches(s, lights[light]))
                            continue;
                        ++sums.pairs;
                        const bool mapLit =
                            frame.shadows->visibility(frame.shadows->shadowOf(light),
                                                      s.positionView, s.normalView) >= 0.5f;
                        const bool rayLit = truth.visibility(light, glm::dvec3(s.positionView),
                                                             glm::dvec3(s.normalView)) >= 0.5;
                        sums.truthShadowed += rayLit ? 0 : 1;
                        if (mapLit && !rayLit) {
                            ++sums.litWrong;
                            uint16_t& at = counts.litShouldBeShadowedAt[pixel];
                            at = uint16_t(std::min<int>(at + 1, 65535));
                        } else if (!mapLit && rayLit) {
                            ++sums.shadowWrong;
                            uint16_t& at = counts.shadowedShouldBeLitAt[pixel];
                            at = uint16_t(std::min<int>(at + 1, 65535));
                        }
                    }
                }
            return sums;
        },
        [](Sums a, const Sums& b) {
            a.pairs += b.pairs;
            a.truthShadowed += b.truthShadowed;
            a.litWrong += b.litWrong;
            a.shadowWrong += b.shadowWrong;
            return a;
        });
    counts.pairs = total.pairs;
    counts.truthShadowed = total.truthShadowed;
    counts.litShouldBeShadowed = total.litWrong;
    counts.shadowedShouldBeLit = total.shadowWrong;
    return counts;
}

} // namespace lighting::shadows
