// LightVolumes: proxy mesh construction, frustum and screen-rectangle bounds (see the header).
#include "lighting/culling/LightVolumes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace lighting {

namespace {

ProxyMesh buildUnitProxySphere() {
    // Icosahedron: the cyclic permutations of (0, +-1, +-phi).
    const float phi = (1.0f + std::sqrt(5.0f)) * 0.5f;
    std::vector<glm::vec3> positions = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                                        {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                                        {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
    for (glm::vec3& p : positions)
        p = glm::normalize(p);
    const std::vector<uint32_t> faces = {0, 11, 5, 0, 5,  1,  0,  1,  7,  0,  7, 10, 0, 10, 11,
                                         1, 5,  9, 5, 11, 4,  11, 10, 2,  10, 7, 6,  7, 1,  8,
                                         3, 9,  4, 3, 4,  2,  3,  2,  6,  3,  6, 8,  3, 8,  9,
                                         4, 9,  5, 2, 4,  11, 6,  2,  10, 8,  6, 7,  9, 8,  1};
    // One subdivision: each edge's midpoint, pushed to the unit sphere, shared between faces.
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto midpoint = [&](uint32_t a, uint32_t b) {
        const auto key = std::minmax(a, b);
        const auto found = midpoints.find(key);
        if (found != midpoints.end())
            return found->second;
        positions.push_back(glm::normalize(positions[a] + positions[b]));
        const uint32_t index = uint32_t(positions.size() - 1);
        midpoints.emplace(key, index);
        return index;
    };
    ProxyMesh mesh;
    for (size_t f = 0; f < faces.size(); f += 3) {
        const uint32_t a = faces[f], b = faces[f + 1], c = faces[f + 2];
        const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
        for (uint32_t t : {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca})
            mesh.indices.push_back(t);
    }
    // Counter-clockwise seen from outside (the outward normal by the right-hand rule).
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
        const glm::vec3 &a = positions[mesh.indices[t]], &b = positions[mesh.indices[t + 1]],
                        &c = positions[mesh.indices[t + 2]];
        if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0.0f)
            std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
    }
    // Scale so the smallest face-plane distance (the inradius) is 1, computed in double and
    // rounded up by a relative 1e-6 so float rounding cannot leave it just below 1.
    double inradius = 1.0;
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
        const glm::dvec3 a(positions[mesh.indices[t]]), b(positions[mesh.indices[t + 1]]),
            c(positions[mesh.indices[t + 2]]);
        inradius = std::min(inradius, glm::dot(glm::normalize(glm::cross(b - a, c - a)), a));
    }
    const float scale = float(1.0 / inradius * (1.0 + 1e-6));
    mesh.circumradius = 0.0f;
    for (glm::vec3& p : positions) {
        p *= scale;
        mesh.circumradius = std::max(mesh.circumradius, glm::length(p));
    }
    mesh.circumradius *= 1.0f + 1e-6f;
    mesh.positions = std::move(positions);
    // Sum of the tetrahedra from the origin to each face.
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
        const glm::dvec3 a(mesh.positions[mesh.indices[t]]), b(mesh.positions[mesh.indices[t + 1]]),
            c(mesh.positions[mesh.indices[t + 2]]);
        mesh.volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    return mesh;
}

std::vector<uint32_t> buildConeProxyIndices() {
    // Vertex 0 the apex, 1..n the base polygon counter-clockwise seen from the base's side.
    const uint32_t n = kConeProxySides;
    std::vector<uint32_t> indices;
    for (uint32_t k = 0; k < n; ++k) {
        const uint32_t b = 1 + k, next = 1 + (k + 1) % n;
        for (uint32_t i : {0u, next, b})
            indices.push_back(i); // side
    }
    for (uint32_t k = 1; k + 1 < n; ++k)
        for (uint32_t i : {1u, 1 + k, 2 + k})
            indices.push_back(i); // base fan
    return indices;
}

} // namespace

const ProxyMesh& unitProxySphere() {
    static const ProxyMesh mesh = buildUnitProxySphere();
    return mesh;
}

const std::vector<uint32_t>& coneProxyIndices() {
    static const std::vector<uint32_t> indices = buildConeProxyIndices();
    return indices;
}

std::optional<ConeProxy> coneProxy(const LightSphere& light, float marginMetres) {
    if (!light.spot || light.unbounded)
        return std::nullopt;
    // The half-angle t, widened for the float cosine test and then by the relative slack.
    const double cosT = std::min(double(light.spotOuterCos), 1.0) - kConeCosSlack;
    if (!(cosT > std::cos(glm::radians(kConeMaxHalfAngleDegrees))))
        return std::nullopt;
    const double tanT = std::sqrt(1.0 - cosT * cosT) / cosT * (1.0 + kCullingSlack);
    const double sinT = tanT / std::sqrt(1.0 + tanT * tanT);
    const double range = light.rangeMetres;
    const glm::dvec3 apex(light.positionView);
    // Dilate the truncated cone by s: LightBounds' slack (relative, absolute, and the float
    // rounding it allows for positions), plus the caller's margin. Moving the apex back along the
    // axis by s / sin t moves every side line out by s (the cone around the old apex's s-ball);
    // the base moves out by s.
    const double dilation = range * kCullingSlack + kCullingSlackMetres +
                            4e-7 * (glm::length(apex) + range) + double(marginMetres);
    const double back = dilation / sinT;
    const double height = back + range + dilation;
    // The base polygon circumscribes the circle of radius height * tan t.
    const double pi = 3.14159265358979323846;
    const double inradius = height * tanT;
    const double circumradius = inradius / std::cos(pi / kConeProxySides) * (1.0 + 1e-6);
    const glm::dvec3 axis = glm::normalize(glm::dvec3(light.axisView));
    // A right-handed frame (u, v, axis): angles increase counter-clockwise seen from +axis.
    const glm::dvec3 helper = std::abs(axis.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, axis));
    const glm::dvec3 v = glm::cross(axis, u);
    const glm::dvec3 apexProxy = apex - back * axis;
    const glm::dvec3 baseCentre = apex + (range + dilation) * axis;
    ConeProxy proxy;
    proxy.positionsView[0] = glm::vec3(apexProxy);
    for (int k = 0; k < kConeProxySides; ++k) {
        const double angle = 2.0 * pi * k / kConeProxySides;
        proxy.positionsView[size_t(k) + 1] =
            glm::vec3(baseCentre + circumradius * (std::cos(angle) * u + std::sin(angle) * v));
    }
    // The base polygon's area is n r^2 tan(pi / n) for inradius r.
    proxy.volume =
        height * kConeProxySides * inradius * inradius * std::tan(pi / kConeProxySides) / 3.0;
    return proxy;
}

LightVolumeRasterizer::LightVolumeRasterizer(const gbuffer::GBuffer& gbuffer, VolumeShape shape,
                                             bool stencil, SpotProxy spotProxy)
    : mGBuffer(gbuffer), mDepth(gbuffer.depth().data()), mShape(shape), mStencil(stencil),
      mSpotProxy(spotProxy), mRasterizer(gbuffer.width(), gbuffer.height()) {
    const gbuffer::CameraView& view = gbuffer.view();
    mReversedZ = view.reversedZ();
    mClearDepth = view.clearDepth();
    mNearMetres = view.nearMetres;
    mFarMetres = view.farMetres;
    mClipFromView = view.clipFromView;
    mProjX = view.clipFromView[0][0];
    mProjY = view.clipFromView[1][1];
    mPixelsPerTanX = mProjX * 0.5f * float(view.width);
    mPixelsPerTanY = mProjY * 0.5f * float(view.height);
    mClipFromViewExact = glm::inverse(view.viewFromClipExact);
}

std::vector<uint32_t> LightVolumeRasterizer::lightsToDraw(const std::vector<LightSphere>& spheres,
                                                          bool frustumCull) const {
    return ViewFrustum(mGBuffer.view()).visibleLights(spheres, frustumCull);
}

LightVolumeRasterizer::PixelRect
LightVolumeRasterizer::screenRect(const LightSphere& sphere) const {
    const int width = mGBuffer.width(), height = mGBuffer.height();
    const PixelRect full{0, 0, width - 1, height - 1};
    const glm::dvec3 c(sphere.centreView);
    const double r = double(sphere.radius) * (1.0 + 1e-6);
    if (c.z + r >= -double(mNearMetres))
        return full; // crosses the near plane (or behind)
    // The sphere is wholly in front of the eye: in the xz (yz) plane its shadow is a disc of
    // radius r, whose tangents from the eye bound x / -z (y / -z).
    auto tangentRange = [&](double lateral, double& tanMin, double& tanMax) {
        const double centreAngle = std::atan2(lateral, -c.z);
        const double halfAngle =
            std::asin(std::min(1.0, r / std::sqrt(lateral * lateral + c.z * c.z)));
        tanMin = std::tan(centreAngle - halfAngle);
        tanMax = std::tan(centreAngle + halfAngle);
    };
    double tanMinX, tanMaxX, tanMinY, tanMaxY;
    tangentRange(c.x, tanMinX, tanMaxX);
    tangentRange(c.y, tanMinY, tanMaxY);
    // Screen x = (ndc + 1) w / 2, y = (1 - ndc) h / 2; pixel p is sampled at p + 0.5. One extra
    // pixel each side absorbs every rounding of the above.
    const double xMin = (mProjX * tanMinX + 1.0) * 0.5 * width,
                 xMax = (mProjX * tanMaxX + 1.0) * 0.5 * width;
    const double yMin = (1.0 - mProjY * tanMaxY) * 0.5 * height,
                 yMax = (1.0 - mProjY * tanMinY) * 0.5 * height;
    auto clampTo = [](double v, int hi) { return int(std::clamp(v, -1.0, double(hi))); };
    PixelRect rect;
    rect.minX = std::max(0, clampTo(std::ceil(xMin - 0.5) - 1.0, width));
    rect.maxX = std::min(width - 1, clampTo(std::floor(xMax - 0.5) + 1.0, width));
    rect.minY = std::max(0, clampTo(std::ceil(yMin - 0.5) - 1.0, height));
    rect.maxY = std::min(height - 1, clampTo(std::floor(yMax - 0.5) + 1.0, height));
    return rect;
}

LightVolumeRasterizer::DepthRange
LightVolumeRasterizer::depthBounds(const LightSphere& sphere) const {
    return depthBoundsOfViewZ(double(sphere.centreView.z) + sphere.radius,
                              double(sphere.centreView.z) - sphere.radius);
}

LightVolumeRasterizer::DepthRange
LightVolumeRasterizer::depthBoundsOfViewZ(double zNearest, double zFarthest) const {
    // Surfaces lie between the near and far planes; clamp so the mapping stays finite.
    const double nearZ = -double(mNearMetres), farZ = -double(mFarMetres);
    zNearest = std::clamp(zNearest, farZ, nearZ);
    zFarthest = std::clamp(zFarthest, farZ, nearZ);
    // For a perspective projection clip z and w depend on view z only.
    const glm::dmat4& m = mClipFromViewExact;
    auto depthOf = [&](double z) { return (m[2][2] * z + m[3][2]) / (m[2][3] * z + m[3][3]); };
    double a = depthOf(zNearest), b = depthOf(zFarthest);
    if (a > b)
        std::swap(a, b);
    const double toleranceLo = kDepthTolerance * (mReversedZ ? a : 1.0);
    const double toleranceHi = kDepthTolerance * (mReversedZ ? b : 1.0);
    return {float(a - toleranceLo), float(b + toleranceHi)};
}

void LightVolumeRasterizer::buildGeometry(const std::vector<LightSphere>& spheres,
                                          const std::vector<uint32_t>& lightIndices) {
    mStats = {};
    mVisitedStamp.assign(mGBuffer.pixelCount(), 0u);
    if (mStencil)
        mFrontStamp.assign(mGBuffer.pixelCount(), 0u);
    mClip.clear();
    mIndices.clear();
    mTriangleSlot.clear();
    mSlots.clear();
    const PixelRect fullScreen{0, 0, mGBuffer.width() - 1, mGBuffer.height() - 1};
    const float infinity = std::numeric_limits<float>::infinity();
    for (uint32_t light : lightIndices) {
        const LightSphere& sphere = spheres[light];
        const uint32_t slot = uint32_t(mSlots.size());
        if (sphere.unbounded) {
            mSlots.push_back({light, {-infinity, infinity}, false, false});
            addQuad(fullScreen, slot);
            continue;
        }
        ++mStats.lightsDrawn;
        mSlots.push_back({light, depthBounds(sphere), false, false});
        if (mShape == VolumeShape::Sphere) {
            if (mSpotProxy == SpotProxy::Cone && sphere.spot && tryConeProxy(sphere, slot)) {
                ++mStats.coneProxies;
                continue;
            }
            // The proxy's extent: the grown radius times the proxy's circumradius.
            const float margin = marginMetres(glm::length(sphere.centreView) + sphere.radius);
            const float extent =
                (sphere.radius + margin) * unitProxySphere().circumradius * (1.0f + 1e-5f);
            // Back faces beyond the far plane would be clipped away: use the rectangle instead.
            if (sphere.centreView.z - extent > -mFarMetres) {
                mSlots[slot].backFaceTest = true;
                // Front faces are complete only when the proxy is wholly beyond the near plane.
                mSlots[slot].frontFaceTest =
                    mStencil && sphere.centreView.z + extent < -mNearMetres;
                addProxy(sphere, slot);
                continue;
            }
            ++mStats.rectFallbacks;
        }
        const PixelRect rect = screenRect(sphere);
        if (rect.minX <= rect.maxX && rect.minY <= rect.maxY)
            addQuad(rect, slot);
    }
}

float LightVolumeRasterizer::marginMetres(float farthestMetres) const {
    // A metric margin m at distance d projects to at least m / d * focal pixels.
    return farthestMetres * kProxyMarginPixels / std::min(mPixelsPerTanX, mPixelsPerTanY);
}

bool LightVolumeRasterizer::tryConeProxy(const LightSphere& sphere, uint32_t slot) {
    // Lit points are at most range (plus slack) from the apex: grow by kProxyMarginPixels there.
    const float farthest =
        glm::length(sphere.positionView) + sphere.rangeMetres * (1.0f + kCullingSlack);
    const std::optional<ConeProxy> cone = coneProxy(sphere, marginMetres(farthest));
    if (!cone)
        return false;
    // The smaller proxy wins (file comment); the sphere proxy grown as in addProxy.
    const double sphereRadius =
        double(sphere.radius) + marginMetres(glm::length(sphere.centreView) + sphere.radius);
    if (!(cone->volume < unitProxySphere().volume * sphereRadius * sphereRadius * sphereRadius))
        return false;
    double zMin = cone->positionsView[0].z, zMax = zMin;
    for (const glm::vec3& p : cone->positionsView) {
        zMin = std::min(zMin, double(p.z));
        zMax = std::max(zMax, double(p.z));
    }
    // Back faces beyond the far plane would be clipped away: leave it to the sphere's checks.
    if (!(zMin - 1e-5 * std::abs(zMin) > -double(mFarMetres)))
        return false;
    Slot& s = mSlots[slot];
    s.backFaceTest = true;
    // Front faces are complete only when the proxy is wholly beyond the near plane.
    s.frontFaceTest = mStencil && zMax + 1e-5 * std::abs(zMax) < -double(mNearMetres);
    // Both depth ranges hold every lit surface: keep their intersection.
    const DepthRange coneDepth = depthBoundsOfViewZ(zMax, zMin);
    s.depth = {std::max(s.depth.lo, coneDepth.lo), std::min(s.depth.hi, coneDepth.hi)};
    addMesh(cone->positionsView.data(), cone->positionsView.size(), coneProxyIndices(), slot);
    return true;
}

void LightVolumeRasterizer::addProxy(const LightSphere& sphere, uint32_t slot) {
    // Grow the sphere by kProxyMarginPixels at its farthest distance from the eye.
    const float radius =
        sphere.radius + marginMetres(glm::length(sphere.centreView) + sphere.radius);
    const ProxyMesh& proxy = unitProxySphere();
    std::vector<glm::vec3> positionsView;
    positionsView.reserve(proxy.positions.size());
    for (const glm::vec3& p : proxy.positions)
        positionsView.push_back(sphere.centreView + radius * p);
    addMesh(positionsView.data(), positionsView.size(), proxy.indices, slot);
}

void LightVolumeRasterizer::addMesh(const glm::vec3* positionsView, size_t positionCount,
                                    const std::vector<uint32_t>& indices, uint32_t slot) {
    const uint32_t base = uint32_t(mClip.size());
    for (size_t i = 0; i < positionCount; ++i)
        mClip.push_back(mClipFromView * glm::vec4(positionsView[i], 1.0f));
    // Stencil: a front-marking copy first, then the testing copy (see the header).
    const bool frontCopy = mSlots[slot].frontFaceTest;
    for (int copy = frontCopy ? 0 : 1; copy < 2; ++copy)
        for (size_t t = 0; t < indices.size(); t += 3) {
            for (int k = 0; k < 3; ++k)
                mIndices.push_back(base + indices[t + k]);
            mTriangleSlot.push_back(copy == 0 ? (slot | kFrontCopy) : slot);
        }
}

void LightVolumeRasterizer::addQuad(const PixelRect& rect, uint32_t slot) {
    // Edges on pixel boundaries, so exactly the rectangle's pixel centres are inside; z = w / 2
    // is inside the clip volume. Clockwise in NDC: back-facing, like the proxies' drawn faces.
    const float x0 = float(rect.minX) / float(mGBuffer.width()) * 2.0f - 1.0f;
    const float x1 = float(rect.maxX + 1) / float(mGBuffer.width()) * 2.0f - 1.0f;
    const float y0 = 1.0f - float(rect.maxY + 1) / float(mGBuffer.height()) * 2.0f; // bottom
    const float y1 = 1.0f - float(rect.minY) / float(mGBuffer.height()) * 2.0f;     // top
    const uint32_t base = uint32_t(mClip.size());
    mClip.push_back({x0, y0, 0.5f, 1.0f});
    mClip.push_back({x1, y0, 0.5f, 1.0f});
    mClip.push_back({x1, y1, 0.5f, 1.0f});
    mClip.push_back({x0, y1, 0.5f, 1.0f});
    for (uint32_t i : {0u, 2u, 1u, 0u, 3u, 2u})
        mIndices.push_back(base + i);
    mTriangleSlot.push_back(slot);
    mTriangleSlot.push_back(slot);
}

} // namespace lighting
