#include "lighting/ShadingStage.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace lighting {

namespace {
// `plane` sized n and zero-filled on the caller's TBB threads: a 1280x720 result is 15 MB of
// planes, cleared at every shade() call (once per fragment layer with MSAA), which one thread's
// memset made a visible share of the frame.
template <class T> void zeroFill(std::vector<T>& plane, size_t n) {
    if (plane.size() != n) {
        plane.assign(n, T{}); // another size (the first frame): allocated zeroed, once
        return;
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 16), [&](const auto& range) {
        std::fill(plane.begin() + range.begin(), plane.begin() + range.end(), T{});
    });
}
} // namespace

void StageResult::resize(int w, int h, bool withOracle) {
    width = w;
    height = h;
    const size_t n = size_t(w) * h;
    for (auto& plane : radiance)
        zeroFill(plane, n);
    zeroFill(lightsEvaluated, n);
    zeroFill(lightsOracle, withOracle ? n : 0);
    lightingSamples.clear();
    timingsMs.clear();
    parameters.clear();
    lightTrace.assign(traceLights ? n : 0, {});
    blendedTrace.assign(traceLights ? n : 0, {});
}

} // namespace lighting
