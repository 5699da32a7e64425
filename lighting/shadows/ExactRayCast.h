// ExactRayCast: the scalar double-precision oracle of RayVisibility. Brute force over every
// triangle of gbuffer::SceneGeometry::positionWorldExact, Moeller-Trumbore in double, on the same
// segment (ShadowRay.h: the same origin offset, the same stop short of the light). No BVH, no
// float, no SIMD: slow (every triangle for every ray, about 10 ns each) and plain enough to check
// by reading. The tests hold RayVisibility to it.
//
// Conventions: as ShadowRay.h. Triangles are two-sided; a hit on an edge or a vertex counts
// (barycentrics >= 0, inclusive, as Embree's watertight test), the segment is open at both ends
// (0 < t < length). With a CasterAlphaTest, a hit on an alpha-tested triangle blocks only where
// its alpha passes at the hit's barycentrics (CasterMaterials.h). Degenerate triangles (zero area
// in double, non-finite vertices, indices out of range) never block. All functions are pure and
// thread-safe.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/CasterMaterials.h"
#include "lighting/shadows/ShadowRay.h"

namespace lighting::shadows {

// Where triangle (a, b, c) meets the open segment (Moeller-Trumbore in double): the weights of
// a, b, c at the crossing point, or nothing when they do not meet.
std::optional<glm::dvec3> segmentHitWeightsExact(const ShadowSegment& segment, const glm::dvec3& a,
                                                 const glm::dvec3& b, const glm::dvec3& c);
// True when triangle (a, b, c) meets the open segment.
bool segmentHitsTriangleExact(const ShadowSegment& segment, const glm::dvec3& a,
                              const glm::dvec3& b, const glm::dvec3& c);

// True when any triangle of `geometry` blocks `ray`'s segment: the oracle of
// RayVisibility::occluded. With `alphaTest`, alpha-tested triangles block only where they cast.
bool segmentBlockedExact(const gbuffer::SceneGeometry& geometry, const ShadowRay& ray,
                         const CasterAlphaTest* alphaTest = nullptr);
bool segmentBlockedExact(const gbuffer::SceneGeometry& geometry, const glm::dvec3& surfaceWorld,
                         const glm::dvec3& normalWorld, const glm::dvec3& lightWorld);
bool directionBlockedExact(const gbuffer::SceneGeometry& geometry, const glm::dvec3& surfaceWorld,
                           const glm::dvec3& normalWorld, const glm::dvec3& directionWorld);

// The answer, and whether it is robust to moving the geometry by up to `toleranceWorld` metres.
enum class ExactVerdict : uint8_t {
    Clear,           // no triangle comes within the tolerance of blocking
    Blocked,         // some triangle blocks with a margin of at least the tolerance
    WithinTolerance, // neither: a float caster may answer either way
};

// The verdict on `ray`'s segment S. A triangle T blocks robustly when S meets T and S stays
// `toleranceWorld` away from T's three edges and T stays as far from S's two endpoints; it is
// robustly clear of S when S misses T by the same margins. Those are the only ways a segment and
// a triangle can start or stop meeting when either moves continuously, so a robust answer cannot
// be changed by rounding smaller than the tolerance. A directional light's half-line is cut where
// it has left the scene's bounding box. Cost: five distance computations per triangle.
ExactVerdict classifyShadowRayExact(const gbuffer::SceneGeometry& geometry, const ShadowRay& ray,
                                    double toleranceWorld);

} // namespace lighting::shadows
