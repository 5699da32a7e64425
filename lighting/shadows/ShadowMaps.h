// ShadowMaps: the shadow maps of one frame (issue 29 item 1), rendered by raster::Rasterizer's
// depth-only path (a no-op fragment function), and their scalar lookup.
//
// Which objects: each light draws its shadow-casting set only (ShadowCasterSets.h; the objects
// that can cast onto a visible receiver), and point and spot lights only the triangles within
// their range. Which lights: every scene light with castsShadows that is not ambient; with a budget
// (ShadowSettings::maxShadowLights = N >= 0) the N of them that matter most in view
// (chooseLights). Each light with its own settings (ShadowSettings.h settingsForLight: the global
// ones, with a scene light's own map size, biases, filter and normal offset over them). Per
// light, faces:
//   spot         one perspective face along the axis, half-angle acos(spotOuterCos) plus a
//                margin of kFaceMarginTexels (clamped at kMaxSpotHalfAngleDegrees), near =
//                kNearFraction * range, far = range;
//   point        a cube map: six 90-degree perspective faces along world +X, -X, +Y, -Y, +Z, -Z,
//                near and far as for spot lights; a lookup takes the face of the major axis of
//                the world-space direction from the light. Or (ShadowPointProjection::
//                DualParaboloid) two paraboloid faces looking down world -Y (front) and +Y
//                (back): a direction d (unit, in the face's light frame, the face looking down
//                -Z) maps to (d.x, d.y) / (1 - d.z), its hemisphere to the disk inscribed in the
//                face; depth is the distance to the light, stored linearly (1 = near, 0 = far).
//                Each face draws its casters clipped to its hemisphere (the plane through the
//                light) and split until every edge spans at most paraboloidMaxEdgeDegrees seen
//                from the light: the rasterizer draws straight edges and interpolates depth
//                linearly on screen, where the paraboloid maps straight edges to circular arcs
//                and distance is not linear. An edge is split by its own length and angle only
//                (the same decision in both triangles that share it), so the split mesh has no
//                T-junctions and stays watertight. A lookup takes the face of the hemisphere of
//                the direction from the light;
//   directional  `cascades` orthographic faces, each fitted to its slice of the camera frustum
//                clipped to the scene's geometry bounds (the visible receivers), in light space:
//                x and y the intersection of the slice's and the scene's light-space boxes (plus
//                kFaceMarginTexels), the near plane pushed back to the scene's bound nearest the
//                light (so every caster of the scene between receivers and light is in). The
//                slices split the view depth range [max(near, scene), min(far, scene)] by the
//                practical scheme (log/uniform, lambda kCascadeLambda); the lookup takes the first
//                cascade whose far split is at or beyond the receiver's view depth.
//
// Conventions: each face is a right-handed light view (looking down its -Z) with a zero-to-one
// reversed-Z projection (1 = near plane, 0 = far plane / nothing; orthographic depth is linear,
// perspective float depth keeps ~1e-7 relative precision); the depth texture is mapSize^2 floats
// (ShadowDepthFormat::Unorm16: 16-bit linear depth, the same 1 = near, 0 = far, ShadowSettings.h),
// row 0 at the top (the rasterizer's screen convention, y down). No face culling (CullMode::None):
// both sides of a caster write, so open meshes (a single quad, a leaf) cast and the bias model
// does not depend on which side faces the light. lightClipFromView maps CAMERA VIEW space (the
// space the shading kernel works in) to the face's clip space.
//
// Threading: render() runs in parallel under the caller's tbb::task_arena (per ShadowSchedule);
// every face is written by one task only, so the maps are bitwise the same for any thread count.
// A built ShadowMaps is immutable; visibility() and the accessors are thread-safe.
//
// Two lookups, one answer: visibility() here (scalar, the oracle) and the shading kernel's vector
// lookup (lighting/kernel/VectorShadows-inl.h), which reads view() (ShadowMapsView.h: the same
// matrices, planes, depth texels, settings and constants) and performs the same double operations
// in the same order for 2 to 8 lanes at once, so its answers are bitwise visibility()'s
// (tests/kernel/vector_shadows_test.cpp). A change to the lookup's arithmetic here must be made
// there too; that test fails when they disagree on its random points and the cube's seams.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/ShadowLookup.h"
#include "lighting/shadows/ShadowMapsView.h"
#include "lighting/shadows/ShadowSettings.h"
#include "scenes/Scene.h"

namespace lighting {

// Near plane of spot and point faces as a fraction of the range: casters closer than 0.1% of the
// range to the light cast no shadow (a light inside a caster would be black anyway). Reversed Z
// in float keeps the depth's relative precision whatever the near plane, so it costs no
// precision to keep it small; at 1% a leaf card 3.5 cm from a light of range 3.5 m (foliage)
// was clipped and leaked light onto a whole bush.
inline constexpr double kNearFraction = 0.001;
// Spot cones wider than this are clamped (a perspective face cannot reach 90 degrees); points
// outside the clamped cone are lit.
inline constexpr double kMaxSpotHalfAngleDegrees = 80.0;
// Every face except the cube's is widened by this many texels on each side, so that filter taps
// (at most 2.5 texels away) at the edge of a spot cone or a cascade stay inside the map.
inline constexpr int kFaceMarginTexels = 3;
// The practical split scheme's weight of the logarithmic split (1 - lambda: uniform).
inline constexpr double kCascadeLambda = 0.5;
// The farthest texel centre a lookup reads from the receiver's projection, in texels: the
// Poisson disk's radius (ShadowSettings.h; PCF 5x5 reaches 2).
inline constexpr double kMaxTapDistanceTexels = 2.5;

struct ShadowFace {
    // Camera view -> face clip (reversed Z, 0 <= z <= w); paraboloid faces: camera view -> the
    // face's light frame (looking down -Z), the projection after it is not a matrix (above).
    glm::mat4 lightClipFromView{1.0f};
    glm::dmat4 lightClipFromViewExact{1.0}; // the same in double, what visibility() uses
    bool orthographic = false;
    bool paraboloid = false;
    double nearMetres = 0.0; // light-space depth of the near and far planes
    double farMetres = 0.0;
    // Perspective: tan of the half field of view; orthographic: the box's larger side, metres.
    // Paraboloid: 2, so that 2 * tanHalfFov * depth / mapSize is its widest texel (at the
    // face's centre; at its rim a texel spans half that).
    double tanHalfFov = 0.0;
    double extentMetres = 0.0;
    // Nothing to receive: lookups lit. A cascade outside the scene, or a perspective face that
    // no receiver in the camera's frustum can select (outsideView, ShadowSettings::
    // cullFacesOutsideView): never looked up.
    bool empty = false;
    bool outsideView = false;
    int mapSize = 0; // its light's (ShadowLightStats::settings.mapSize)
    ShadowDepthFormat depthFormat = ShadowDepthFormat::Float32;
    // Float32 faces: mapSize^2, row 0 at the top; empty when `empty` and for Unorm16 faces.
    std::vector<float> depth;
    // Unorm16 faces: mapSize^2 texels (row 0 at the top) packed two per word, texel k in
    // shadows::unorm16Texel(packedDepth.data(), k); else empty.
    std::vector<uint32_t> packedDepth;
    // Per rasterizer tile of `depth` (raster::RasterState::tilesNotClear): whether casters were
    // binned to it; 0 = the tile holds only 0 (far). It travels with the buffer to the next
    // frame's maps (render's `recycled`), whose draw then clears only the tiles that are not
    // already clear. Unorm16 faces are drawn into a per-thread float buffer, which keeps its
    // own record; theirs is packedDepth's (0 = the tile's texels are all 0), so that packing
    // rewrites a clear tile only where a previous frame left depth in it.
    std::vector<uint8_t> tilesNotClear;
};

// Per shadow (one casting light).
struct ShadowLightStats {
    size_t lightIndex = 0;
    scenes::LightType type = scenes::LightType::Point;
    size_t faceCount = 0;
    size_t facesOutsideView = 0; // of faceCount, left empty by cullFacesOutsideView
    size_t bytes = 0;
    // The settings its maps were rendered and are looked up with: the global ones with the
    // light's own (scenes::LightShadow) over them (settingsForLight).
    ShadowSettings settings;
    // Triangles the rasterizer was given over all faces: after the range cull and, with
    // cullCastersPerFace, each face's frustum cull (dual-paraboloid faces: after clipping to
    // the hemisphere and splitting).
    uint64_t trianglesDrawn = 0;
    // Its shadow-casting set (ShadowCasterSets.h): the instances drawn into its maps (every
    // instance with triangles when the sets are off), and O'Rorke's case.
    uint64_t casterObjects = 0;
    bool lightInFrustum = false;
    // Sum of the wall time of its faces' render tasks (with faces in parallel, CPU time).
    double renderMs = 0.0;
};

struct ShadowStats {
    size_t faceCount = 0;
    size_t facesOutsideView = 0; // of faceCount, left empty by cullFacesOutsideView
    size_t totalBytes = 0;
    double renderMs = 0.0;                // wall time of render(), all lights
    size_t castingLightCount = 0;         // lights that would cast without the budget
    uint64_t objectCount = 0;             // scene instances with triangles
    std::vector<ShadowLightStats> lights; // one per shadow, in shadow index order
};

// The kernel's ShadowLookup (ShadowLookup.h): the stages shade with it through KernelLights.
class ShadowMaps final : public shadows::ShadowLookup {
public:
    static constexpr uint32_t kNoShadow = shadows::kNoShadow;

    ShadowMaps() = default;
    // Move-only: the view (view()) points into the maps' own arrays, which a move carries along
    // and a copy would not.
    ShadowMaps(ShadowMaps&&) noexcept = default;
    ShadowMaps& operator=(ShadowMaps&&) noexcept = default;
    ShadowMaps(const ShadowMaps&) = delete;
    ShadowMaps& operator=(const ShadowMaps&) = delete;

    // Renders every face of every chosen light. Parallel under the caller's task_arena; the
    // result is bitwise independent of the thread count. Cost: per light the triangles within
    // its range (spot, point) or all (directional), set up once per face; memory: mapSize^2
    // texels of the depth format per face (plus, for Unorm16, one float buffer per thread and
    // map size, kept in the scratch). Throws std::invalid_argument for a mapSize (global or a
    // light's own) outside [1, 16384] or cascades outside [1, 8]. `recycled`, when given, is a
    // previous frame's maps whose depth buffers and rasterizers the new maps take over (it is left
    // without faces), face i the buffer of its face i: a frame then pays no allocation or page
    // fault for its maps, and clears only the tiles that either frame drew into.
    static ShadowMaps render(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry,
                             const gbuffer::CameraView& view, const ShadowSettings& settings,
                             ShadowMaps* recycled = nullptr);

    // The casting lights (indices into scene.lights, ascending) that get maps under the budget
    // (casting: castsShadows and not ambient; when no light of the scene is marked, every
    // non-ambient light):
    // all of them when maxShadowLights < 0, else the maxShadowLights with the highest
    // intensity * max(colour) / max(distance from the camera to the light's support, near)^2
    // (support: the light's bounding sphere, LightBounds.h; directional: distance 0), those
    // whose support misses the view frustum after all others, ties by index. Pure.
    static std::vector<uint32_t> chooseLights(const std::vector<scenes::Light>& lights,
                                              const gbuffer::CameraView& view, int maxShadowLights);

    // Shadow index of scene light `lightIndex` (the scene's `lights` order, which LightList
    // keeps), or kNoShadow. O(1).
    uint32_t shadowOf(size_t lightIndex) const override {
        return lightIndex < mShadowOfLight.size() ? mShadowOfLight[lightIndex] : kNoShadow;
    }
    // Fraction of the light reaching a receiver at positionView with normal normalView (camera
    // view space; the normal need not be unit, a zero normal disables the receiver plane and the
    // slope bias) in [0, 1], 0 = fully shadowed, with the light's filter and bias
    // (ShadowSettings.h; the global ones unless the light has its own). Points outside every face's
    // coverage (beyond the range, outside a spot's cone or a cascade's box, closer than the near
    // plane) are lit: the light's own falloff and cone decide there. Never NaN for finite input
    // (non-finite input: 1). Cost: a few matrix products and 1 / 9 / 25 / 16 taps. Thread-safe.
    float visibility(uint32_t shadow, const glm::vec3& positionView,
                     const glm::vec3& normalView) const override;
    // The maps as plain data for the kernel's vector lookup (ShadowMapsView.h), which is bitwise
    // visibility(): it points into these maps. O(1).
    const shadows::ShadowMapsView* view() const override { return &mView; }

    size_t shadowCount() const { return mShadows.size(); }
    const ShadowFace& face(size_t index) const { return mFaces[index]; }
    size_t faceCount() const { return mFaces.size(); }
    // Faces of a shadow: [firstFace, firstFace + faceCount).
    size_t firstFace(uint32_t shadow) const { return mShadows[shadow].firstFace; }
    size_t faceCountOf(uint32_t shadow) const { return mShadows[shadow].faceCount; }
    // The face a lookup of `shadow` at positionView (camera view space) reads: the cube face of
    // its major axis, the cascade of its depth, a spot's or paraboloid's own; SIZE_MAX for none.
    size_t faceOf(uint32_t shadow, const glm::vec3& positionView) const {
        return faceFor(mShadows[shadow], glm::dvec3(positionView));
    }
    const ShadowStats& stats() const { return mStats; }
    // The global settings render() was given (each light's own: stats().lights[s].settings).
    const ShadowSettings& settings() const { return mSettings; }

private:
    struct Shadow {
        size_t lightIndex = 0;
        scenes::LightType type = scenes::LightType::Point;
        size_t firstFace = 0;
        size_t faceCount = 0;
        ShadowSettings settings;                 // the light's (settingsForLight)
        bool paraboloid = false;                 // point lights: dual-paraboloid faces
        glm::dvec3 positionView{0.0};            // point lights: the cube's centre
        std::vector<double> cascadeFarDepthView; // directional: far split of each cascade
    };

    // The face of `shadow` that covers positionView (cube face, cascade), or SIZE_MAX.
    size_t faceFor(const Shadow& shadow, const glm::dvec3& positionView) const;
    float faceVisibility(const ShadowFace& face, const ShadowSettings& settings,
                         glm::dvec3 positionView, const glm::dvec3& normalView) const;

    struct RenderScratch; // per-thread rasterizers, handed from frame to frame (ShadowMaps.cpp)

    ShadowSettings mSettings;
    std::shared_ptr<RenderScratch> mScratch;
    std::vector<Shadow> mShadows;
    std::vector<ShadowFace> mFaces;
    std::vector<uint32_t> mShadowOfLight; // per scene light
    glm::dmat3 mWorldFromViewRotation{1.0};
    ShadowStats mStats;
    // view(): filled at the end of render(); its arrays point into mShadows and mFaces.
    std::vector<shadows::ShadowView> mShadowViews;
    std::vector<shadows::ShadowFaceView> mFaceViews;
    shadows::ShadowMapsView mView;
};

} // namespace lighting
