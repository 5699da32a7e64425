// ShadowCasterSets: per shadow-casting light, the scene objects (instances) that can cast a
// shadow onto something the camera sees: the shadow-casting sets of the forward-vs-deferred
// dissertation (section 4.4.5), after O'Rorke ("Managing Visibility for Per-Pixel Lighting", GPU
// Gems 2004). Only these objects are drawn into the light's shadow map (ShadowMaps.h).
//
// The volume. A visible receiver lies in the view frustum, clipped in depth to the scene's
// bounds ([receiverNear, receiverFar]); a point shadows it only if it lies on the segment from the
// receiver to the light. Those segments fill the convex hull of the frustum and the light
// (directional: the frustum swept towards the light by the scene's diagonal, beyond which nothing
// of the scene can be). O'Rorke's two cases are the two shapes that hull takes:
//   light inside the frustum   the hull is the frustum itself: casters must be in view;
//   light outside the frustum  the frustum grows towards the light (the dissertation left this
//                              case unfinished: "the convex hull of the frustum and the light").
// The hull is built as the planes through three of its points that have every point on one side
// (at most 16 points: 560 triples), which needs no case analysis and is exact for both cases.
//
// Conservative for filtered lookups. A shadow-map lookup reads texels around the receiver's
// projection (PCF taps up to 2.5 texels away, a receiver moved by the normal offset), whose rays
// pass up to `marginMetres` beside the receiver; the segments to those points stay within that
// distance of the hull (they share the light's end), so an object is kept when its bounding box
// comes within marginMetres of the hull. An excluded object can then change no texel a visible
// receiver reads: the image is the same with and without the sets (tested against brute force,
// tests/lighting/shadows/shadow_caster_sets_test.cpp).
//
// Within the light's range. A point or spot light's maps draw only the triangles whose box touches
// its range sphere (ShadowMaps.cpp's range cull, with or without the sets), so an object whose
// box misses the sphere has no triangle in any of its maps: leaving it out of the set changes
// nothing drawn, exactly. Both tests are the one function boxTouchesSphere, and it is monotone
// in the box (the distance from the centre to a box never grows as the box grows, in floating
// point too: every step, the differences, the max with 0, the squares and their sum, rounds
// monotonically), and a triangle's box lies inside its object's box (both are min/max of the
// same float positions), so a triangle the cull draws is never in a dropped object. Without
// this, every light's set holds every object of the hull however far from the light: on the
// wall scene, whose lights are all in view, every object in view (57% of the objects with
// clutter=200; 1-2% with the range test: lighting/shadows/README.md).
//
// Pure functions of their inputs; no state.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "scenes/Scene.h"

namespace lighting {

// A convex volume as planes n.x + d <= 0 (inside), world space, n unit.
struct CasterVolume {
    std::vector<glm::dvec4> planes; // (n, d)
    bool lightInFrustum = false;    // O'Rorke's case (the hull is then the frustum)
    bool unbounded = false;         // degenerate frustum: every object is kept
    // Point and spot lights: the range sphere (file comment, "Within the light's range").
    bool rangeBounded = false;
    glm::dvec3 rangeCentre{0.0};
    double rangeMetres = 0.0;

    // Whether `box` comes within `margin` metres of the volume (conservative: a box near a corner
    // of the volume but outside it may be kept; none inside is dropped).
    bool mayContain(const scenes::Aabb& box, double margin) const;
    // Whether the light's maps may draw part of `box`: mayContain, and for point and spot lights
    // the box touches the range sphere (no margin: the range cull that draws has none). The
    // shadow-casting set is the objects for which this holds.
    bool mayCast(const scenes::Aabb& box, double margin) const;
};

// Whether `box` comes within `radius` of `centre` (the maps' range cull and the sets' range test;
// see the file comment for why they must be this one function).
bool boxTouchesSphere(const glm::dvec3& centre, double radius, const scenes::Aabb& box);

// The view frustum of `view` between view depths receiverNear and receiverFar, in world space
// (8 corners: near then far, each (-x,-y), (+x,-y), (-x,+y), (+x,+y)).
std::vector<glm::dvec3> frustumCornersWorld(const gbuffer::CameraView& view, double receiverNear,
                                            double receiverFar);

// The hull of `frustumCorners` and `light` (see the file comment); `sweepMetres` is how far a
// directional light's frustum is swept towards the light (the scene's diagonal).
CasterVolume casterVolume(const std::vector<glm::dvec3>& frustumCorners, const scenes::Light& light,
                          double sweepMetres);

// World-space bounds of every scene instance's triangles (empty boxes for instances without any).
std::vector<scenes::Aabb> instanceBounds(const gbuffer::SceneGeometry& geometry,
                                         size_t instanceCount);
// The same boxes, bitwise for finite positions (min and max are exact), from the bounds of
// consecutive chunks of `trianglesPerChunk` triangles (chunkBounds[c] bounds triangles [c *
// trianglesPerChunk, (c + 1) * trianglesPerChunk)), which the shadow maps compute anyway: a chunk
// within one instance extends its instance's box once, a chunk that straddles instances triangle by
// triangle. Reads the instance id of every triangle but the positions of straddling chunks
// only; serial. Throws std::invalid_argument when chunkBounds does not cover the triangles.
std::vector<scenes::Aabb> instanceBoundsFromChunks(const gbuffer::SceneGeometry& geometry,
                                                   size_t instanceCount,
                                                   std::span<const scenes::Aabb> chunkBounds,
                                                   uint32_t trianglesPerChunk);

} // namespace lighting
