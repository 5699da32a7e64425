// LightList: the scene's lights transformed into view space for one frame, in float (for stages)
// and double (for the reference), built from the double-precision camera matrix.
#pragma once

#include <vector>

#include "gbuffer/visibility/CameraView.h"
#include "lighting/brdf/Brdf.h"
#include "scenes/Scene.h"

namespace lighting {

struct LightList {
    std::vector<LightInView<float>> lights;
    std::vector<LightInView<double>> lightsExact;

    static LightList build(const std::vector<scenes::Light>& sceneLights,
                           const gbuffer::CameraView& view);
    size_t size() const { return lights.size(); }
};

} // namespace lighting
