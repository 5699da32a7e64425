#include "lighting/ShadingStage.h"

namespace lighting {

void StageResult::resize(int w, int h, bool withOracle) {
    width = w;
    height = h;
    const size_t n = size_t(w) * h;
    for (auto& plane : radiance)
        plane.assign(n, 0.0f);
    lightsEvaluated.assign(n, 0);
    lightsOracle.assign(withOracle ? n : 0, 0);
    lightingSamples.clear();
    timingsMs.clear();
    parameters.clear();
    lightTrace.assign(traceLights ? n : 0, {});
    blendedTrace.assign(traceLights ? n : 0, {});
}

} // namespace lighting
