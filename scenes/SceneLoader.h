// One entry point for every scene source: a built-in procedural name, a .gltf/.glb model, or a
// .json scene file (which places glTF models and procedural objects, sets the camera and lists
// lights or a light generator). Errors are SceneError with one message naming the file and the
// problem; nothing here crashes or hangs on malformed input.
#pragma once

#include <filesystem>
#include <string>

#include "scenes/Scene.h"
#include "scenes/SceneRequest.h"

namespace scenes {

// A procedural name, or a path to .gltf/.glb/.json. For a glTF model without lights, the
// request's lightCount point lights are scattered with defaultScatterFor(); a default camera
// framing the bounds is added when the file has none.
Scene loadScene(const std::string& nameOrPath, const SceneRequest& request);

// glTF 2.0 (.gltf or .glb) through tinygltf: node hierarchy and transforms, triangle
// lists/strips/fans, indexed or not, normals computed when missing, first camera used.
// Unreadable textures give a warning (Scene::warnings and stderr) and fall back to the factor.
Scene loadGltf(const std::filesystem::path& path);

// A camera that frames the bounds (60 degree field of view, from the front and a little above),
// for files that bring none.
Camera cameraFramingBounds(const Aabb& boundsWorld);

// The JSON scene format (documented in scenes/README.md).
Scene loadJsonScene(const std::filesystem::path& path, const SceneRequest& request);

} // namespace scenes
