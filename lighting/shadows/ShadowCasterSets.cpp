#include "lighting/shadows/ShadowCasterSets.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lighting {

bool CasterVolume::mayContain(const scenes::Aabb& box, double margin) const {
    if (box.empty())
        return false;
    if (unbounded)
        return true;
    const glm::dvec3 centre = 0.5 * (glm::dvec3(box.min) + glm::dvec3(box.max));
    const glm::dvec3 half = 0.5 * (glm::dvec3(box.max) - glm::dvec3(box.min));
    for (const glm::dvec4& plane : planes) {
        const glm::dvec3 n(plane);
        // The box's nearest point to the inside: outside by more than the margin = excluded.
        const double nearest = glm::dot(n, centre) + plane.w - glm::dot(glm::abs(n), half);
        if (nearest > margin)
            return false;
    }
    return true;
}

bool CasterVolume::mayCast(const scenes::Aabb& box, double margin) const {
    if (!mayContain(box, margin))
        return false;
    return !rangeBounded || boxTouchesSphere(rangeCentre, rangeMetres, box);
}

bool boxTouchesSphere(const glm::dvec3& centre, double radius, const scenes::Aabb& box) {
    const glm::dvec3 d = glm::max(
        glm::max(glm::dvec3(box.min) - centre, centre - glm::dvec3(box.max)), glm::dvec3(0.0));
    return glm::dot(d, d) <= radius * radius;
}

std::vector<glm::dvec3> frustumCornersWorld(const gbuffer::CameraView& view, double receiverNear,
                                            double receiverFar) {
    const glm::dmat4 worldFromView = glm::inverse(view.viewFromWorldExact);
    // Symmetric pinhole (CameraView.h): the side slopes from the projection's diagonal.
    const double tanHalfX = 1.0 / double(view.clipFromView[0][0]);
    const double tanHalfY = 1.0 / double(view.clipFromView[1][1]);
    std::vector<glm::dvec3> corners;
    for (double depth : {receiverNear, receiverFar})
        for (int k = 0; k < 4; ++k) {
            const glm::dvec4 viewPoint((k & 1 ? 1.0 : -1.0) * tanHalfX * depth,
                                       (k & 2 ? 1.0 : -1.0) * tanHalfY * depth, -depth, 1.0);
            corners.push_back(glm::dvec3(worldFromView * viewPoint));
        }
    return corners;
}

namespace {

// The convex hull of `points` as its supporting planes: every plane through three of the points
// with all points on its inner side (within a tolerance relative to the points' extent).
// Duplicate planes are harmless. An empty result means the points are (nearly) coplanar.
std::vector<glm::dvec4> hullPlanes(const std::vector<glm::dvec3>& points) {
    double extent = 0.0;
    for (const glm::dvec3& p : points)
        extent = std::max(extent, glm::length(p - points.front()));
    const double tolerance = 1e-9 * std::max(extent, 1.0);
    std::vector<glm::dvec4> planes;
    const size_t n = points.size();
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j)
            for (size_t k = j + 1; k < n; ++k) {
                glm::dvec3 normal = glm::cross(points[j] - points[i], points[k] - points[i]);
                const double length = glm::length(normal);
                if (!(length > 1e-12 * std::max(extent * extent, 1.0)))
                    continue; // collinear
                normal /= length;
                double d = -glm::dot(normal, points[i]);
                bool anyAbove = false, anyBelow = false;
                for (const glm::dvec3& p : points) {
                    const double s = glm::dot(normal, p) + d;
                    anyAbove |= s > tolerance;
                    anyBelow |= s < -tolerance;
                }
                if (anyAbove && anyBelow)
                    continue; // cuts through the points: not a face
                if (anyAbove) {
                    normal = -normal;
                    d = -d;
                }
                planes.emplace_back(normal, d);
            }
    return planes;
}

bool insideAll(const std::vector<glm::dvec4>& planes, const glm::dvec3& p) {
    return std::all_of(planes.begin(), planes.end(), [&](const glm::dvec4& plane) {
        return glm::dot(glm::dvec3(plane), p) + plane.w <= 0.0;
    });
}

} // namespace

CasterVolume casterVolume(const std::vector<glm::dvec3>& frustumCorners, const scenes::Light& light,
                          double sweepMetres) {
    CasterVolume volume;
    if (light.type == scenes::LightType::Point || light.type == scenes::LightType::Spot) {
        volume.rangeBounded = true;
        volume.rangeCentre = glm::dvec3(light.positionWorld);
        volume.rangeMetres = light.rangeMetres;
    }
    const std::vector<glm::dvec4> frustum = hullPlanes(frustumCorners);
    if (frustum.empty()) {
        volume.unbounded = true;
        return volume;
    }
    std::vector<glm::dvec3> points = frustumCorners;
    if (light.type == scenes::LightType::Directional) {
        // The light is at infinity: sweep the frustum towards it (against the direction the light
        // travels) by the scene's diagonal, beyond which no part of the scene can cast.
        const glm::dvec3 towardsLight = -glm::normalize(glm::dvec3(light.directionWorld));
        for (const glm::dvec3& corner : frustumCorners)
            points.push_back(corner + sweepMetres * towardsLight);
    } else {
        const glm::dvec3 position(light.positionWorld);
        volume.lightInFrustum = insideAll(frustum, position);
        points.push_back(position);
    }
    volume.planes = volume.lightInFrustum ? frustum : hullPlanes(points);
    if (volume.planes.empty())
        volume.unbounded = true;
    return volume;
}

std::vector<scenes::Aabb> instanceBounds(const gbuffer::SceneGeometry& geometry,
                                         size_t instanceCount) {
    std::vector<scenes::Aabb> bounds(instanceCount);
    const uint32_t triangles = geometry.triangleCount();
    for (uint32_t t = 0; t < triangles; ++t) {
        scenes::Aabb& box = bounds[geometry.triangleInstance[t]];
        for (int k = 0; k < 3; ++k)
            box.extend(geometry.positionWorld[geometry.indices[3 * t + k]]);
    }
    return bounds;
}

std::vector<scenes::Aabb> instanceBoundsFromChunks(const gbuffer::SceneGeometry& geometry,
                                                   size_t instanceCount,
                                                   std::span<const scenes::Aabb> chunkBounds,
                                                   uint32_t trianglesPerChunk) {
    const uint32_t triangles = geometry.triangleCount();
    if (trianglesPerChunk == 0 ||
        chunkBounds.size() != (size_t(triangles) + trianglesPerChunk - 1) / trianglesPerChunk)
        throw std::invalid_argument(
            "instanceBoundsFromChunks: " + std::to_string(chunkBounds.size()) + " chunks of " +
            std::to_string(trianglesPerChunk) + " for " + std::to_string(triangles) + " triangles");
    std::vector<scenes::Aabb> bounds(instanceCount);
    for (size_t c = 0; c < chunkBounds.size(); ++c) {
        const uint32_t begin = uint32_t(c) * trianglesPerChunk;
        const uint32_t end = std::min(triangles, begin + trianglesPerChunk);
        const uint32_t instance = geometry.triangleInstance[begin];
        bool oneInstance = true;
        for (uint32_t t = begin + 1; t < end && oneInstance; ++t)
            oneInstance = geometry.triangleInstance[t] == instance;
        if (oneInstance) {
            bounds[instance].extend(chunkBounds[c]);
            continue;
        }
        for (uint32_t t = begin; t < end; ++t) {
            scenes::Aabb& box = bounds[geometry.triangleInstance[t]];
            for (int k = 0; k < 3; ++k)
                box.extend(geometry.positionWorld[geometry.indices[3 * t + k]]);
        }
    }
    return bounds;
}

} // namespace lighting
