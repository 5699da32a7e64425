// Oracle: how many lights contribute at each pixel, counted by brute force over every light
// from the G-buffer. Culling stages are checked against it: at every pixel a stage must evaluate
// at least this many lights. Blended fragments (BlendedPass.h) add their contributing lights at
// their pixel, as the stages add the lights they evaluate there.
#pragma once

#include <cstdint>
#include <vector>

#include "lighting/ShadingStage.h"

namespace lighting {

std::vector<uint32_t> countContributingLights(const StageInputs& inputs);

} // namespace lighting
