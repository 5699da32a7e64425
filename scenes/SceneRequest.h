// SceneRequest: what the caller asks of a scene besides its name or file: how many generated
// lights, the seed that places them, and scene-specific options (e.g. wall's "behind=1000").
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace scenes {

struct SceneRequest {
    // Generated point lights, placed deterministically from seed. Unset: the source decides: none
    // for built-in scenes and glTF models, a JSON scene's own lightGenerator (count and seed).
    // Set (0 included): that many, replacing a JSON scene's generator count and seed.
    std::optional<int> lightCount;
    uint64_t seed = 1;
    // Scene-specific options as key=value. A builder must reject keys it does not know
    // (SceneError naming the key and the valid ones), never silently ignore them.
    std::map<std::string, std::string> options;
};

} // namespace scenes
