// ShadowRay: one shadow query (a surface point toward a light) and the rule that turns it into the
// segment both ray casters test, RayVisibility (Embree, float) and the exact oracle
// (ExactRayCast.h, double). Having one rule is what lets the tests hold them equal.
//
// Conventions: world space, metres, any handedness (nothing here depends on it). A triangle
// blocks whichever side the ray comes from (shadows are two-sided); lights are points, never
// geometry.
//
// The origin offset. The ray does not start at the surface point but at
//     origin = surfaceWorld + normalize(normalWorld) * offset(surfaceWorld),
//     offset(p) = kOriginOffsetRelative * max(max(|p.x|, |p.y|, |p.z|), kOriginOffsetFloorWorld),
// and a segment toward a light stops offset(lightWorld) short of the light. Why:
//   - Along the normal, not along the ray: a step along the ray shrinks to nothing at grazing
//     angles (a 1-degree light moves the origin off the plane by sin 1deg of the step), a step
//     along the normal keeps the full distance from the surface's own plane at every angle.
//   - Scaled to the coordinates' magnitude: what the offset must beat is rounding, and rounding
//     is relative. Embree holds vertices and rays in float (24-bit significand: a coordinate of
//     magnitude m moves by up to m 2^-24, a few such errors add up in its intersection test);
//     kOriginOffsetRelative = 2^-14 is 1024 times m 2^-24, so the surface's own triangle, as
//     Embree rounds it, stays behind the origin. The floor (1 m, offset 61 um) covers points
//     near the world origin on triangles whose vertices are far from it: it holds while a
//     triangle's vertices stay within about 100 m of the origin for a point near it (the float
//     error of its plane there is about (vertex magnitude) 2^-21).
//   - The same at the light end: a light on a wall (a lamp fixed to it) is not shadowed by that
//     wall, and a wall just behind the light never blocks it.
// Cost in exactness: a blocker thinner than the offset, or closer than it to the surface (a
// contact shadow within 61 um at 1 m from the origin, 0.6 mm at 10 m), is missed, by both
// casters alike. The offset is the only approximation the oracle shares.
//
// A zero normal (no orientation known) moves the origin the same distance along the ray instead.
// A segment shorter than nothing after both offsets (the light within the offsets of the
// surface) is never blocked.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace lighting::shadows {

// 2^-14: 1024 float half-ulps of the coordinate's magnitude (see above).
inline constexpr double kOriginOffsetRelative = 1.0 / 16384.0;
// Metres: the magnitude below which the offset stops shrinking (see above).
inline constexpr double kOriginOffsetFloorWorld = 1.0;

enum class ShadowRayKind : uint8_t {
    ToPoint,     // point and spot lights: the segment to lightWorld
    Directional, // the half-line toward -directionWorld, unbounded
};

struct ShadowRay {
    glm::dvec3 surfaceWorld{0.0};
    // The side being lit: the geometric or shading normal, facing the viewer for two-sided
    // surfaces. Need not be unit. A light behind it is blocked by the surface itself (when the
    // surface is a triangle of the scene).
    glm::dvec3 normalWorld{0.0};
    glm::dvec3 lightWorld{0.0}; // ToPoint: the light's position
    glm::dvec3 directionWorld{
        0.0}; // Directional: the direction the light travels (need not be unit)
    ShadowRayKind kind = ShadowRayKind::ToPoint;

    static ShadowRay toPoint(const glm::dvec3& surface, const glm::dvec3& normal,
                             const glm::dvec3& light) {
        return {surface, normal, light, glm::dvec3(0.0), ShadowRayKind::ToPoint};
    }
    static ShadowRay directional(const glm::dvec3& surface, const glm::dvec3& normal,
                                 const glm::dvec3& direction) {
        return {surface, normal, glm::dvec3(0.0), direction, ShadowRayKind::Directional};
    }
};

// The segment a ShadowRay tests: points originWorld + t directionWorld for 0 < t < lengthWorld
// (open at both ends); lengthWorld is +infinity for a directional light and <= 0 when nothing
// can block (then directionWorld may be anything).
struct ShadowSegment {
    glm::dvec3 originWorld{0.0};
    glm::dvec3 directionWorld{0.0}; // unit
    double lengthWorld = 0.0;
};

// The offset of the rule above at p, in metres.
inline double originOffset(const glm::dvec3& p) {
    const double magnitude = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    return kOriginOffsetRelative * std::max(magnitude, kOriginOffsetFloorWorld);
}

// The rule above. Pure and cheap (two square roots); both casters call it.
inline ShadowSegment shadowSegment(const ShadowRay& ray) {
    ShadowSegment segment;
    const double offset = originOffset(ray.surfaceWorld);
    const double normalLength = glm::length(ray.normalWorld);
    if (ray.kind == ShadowRayKind::Directional) {
        const double directionLength = glm::length(ray.directionWorld);
        if (!(directionLength > 0.0))
            return segment; // no direction: nothing to test
        segment.directionWorld = -ray.directionWorld / directionLength;
        segment.originWorld = normalLength > 0.0
                                  ? ray.surfaceWorld + ray.normalWorld * (offset / normalLength)
                                  : ray.surfaceWorld + segment.directionWorld * offset;
        segment.lengthWorld = std::numeric_limits<double>::infinity();
        return segment;
    }
    if (normalLength > 0.0) {
        segment.originWorld = ray.surfaceWorld + ray.normalWorld * (offset / normalLength);
    } else {
        const glm::dvec3 toLight = ray.lightWorld - ray.surfaceWorld;
        const double toLightLength = glm::length(toLight);
        if (!(toLightLength > offset))
            return segment;
        segment.originWorld = ray.surfaceWorld + toLight * (offset / toLightLength);
    }
    const glm::dvec3 toLight = ray.lightWorld - segment.originWorld;
    const double distance = glm::length(toLight);
    const double length = distance - originOffset(ray.lightWorld);
    if (!(length > 0.0))
        return segment;
    segment.directionWorld = toLight / distance;
    segment.lengthWorld = length;
    return segment;
}

} // namespace lighting::shadows
