// CullingTests: the conservative light tests every culling method shares (tiles, clusters,
// forward objects, light volumes) and the ONE slack policy they widen by. README.md of this folder
// states the policy and which test each stage uses.
//
// Slack policy (the only place its constants live, with LightBounds.h's light-sphere slack):
//   1. Light spheres carry the emitter side: boundingSpheresView (LightBounds.h) widens every
//      radius by kCullingSlack (relative) + kCullingSlackMetres (absolute).
//   2. A receiver bound built from the SAMPLES it bounds (a tile's depth range: the min/max of the
//      decoded positions, bitwise the ones shading uses) needs no slack.
//   3. A receiver bound built from anything else (cluster boxes from slice depths, forward
//      objects' boxes from float-transformed vertices, the view frustum from the camera) is
//      widened on every side by boundSlackMetres(magnitude) = kBoundSlack * magnitude +
//      kBoundSlackMetres, magnitude being the largest view-space distance involved: a
//      reconstructed position is off by a few ulps of its distance from the eye (~1e-7
//      relative), along every axis, so 1e-5 is ~100x that.
// Every test here may keep a light that touches nothing, never the reverse; slack only ever adds
// work. Conventions: view space right-handed, camera looking down -Z, metres. Pure functions;
// thread-safe.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "lighting/culling/LightBounds.h"

namespace lighting {

// Rule 3 of the slack policy: relative to the largest view-space distance of the bound, and an
// absolute floor for bounds at the eye.
inline constexpr float kBoundSlack = 1e-5f;
inline constexpr float kBoundSlackMetres = 1e-6f;

inline float boundSlackMetres(float magnitudeMetres) {
    return kBoundSlack * magnitudeMetres + kBoundSlackMetres;
}

// An axis-aligned view-space box [lo, hi].
struct ViewBox {
    glm::vec3 lo{0.0f};
    glm::vec3 hi{0.0f};
};

// The box grown by rule 3 of the slack policy (magnitude: its largest coordinate magnitude).
inline ViewBox widenedBox(const glm::vec3& lo, const glm::vec3& hi) {
    const glm::vec3 magnitude = glm::max(glm::abs(lo), glm::abs(hi));
    const glm::vec3 slack(boundSlackMetres(std::max({magnitude.x, magnitude.y, magnitude.z})));
    return {lo - slack, hi + slack};
}

// Sphere (centre, radius) vs box: true when the squared distance from the centre to the box
// (0 inside) is at most radius^2. The one sphere/box test of tiles, clusters and objects.
inline bool sphereTouchesBox(const glm::vec3& centre, float radius, const glm::vec3& lo,
                             const glm::vec3& hi) {
    const glm::vec3 d = glm::max(glm::max(lo - centre, centre - hi), glm::vec3(0.0f));
    return glm::dot(d, d) <= radius * radius;
}
// The same for a light's bounding sphere; unbounded lights touch everything.
inline bool sphereTouchesBox(const LightSphere& sphere, const ViewBox& box) {
    return sphere.unbounded || sphereTouchesBox(sphere.centreView, sphere.radius, box.lo, box.hi);
}

// View-frustum culling of light spheres, shared by the tiled stages and the light-volume stages:
// the camera's frustum between its near and far planes (side planes through the image edges),
// every plane moved out by rule 3 of the slack policy. Assumes the symmetric pinhole of
// scenes::Camera (the side planes are x = +-z / clipFromView[0][0], likewise y). In double, so
// the planes themselves add no rounding worth a thought.
class ViewFrustum {
public:
    explicit ViewFrustum(const gbuffer::CameraView& view);

    // May the sphere touch a surface inside the frustum? Unbounded lights always may.
    bool mayTouch(const LightSphere& sphere) const;
    // Ascending indices of the spheres to keep: all of them (cull false), or those mayTouch
    // keeps.
    std::vector<uint32_t> visibleLights(const std::vector<LightSphere>& spheres, bool cull) const;

private:
    double mNearMetres = 0.0, mFarMetres = 0.0;
    // Unit normals (outward) of the side planes in the xz and yz planes: (p, 1) / |(p, 1)|.
    double mProjX = 1.0, mProjY = 1.0, mLengthX = 1.0, mLengthY = 1.0;
};

} // namespace lighting
