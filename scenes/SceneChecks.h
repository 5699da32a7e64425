// SceneChecks: the rules every scene satisfies before it is rendered, written once (issue 32,
// classes 1 and 2). validate(const Scene&) (Scene.h) applies them to a whole scene, naming the
// element (mesh, instance, camera, light, material); the loaders apply the same functions where
// they build each element, naming the file's field (a glTF node, a JSON scene's
// "objects[1].transform"), so a hostile value is refused where the user wrote it and, whatever
// path it took, never reaches the renderer.
//
// The rules are checked in float, the precision the renderer uses, on derived quantities
// (composed transforms, placed bounds, colour x intensity, view matrices) as well as on the
// values read (scenes/input/FloatRange.h narrows each one):
//   transforms   every entry finite;
//   placement    a mesh's bounds placed by its instance's transform lie within
//                +-limits::kMaxCoordinateMetres on every axis (so do light positions, cameras);
//   lengths      ranges, near and far planes finite and at most kMaxCoordinateMetres;
//   radiance     a light's colour x intensity and a material's emissive x strength, per channel
//                in float, finite and at most limits::kMaxRadiance;
//   cameras      forward and up unit, not within kMinUpViewSine of parallel, 0 < near < far,
//                0 < fov < 3.1 rad, and the float view matrix (viewFromWorld) finite.
// Every function returns "" when the value is fine, else the problem as text without the
// element's name ("its world transform has an infinite entry"). Pure, thread-safe.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "scenes/Scene.h"

namespace scenes {

// A camera's up vector must make at least this sine with its viewing direction (0.057 degrees):
// closer, the float cross product that gives the image's horizontal axis is mostly rounding
// error (a visible, arbitrary roll); parallel, it is zero and the view matrix NaN.
inline constexpr float kMinUpViewSine = 1e-3f;

std::string transformProblem(const glm::mat4& worldFromObject);
// A world-space point (light position, camera position, placed corner).
std::string pointProblem(const glm::vec3& pointWorld);
// A length in metres (a range, a near or far plane): finite, >= 0, at most kMaxCoordinateMetres.
std::string lengthProblem(float metres);
// Linear RGB (colour or emissive) times a scalar (intensity or strength), in float.
std::string radianceProblem(const glm::vec3& color, float scale);
// The object-space bounds of a mesh placed by worldFromObject (transformProblem first).
std::string placedBoundsProblem(const Aabb& boundsObject, const glm::mat4& worldFromObject);
std::string cameraProblem(const Camera& camera);
std::string lightProblem(const Light& light);
std::string materialProblem(const Material& material);

// A mesh's object-space bounds (empty for a mesh without positions).
Aabb boundsOf(const Mesh& mesh);

} // namespace scenes
