// SceneRequest: what the caller asks of a scene besides its name or file: how many generated
// lights, the seed that places them, and scene-specific options (e.g. wall's "behind=1000").
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace scenes {

struct SceneRequest {
    int lightCount = 0; // generated point lights, placed deterministically from seed
    uint64_t seed = 1;
    // Scene-specific options as key=value. A builder must reject keys it does not know
    // (SceneError naming the key and the valid ones), never silently ignore them.
    std::map<std::string, std::string> options;
};

} // namespace scenes
