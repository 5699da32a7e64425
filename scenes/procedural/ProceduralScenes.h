// Built-in procedural scenes, registered by name, needing no file:
//   atrium  (default) Sponza-like courtyard, >= 250k triangles, camera along the nave
//   wall    long wall seen at an angle, lights on both sides ("behind=N" lights behind it),
//           optionally "clutter=N" street-furniture objects on both sides (shadow-casting sets)
//   spheres analytic spheres on a plane, for precision tests
//   glass   alpha-tested (MASK) and overlapping blended (BLEND) panes, for transparency
//   foliage alpha-masked leaf cards (about a texel per pixel), for alpha-to-coverage
// Each builder places request.lightCount point lights itself (scene-appropriate region and radii)
// and may add one directional and one ambient light.
#pragma once

#include <string>
#include <vector>

#include "scenes/Scene.h"
#include "scenes/SceneRequest.h"

namespace scenes {

inline constexpr const char* kDefaultSceneName = "atrium";

// One option of a built-in scene (`--scene-option key=value`): an integer in minValue..maxValue,
// defaultValue when not given (0|1 switches for the ambient and sun lights).
struct SceneOption {
    std::string key;
    int defaultValue;
    int minValue;
    int maxValue;
    std::string meaning;
};

std::vector<std::string> proceduralSceneNames();
// The options of a built-in scene, in its table's order, as its builder reads them for a request
// of `lightCount` generated lights (wall's behind is at most the light count). Throws SceneError
// for an unknown name.
std::vector<SceneOption> proceduralSceneOptions(const std::string& name, int lightCount);
bool isProceduralScene(const std::string& name);
// Throws SceneError for an unknown name (listing the valid ones) or an unknown/invalid option.
Scene buildProceduralScene(const std::string& name, const SceneRequest& request);

} // namespace scenes
