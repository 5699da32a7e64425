// SceneRequest: what the caller asks of a scene besides its name or file: how many generated
// lights, the seed that places them, and scene-specific options (e.g. wall's "behind=1000").
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace scenes {

// How generated point lights scale with their count (scenes/procedural/LightGenerator.h):
//   FixedRadius      every count draws radii and intensities from the scene's own ranges, so the
//                    lights reaching a point grow in proportion to the count (the seeds' setting);
//   ConstantOverlap  radii scale with (kOverlapReferenceCount / count)^(1/3), so the expected
//                    number of lights reaching a point stays what it is at the reference count,
//                    and intensities scale to keep the mean radiance a light adds inside its
//                    sphere: a scaling curve then measures scaling, not overlap.
enum class LightDensity { FixedRadius, ConstantOverlap };

struct SceneRequest {
    // Generated point lights, placed deterministically from seed. Unset: the source decides: none
    // for built-in scenes and glTF models, a JSON scene's own lightGenerator (count and seed).
    // Set (0 included): that many, replacing a JSON scene's generator count and seed.
    std::optional<int> lightCount;
    uint64_t seed = 1;
    LightDensity lightDensity = LightDensity::FixedRadius;
    // Scene-specific options as key=value. A builder must reject keys it does not know
    // (SceneError naming the key and the valid ones), never silently ignore them.
    std::map<std::string, std::string> options;
};

} // namespace scenes
