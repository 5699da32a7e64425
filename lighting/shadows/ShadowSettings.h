// ShadowSettings: how shadow maps are rendered and looked up (ShadowMaps.h), one struct with the
// defaults in one place. Units: metres for world-space distances, texels for what scales with the
// map's resolution (a texel's footprint on the receiver, texelWorld below).
//
// The bias model (ShadowMaps::visibility): a receiver at light-space depth d (metres along the
// face's axis) is compared at each filter tap with the depth of its own tangent plane at that
// tap's texel centre (receiver-plane depth, so PCF taps on a tilted plane do not shadow the plane
// itself), minus
//   bias = biasConstant + biasSlope * texelWorld * tan(theta),
// theta the angle between the normal and the light (tan clamped at kMaxBiasTan, ShadowMaps.h),
// texelWorld the side of one texel at the receiver's depth. Before that the receiver moves by
// normalOffset * texelWorld along its normal. Plain data; parse/format are pure functions.
//
// These are the global settings (the CLI's). A scene light may override mapSize, the biases,
// the filter and the normal offset for itself (scenes::LightShadow: a JSON light's "shadow");
// ShadowMaps renders and looks up each light with settingsForLight(global, light.shadow).
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

#include "scenes/LightShadow.h"

namespace lighting {

// Percentage-closer filtering (none, pcf3, pcf5, poisson): defined with its names in
// scenes/LightShadow.h, since a scene may choose a light's own filter.
using scenes::formatShadowFilter;
using scenes::kShadowFilterNames;
using scenes::parseShadowFilter;
using scenes::ShadowFilter;

// How render() schedules the faces. FacesInParallel (default): one face per task, each task
// rendering with its thread's own Rasterizer; FacesInSequence: one face after another, each with
// the rasterizer's own tile parallelism. Both give bitwise the same maps. Measured on atrium
// with 16 casting point lights at 512^2 (tests/bench/shadow_bench.cpp, README.md here): faces in
// parallel 316 ms vs 373 ms in sequence on 1 thread (a 512^2 face has 16 tiles and most faces
// hold fewer triangles than one set-up batch, 2048, so in sequence the set-up is serial); the
// 2-thread run was taken on an overloaded machine and decides nothing yet.
enum class ShadowSchedule { FacesInParallel, FacesInSequence };

// How a point light's maps cover its sphere of directions. Cube: six 90-degree perspective
// faces; DualParaboloid: two faces, each a paraboloid projection of one hemisphere (front: world
// -Y, back: +Y), a third of the cube's bytes at the same mapSize. The paraboloid maps a straight
// edge to a circular arc but the rasterizer draws straight edges and interpolates depth linearly
// on screen: ShadowMaps splits every caster triangle until its edges span at most
// paraboloidMaxEdgeDegrees as seen from the light (ShadowMaps.h says what that costs).
enum class ShadowPointProjection { Cube, DualParaboloid };

// What a face's depth texels are stored as. Float32: the rasterizer's reversed-Z depth as it
// writes it (perspective: ~1e-7 relative precision at every distance). Unorm16: the distance
// along the face's axis, linear between its near and far planes, in 16 bits (half the bytes and
// half the lookup's memory traffic; a step of (far - near) / 65535: 0.05 mm for a 3.5 m point
// light, 15 mm over a 1 km cascade). Perspective depth is not stored as 16 bits as it is: reversed
// Z in unorm leaves a point light's far half a few hundred steps. Each texel is rounded towards
// the far plane, so an occluder is never stored nearer than it is: quantisation can move a
// shadow's start back by up to one step (peter-panning) but cannot make a surface shadow itself.
// The face is drawn in float (a per-thread buffer) and converted after its draw.
enum class ShadowDepthFormat { Float32, Unorm16 };

// The names parseShadowDepthFormat accepts, for error messages.
inline constexpr const char* kShadowDepthFormatNames = "float32|unorm16";

inline const char* formatShadowDepthFormat(ShadowDepthFormat format) {
    return format == ShadowDepthFormat::Unorm16 ? "unorm16" : "float32";
}

// "float32", "unorm16" (the CLI and sweep names: formatShadowDepthFormat's); nullopt for anything
// else.
inline std::optional<ShadowDepthFormat> parseShadowDepthFormat(std::string_view name) {
    for (const ShadowDepthFormat format : {ShadowDepthFormat::Float32, ShadowDepthFormat::Unorm16})
        if (name == formatShadowDepthFormat(format))
            return format;
    return std::nullopt;
}

// Bytes one texel costs in a face of this format (a face's array: ShadowMaps.h).
inline constexpr size_t shadowBytesPerTexel(ShadowDepthFormat format) {
    return format == ShadowDepthFormat::Unorm16 ? 2 : 4;
}

struct ShadowSettings {
    // Side of every shadow map face in texels (a face is mapSize^2 texels of depthFormat).
    int mapSize = 1024;
    // Of every light's faces (no light overrides it).
    ShadowDepthFormat depthFormat = ShadowDepthFormat::Float32;
    // Constant depth bias, metres. Covers the float depth of the map (reversed-Z perspective:
    // ~1e-7 relative; orthographic: ~1e-7 of the map's depth range, 1e-4 m over 1 km) and the
    // difference between the float render transform and the double lookup transform. 5 mm lets
    // a contact shadow start within 5 mm * sin(light angle) of the caster (the peter-panning
    // case of shadow_maps_test.cpp, a box on the ground).
    float biasConstant = 0.005f;
    // Slope-scaled bias in texels: the depth change across biasSlope texels of the receiver's
    // tangent plane. The receiver-plane depth already follows the plane between taps; this
    // covers normals that are not the geometric one (interpolated normals) and the rasterizer's
    // sub-texel snapping. 1.5 passes the acne case (a plane lit 80 degrees from its normal, no
    // self-shadowed pixel with every filter).
    float biasSlope = 1.5f;
    // Normal offset in texels: the receiver moves by normalOffset * texelWorld along its normal
    // before the lookup. 0 by default: the receiver-plane depth makes it unnecessary on planar
    // receivers, and any offset moves contact shadows away from their casters.
    float normalOffset = 0.0f;
    ShadowFilter filter = ShadowFilter::Pcf3;
    ShadowPointProjection pointProjection = ShadowPointProjection::Cube;
    // Dual-paraboloid faces: caster edges longer than this angle seen from the light are split
    // at their midpoints (recursively; 0 = never split, the straight-edge error in full).
    // Measured on a table's shadow (shadow_maps_test.cpp, 512^2, README.md): misclassified
    // 17.8% unsplit, 1.13% at 16 degrees, 0.70% at 8, 0.53% at 4, 0.52% at 2, for 140, 1.2k,
    // 4.5k, 17k and 68k triangles drawn: 8 keeps most of the gain at a quarter of 4's triangles.
    double paraboloidMaxEdgeDegrees = 8.0;
    // Directional lights: cascades over the view depth range (practical split scheme, log/uniform
    // lambda 0.5); 1 = one map fitted to the whole visible range.
    int cascades = 1;
    // At most this many casting lights get maps, those that matter most in view
    // (ShadowMaps::chooseLights); -1 = all.
    int maxShadowLights = -1;
    ShadowSchedule schedule = ShadowSchedule::FacesInParallel;
    // Shadow-casting sets (ShadowCasterSets.h): each light draws only the objects that can cast
    // onto a visible receiver. Off: every object in range (the brute force the sets are tested
    // against; the image is the same).
    bool casterSets = true;
    // Each face draws only the casters its frustum may hold, chosen by the rasterizer's own
    // trivial reject (raster::frustumOutcode) before the draw; the maps are bitwise the same.
    // Off (tests, A/B): every face hands its light's whole caster list to the draw.
    bool cullCastersPerFace = true;
    // A cube or spot face whose pyramid misses the camera's frustum (no receiver in view can
    // select it) is left empty: not drawn, not stored; the image is bitwise the same. Off (tests,
    // A/B): every face is drawn.
    bool cullFacesOutsideView = true;
};

// The names parseShadowPointProjection accepts, for error messages.
inline constexpr const char* kShadowPointProjectionNames = "cube|dual-paraboloid";

// "cube", "dual-paraboloid" (the CLI and sweep names); nullopt for anything else.
inline std::optional<ShadowPointProjection> parseShadowPointProjection(std::string_view name) {
    if (name == "cube")
        return ShadowPointProjection::Cube;
    if (name == "dual-paraboloid")
        return ShadowPointProjection::DualParaboloid;
    return std::nullopt;
}

inline const char* formatShadowPointProjection(ShadowPointProjection projection) {
    return projection == ShadowPointProjection::DualParaboloid ? "dual-paraboloid" : "cube";
}

// The settings one light's maps are rendered and looked up with: `global` with every field the
// light's own (scenes::LightShadow, a JSON scene's per-light "shadow") overrides. Pure.
inline ShadowSettings settingsForLight(const ShadowSettings& global,
                                       const scenes::LightShadow& own) {
    ShadowSettings settings = global;
    settings.mapSize = own.mapSize.value_or(global.mapSize);
    settings.biasConstant = own.biasConstant.value_or(global.biasConstant);
    settings.biasSlope = own.biasSlope.value_or(global.biasSlope);
    settings.filter = own.filter.value_or(global.filter);
    settings.normalOffset = own.normalOffset.value_or(global.normalOffset);
    return settings;
}

} // namespace lighting
