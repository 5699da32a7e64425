#include "lighting/shadows/ExactRayCast.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace lighting::shadows {

namespace {

// Triangle t's corners, or nothing when an index is out of range.
std::optional<std::array<glm::dvec3, 3>> corners(const gbuffer::SceneGeometry& geometry, size_t t) {
    std::array<glm::dvec3, 3> corner;
    for (int i = 0; i < 3; ++i) {
        const uint32_t index = geometry.indices[3 * t + i];
        if (index >= geometry.positionWorldExact.size())
            return std::nullopt;
        corner[i] = geometry.positionWorldExact[index];
    }
    return corner;
}

// Distance between segments [p1, q1] and [p2, q2] (Ericson, Real-Time Collision Detection, 5.1.9).
double segmentSegmentDistance(const glm::dvec3& p1, const glm::dvec3& q1, const glm::dvec3& p2,
                              const glm::dvec3& q2) {
    const glm::dvec3 d1 = q1 - p1;
    const glm::dvec3 d2 = q2 - p2;
    const glm::dvec3 r = p1 - p2;
    const double a = glm::dot(d1, d1);
    const double e = glm::dot(d2, d2);
    const double f = glm::dot(d2, r);
    double s = 0.0;
    double t = 0.0;
    if (a == 0.0 && e == 0.0)
        return glm::length(r);
    if (a == 0.0) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = glm::dot(d1, r);
        if (e == 0.0) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = glm::dot(d1, d2);
            const double denominator = a * e - b * b;
            // Parallel (to rounding): any s works; the clamps below find the closest pair.
            s = denominator > 1e-14 * a * e ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0)
                                            : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) {
                t = 0.0;
                s = std::clamp(-c / a, 0.0, 1.0);
            } else if (t > 1.0) {
                t = 1.0;
                s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    return glm::length((p1 + d1 * s) - (p2 + d2 * t));
}

// Distance from p to triangle (a, b, c) (Ericson 5.1.5, by Voronoi regions); non-degenerate
// triangles only.
double pointTriangleDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                             const glm::dvec3& c) {
    const glm::dvec3 ab = b - a;
    const glm::dvec3 ac = c - a;
    const glm::dvec3 ap = p - a;
    const double d1 = glm::dot(ab, ap);
    const double d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return glm::length(ap);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp);
    const double d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3)
        return glm::length(bp);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return glm::length(p - (a + ab * (d1 / (d1 - d3))));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp);
    const double d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6)
        return glm::length(cp);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return glm::length(p - (a + ac * (d2 / (d2 - d6))));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const double denominator = 1.0 / (va + vb + vc);
    return glm::length(p - (a + ab * (vb * denominator) + ac * (vc * denominator)));
}

// A finite stand-in for a directional light's half-line: long enough to leave the bounding box
// of every finite vertex by a metre.
double finiteLength(const gbuffer::SceneGeometry& geometry, const glm::dvec3& origin) {
    glm::dvec3 low(std::numeric_limits<double>::max());
    glm::dvec3 high(std::numeric_limits<double>::lowest());
    for (const glm::dvec3& p : geometry.positionWorldExact) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            continue;
        low = glm::min(low, p);
        high = glm::max(high, p);
    }
    if (low.x > high.x)
        return 1.0;
    return glm::length(origin - (low + high) * 0.5) + glm::length(high - low) * 0.5 + 1.0;
}

} // namespace

std::optional<glm::dvec3> segmentHitWeightsExact(const ShadowSegment& segment, const glm::dvec3& a,
                                                 const glm::dvec3& b, const glm::dvec3& c) {
    if (!(segment.lengthWorld > 0.0))
        return std::nullopt;
    const glm::dvec3 edge1 = b - a;
    const glm::dvec3 edge2 = c - a;
    const glm::dvec3 p = glm::cross(segment.directionWorld, edge2);
    const double determinant = glm::dot(edge1, p);
    if (determinant == 0.0 || !std::isfinite(determinant))
        return std::nullopt; // parallel to the plane (or degenerate): no crossing point
    const double inverse = 1.0 / determinant;
    const glm::dvec3 s = segment.originWorld - a;
    const double u = glm::dot(s, p) * inverse;
    if (!(u >= 0.0 && u <= 1.0))
        return std::nullopt;
    const glm::dvec3 q = glm::cross(s, edge1);
    const double v = glm::dot(segment.directionWorld, q) * inverse;
    if (!(v >= 0.0 && u + v <= 1.0))
        return std::nullopt;
    const double t = glm::dot(edge2, q) * inverse;
    if (!(t > 0.0 && t < segment.lengthWorld))
        return std::nullopt;
    return glm::dvec3(1.0 - u - v, u, v);
}

bool segmentHitsTriangleExact(const ShadowSegment& segment, const glm::dvec3& a,
                              const glm::dvec3& b, const glm::dvec3& c) {
    return segmentHitWeightsExact(segment, a, b, c).has_value();
}

bool segmentBlockedExact(const gbuffer::SceneGeometry& geometry, const ShadowRay& ray,
                         const CasterAlphaTest* alphaTest) {
    const ShadowSegment segment = shadowSegment(ray);
    if (!(segment.lengthWorld > 0.0))
        return false;
    for (size_t t = 0; t < geometry.indices.size() / 3; ++t) {
        const auto corner = corners(geometry, t);
        if (!corner)
            continue;
        const auto weights =
            segmentHitWeightsExact(segment, (*corner)[0], (*corner)[1], (*corner)[2]);
        if (weights && (!alphaTest || alphaTest->casts(uint32_t(t), glm::vec3(*weights))))
            return true;
    }
    return false;
}

bool segmentBlockedExact(const gbuffer::SceneGeometry& geometry, const glm::dvec3& surfaceWorld,
                         const glm::dvec3& normalWorld, const glm::dvec3& lightWorld) {
    return segmentBlockedExact(geometry, ShadowRay::toPoint(surfaceWorld, normalWorld, lightWorld));
}

bool directionBlockedExact(const gbuffer::SceneGeometry& geometry, const glm::dvec3& surfaceWorld,
                           const glm::dvec3& normalWorld, const glm::dvec3& directionWorld) {
    return segmentBlockedExact(geometry,
                               ShadowRay::directional(surfaceWorld, normalWorld, directionWorld));
}

ExactVerdict classifyShadowRayExact(const gbuffer::SceneGeometry& geometry, const ShadowRay& ray,
                                    double toleranceWorld) {
    ShadowSegment segment = shadowSegment(ray);
    if (!(segment.lengthWorld > 0.0))
        return ExactVerdict::Clear; // nothing to block, whatever the rounding
    if (std::isinf(segment.lengthWorld))
        segment.lengthWorld = finiteLength(geometry, segment.originWorld);
    const glm::dvec3 begin = segment.originWorld;
    const glm::dvec3 end = segment.originWorld + segment.directionWorld * segment.lengthWorld;
    bool nearAny = false;
    for (size_t t = 0; t < geometry.indices.size() / 3; ++t) {
        const auto corner = corners(geometry, t);
        if (!corner)
            continue;
        const auto& [a, b, c] = *corner;
        const glm::dvec3 normal = glm::cross(b - a, c - a);
        if (!(glm::dot(normal, normal) > 0.0) || !std::isfinite(glm::dot(normal, normal)))
            continue; // degenerate: blocks nothing, in double or in float
        const double margin = std::min(
            {segmentSegmentDistance(begin, end, a, b), segmentSegmentDistance(begin, end, b, c),
             segmentSegmentDistance(begin, end, c, a), pointTriangleDistance(begin, a, b, c),
             pointTriangleDistance(end, a, b, c)});
        const bool near = !(margin >= toleranceWorld);
        if (segmentHitsTriangleExact(segment, a, b, c) && !near)
            return ExactVerdict::Blocked;
        nearAny = nearAny || near;
    }
    return nearAny ? ExactVerdict::WithinTolerance : ExactVerdict::Clear;
}

} // namespace lighting::shadows
