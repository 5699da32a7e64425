// Built-in procedural scenes, registered by name, needing no file:
//   atrium  (default) Sponza-like courtyard, >= 250k triangles, camera along the nave
//   wall    long wall seen at an angle, lights on both sides ("behind=N" lights behind it)
//   spheres analytic spheres on a plane, for precision tests
//   glass   alpha-tested (MASK) and overlapping blended (BLEND) panes, for transparency
// Each builder places request.lightCount point lights itself (scene-appropriate region and radii)
// and may add one directional and one ambient light.
#pragma once

#include <string>
#include <vector>

#include "scenes/Scene.h"
#include "scenes/SceneRequest.h"

namespace scenes {

inline constexpr const char* kDefaultSceneName = "atrium";

std::vector<std::string> proceduralSceneNames();
bool isProceduralScene(const std::string& name);
// Throws SceneError for an unknown name (listing the valid ones) or an unknown/invalid option.
Scene buildProceduralScene(const std::string& name, const SceneRequest& request);

} // namespace scenes
