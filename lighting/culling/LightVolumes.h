// LightVolumes: light-volume rasterization over a G-buffer, shared by the `deferred` and
// `light-indexed` stages (Ishmukhametov 2013, 1.3, 2.3 and 3.5; Trebilco's light-indexed
// deferred lighting).
//
// For each light drawn (bounded lights by their conservative sphere from boundingSpheresView),
// draw() calls fn(light, x, y, pixel) for every covered G-buffer pixel whose surface MAY lie
// inside the sphere, at most once per light and pixel. It never misses a pixel whose surface
// lies inside the sphere:
// - Sphere volumes rasterize a proxy polyhedron (an icosahedron subdivided once, 80 faces) whose
//   faces CIRCUMSCRIBE the sphere, grown further by kProxyMarginPixels of screen space (so
//   fixed-point snapping of the silhouette cannot lose a pixel). Only BACK faces are drawn (front
//   faces culled): a surface inside the volume is in front of (or on) the volume's back face, so
//   the test "surface not behind the back face" keeps it. Near-plane clipping only removes back
//   faces in front of the near plane, where no surface lies, so a camera inside the volume or a
//   volume crossing the near plane loses nothing. Far-plane clipping WOULD lose pixels, so a
//   proxy reaching beyond the far plane falls back to the screen rectangle.
// - Spot lights (half-angle below kConeMaxHalfAngleDegrees) may instead rasterize a CONE PROXY
//   (coneProxy()): a pyramid with its apex behind the light and a kConeProxySides-gon base, whose
//   faces circumscribe the lit cone truncated at axial distance = range (the lit region
//   {distance < range, angle < outer} lies in it: axial distance <= distance), dilated by the
//   same slack as the sphere (LightBounds.h) plus the same kProxyMarginPixels metric margin. The
//   rule (spot=cone): draw whichever of the two proxies has the smaller volume, a view-independent
//   stand-in for the surfaces each one encloses. Per unit range cubed the pyramid has
//   4 tan^2(t) tan(pi/12) and the sphere proxy 4.49 R^3 (R of LightBounds.h): 0.36 vs 0.86 at
//   30 degrees, 1.07 vs 1.59 at 45, 3.2 vs 2.9 at 60; the cone wins up to about 57 degrees. From
//   kConeMaxHalfAngleDegrees on the cone is not even built (its volume blows up as tan^2). The
//   pyramid is convex and closed, so everything said here of sphere proxies (back faces,
//   near-plane clipping, far-plane fallback, stencil) holds for it as well; its depth bounds are
//   the tighter of its vertices' view-depth range and the sphere's.
// - stencil=1 adds the two-sided test: the FRONT faces mark pixels whose surface is not in
//   front of the front face; the back faces then only accept marked pixels. When
//   the proxy crosses the near plane its front faces are clipped, so the front test is skipped.
// - Rect volumes cover the sphere's conservative screen rectangle (full screen when the sphere
//   crosses the near plane), with no back-face test.
// Every volume is followed by the depth-bounds test: the surface's view depth within
// [centre - radius, centre + radius] (for cone proxies also within the pyramid's depth range).
//
// Batching: all lights of a frame are drawn in ONE rasterizer draw, light after light in ascending
// index order. Inside a screen tile the rasterizer visits triangles in submission order, and a
// pixel belongs to one tile, so every pixel meets its lights in ascending order (what exactness
// needs) while all tiles work in parallel and the set-up cost is paid once. Rectangles
// (volume=rect, far-plane fallback) and unbounded lights (directional, ambient: full screen) are
// drawn as screen-aligned quads in the same stream, at their place in the light order. With
// stencil=1 each proxy is submitted twice with no face culling: the first copy's front faces mark
// pixels, the second copy's back faces test; light i's copies precede light i+1's in every tile.
//
// Depth comparisons are done in the fragment function against the G-buffer's depth plane with a
// tolerance (kDepthTolerance) that only ever keeps more pixels: float rounding of the proxy's
// clip coordinates moves its depth by ~1 ulp, more than the proxy's metric margin in standard Z.
//
// Conventions: view space right-handed, camera looking down -Z; depth in the G-buffer's
// convention (reversed Z by default: near = 1). Threading: one draw at a time per object; inside
// a draw fn is called concurrently for different tiles but for any pixel by one task only.
// Deterministic: the pixels visited do not depend on the thread count.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/GBuffer.h"
#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"
#include "raster/Rasterizer.h"

namespace lighting {

// A unit proxy: triangles wound counter-clockwise seen from outside; every face plane is at
// distance >= 1 from the origin (the unit sphere is inside), vertices at circumradius.
struct ProxyMesh {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
    float circumradius = 1.0f; // largest vertex distance from the origin
    double volume = 0.0;       // enclosed volume
};
// The icosahedron subdivided once (42 vertices, 80 faces), scaled so its inradius is 1.
const ProxyMesh& unitProxySphere();

enum class VolumeShape { Sphere, Rect };

// Screen growth of the proxy in pixels: covers fixed-point snapping (1/512 px) and the float
// rounding of vertex transforms by a wide margin; costs a thin ring of extra fragments.
inline constexpr float kProxyMarginPixels = 0.25f;
// A spot light's cone proxy: 12 sides put the base polygon's vertices 3.5% beyond the cone's
// circle (1 / cos(pi/12)) and its area 2.3% above the circle's, for 22 triangles (the sphere
// proxy has 80); 8 sides would cost 8% and 5.5%, 16 sides 2% and 1.3% for 30 triangles.
inline constexpr int kConeProxySides = 12;
// From this outer half-angle on, spot lights use the sphere proxy: the pyramid's volume grows as
// tan^2 and the sphere (radius range * sin) is smaller long before.
inline constexpr double kConeMaxHalfAngleDegrees = 80.0;
// Absolute widening of a spot's outer cosine: evaluateLight compares a float cosine (a few ulps
// of error, and a float axis up to 1e-7 off unit length) with the outer cosine; widening the cone
// by 1e-6 in cosine covers that even for cones narrower than a degree.
inline constexpr double kConeCosSlack = 1e-6;

// A spot light's cone proxy in view space: the apex (index 0) and the base polygon
// (1..kConeProxySides). Faces are coneProxyIndices(), counter-clockwise seen from outside.
struct ConeProxy {
    std::array<glm::vec3, kConeProxySides + 1> positionsView;
    double volume = 0.0; // cubic metres
};
const std::vector<uint32_t>& coneProxyIndices();
// The pyramid around `light`'s lit cone, its faces at least `marginMetres` (plus LightBounds'
// slack) outside the truncated cone; empty for lights that are not spots or whose half-angle is
// kConeMaxHalfAngleDegrees or more. Pure function, thread-safe.
std::optional<ConeProxy> coneProxy(const LightSphere& light, float marginMetres);

// Which proxy a bounded spot light gets (VolumeShape::Sphere only): Cone picks the smaller of the
// cone and sphere proxies (file comment), Sphere always draws the sphere.
enum class SpotProxy { Cone, Sphere };

// Relative depth tolerance (of the depth value in reversed Z, of 1 in standard Z).
inline constexpr float kDepthTolerance = 1e-5f;

struct LightVolumeStats {
    uint64_t lightsDrawn = 0;   // bounded lights that reached a volume draw
    uint64_t rectFallbacks = 0; // sphere volumes replaced by the rectangle (far plane)
    uint64_t coneProxies = 0;   // spot lights drawn with their cone proxy
    uint64_t fragments = 0;     // samples covered by the volume draw (before any depth test)
};

class LightVolumeRasterizer {
public:
    LightVolumeRasterizer(const gbuffer::GBuffer& gbuffer, VolumeShape shape, bool stencil,
                          SpotProxy spotProxy);

    // Indices (ascending) of the lights to draw: all of them, or with `frustumCull` only those
    // whose sphere may touch the view frustum (CPU view-frustum culling, ViewFrustum of
    // CullingTests.h).
    std::vector<uint32_t> lightsToDraw(const std::vector<LightSphere>& spheres,
                                       bool frustumCull) const;

    // Draws the volumes of `lightIndices` (ascending; unbounded lights included) in one pass and
    // calls fn(light, x, y, pixel) as described in the file comment. Cost: set-up of 80 (160 with
    // stencil) triangles per sphere, 22 (44) per cone, then O(covered bounding-box pixels) in
    // parallel over tiles.
    template <class Fn>
    void draw(const std::vector<LightSphere>& spheres, const std::vector<uint32_t>& lightIndices,
              Fn&& fn);

    const LightVolumeStats& stats() const { return mStats; }
    // The rasterizer's screen tiles (raster::kTileSize pixels square, raster::Rasterizer::tileOf):
    // draw() calls fn for the pixels of one tile from one task at a time and, inside a tile, light
    // after light in ascending order (each light's fragments together), so a caller may keep state
    // per tile (e.g. gather a light's pixels and shade them when the tile's light changes).
    int tileCount() const { return mRasterizer.tileCountX() * mRasterizer.tileCountY(); }
    int tileOf(int x, int y) const { return mRasterizer.tileOf(x, y); }

    // Inclusive pixel rectangle that contains the projection of the sphere (full screen when it
    // crosses the near plane); empty (minX > maxX) when it cannot be seen.
    struct PixelRect {
        int minX, minY, maxX, maxY;
    };
    PixelRect screenRect(const LightSphere& sphere) const;
    // The G-buffer depth values a surface inside the sphere can have: its view-depth range
    // (clamped to the near and far planes) mapped to depth, widened by kDepthTolerance.
    struct DepthRange {
        float lo, hi;
    };
    DepthRange depthBounds(const LightSphere& sphere) const;
    // The same for the view-depth range [zFarthest, zNearest] (metres, negative in front).
    DepthRange depthBoundsOfViewZ(double zNearest, double zFarthest) const;

private:
    // One drawn light: what the fragment function needs, looked up by triangle.
    struct Slot {
        uint32_t light;
        DepthRange depth;
        bool backFaceTest;  // a proxy (else a screen quad: no depth test)
        bool frontFaceTest; // stencil: the surface must not be in front of the front face
    };
    // Triangles of a stencil front-marking copy carry this bit in mTriangleSlot.
    static constexpr uint32_t kFrontCopy = 0x80000000u;

    // The surface is not behind the fragment (it may be in front of the volume's back face),
    // with the tolerance in the conservative direction.
    bool surfaceNotBehind(float fragmentDepth, float surfaceDepth) const {
        const float tolerance = kDepthTolerance * (mReversedZ ? surfaceDepth : 1.0f);
        return mReversedZ ? fragmentDepth <= surfaceDepth + tolerance
                          : fragmentDepth >= surfaceDepth - tolerance;
    }
    bool surfaceNotInFront(float fragmentDepth, float surfaceDepth) const {
        const float tolerance = kDepthTolerance * (mReversedZ ? surfaceDepth : 1.0f);
        return mReversedZ ? fragmentDepth >= surfaceDepth - tolerance
                          : fragmentDepth <= surfaceDepth + tolerance;
    }
    // Fills mClip, mIndices, mTriangleSlot and mSlots for the lights to draw.
    void buildGeometry(const std::vector<LightSphere>& spheres,
                       const std::vector<uint32_t>& lightIndices);
    // The metric margin that grows a proxy by kProxyMarginPixels for surfaces up to
    // `farthestMetres` from the eye.
    float marginMetres(float farthestMetres) const;
    // True when the cone proxy was added (it is smaller than the sphere proxy and fits the far
    // plane); fills the slot's tests and depth bounds.
    bool tryConeProxy(const LightSphere& sphere, uint32_t slot);
    void addProxy(const LightSphere& sphere, uint32_t slot);
    void addMesh(const glm::vec3* positionsView, size_t positionCount,
                 const std::vector<uint32_t>& indices, uint32_t slot);
    void addQuad(const PixelRect& rect, uint32_t slot);

    const gbuffer::GBuffer& mGBuffer;
    const float* mDepth;
    VolumeShape mShape;
    bool mStencil;
    SpotProxy mSpotProxy;
    bool mReversedZ;
    float mClearDepth;
    float mNearMetres, mFarMetres;
    float mProjX, mProjY;                 // clipFromView[0][0], [1][1]
    float mPixelsPerTanX, mPixelsPerTanY; // focal lengths in pixels
    glm::dmat4 mClipFromViewExact;
    glm::mat4 mClipFromView;
    raster::Rasterizer mRasterizer;
    std::vector<glm::vec4> mClip;
    std::vector<uint32_t> mIndices;
    std::vector<uint32_t> mTriangleSlot; // per triangle: index into mSlots (| kFrontCopy)
    std::vector<Slot> mSlots;
    std::vector<uint32_t> mVisitedStamp; // light index + 1 of the last light that visited a pixel
    std::vector<uint32_t> mFrontStamp;   // stencil: light index + 1 passing the front-face test
    LightVolumeStats mStats;
};

// ---------------------------------------------------------------------------------------------

template <class Fn>
void LightVolumeRasterizer::draw(const std::vector<LightSphere>& spheres,
                                 const std::vector<uint32_t>& lightIndices, Fn&& fn) {
    buildGeometry(spheres, lightIndices);
    const int width = mGBuffer.width();
    const float clearDepth = mClearDepth;
    const raster::TriangleList triangles{mClip, mIndices};
    raster::RasterState state;
    state.depthWrite = false;
    state.barycentrics = false; // a volume has no varyings
    // Without stencil only back faces are drawn; quads are wound clockwise (back-facing).
    state.cullMode = mStencil ? raster::CullMode::None : raster::CullMode::Front;
    const bool stencil = mStencil;
    mRasterizer.draw(triangles, state, nullptr, [&](const raster::Fragment& f) {
        const uint32_t code = mTriangleSlot[f.triangle];
        const Slot& slot = mSlots[code & ~kFrontCopy];
        const size_t pixel = size_t(f.y) * width + f.x;
        // Background and the depth-bounds test, on depth values (no division per pixel).
        const float depth = mDepth[pixel];
        if (depth == clearDepth || depth < slot.depth.lo || depth > slot.depth.hi)
            return;
        const uint32_t stamp = slot.light + 1;
        if (code & kFrontCopy) {
            if (f.frontFacing && surfaceNotInFront(f.depth, depth))
                mFrontStamp[pixel] = stamp;
            return;
        }
        if (slot.backFaceTest) {
            if (stencil && f.frontFacing)
                return;
            if (!surfaceNotBehind(f.depth, depth))
                return;
            if (slot.frontFaceTest && mFrontStamp[pixel] != stamp)
                return;
        }
        // A watertight convex proxy covers a pixel with one back face; the stamp guards the
        // sum against a double visit all the same (one light must be added once).
        if (mVisitedStamp[pixel] == stamp)
            return;
        mVisitedStamp[pixel] = stamp;
        fn(slot.light, f.x, f.y, pixel);
    });
    mStats.fragments += mRasterizer.lastStats().samplesCovered;
}

} // namespace lighting
