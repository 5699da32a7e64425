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
#pragma once

#include <optional>
#include <string_view>

namespace lighting {

// Percentage-closer filtering: None = the nearest texel; Pcf3 / Pcf5 = box of 3x3 / 5x5 texels
// around it; Poisson = 16 taps of a fixed Poisson disk of radius 2.5 texels (no per-pixel
// rotation: the result depends on nothing but the inputs).
enum class ShadowFilter { None, Pcf3, Pcf5, Poisson };

// How render() schedules the faces. FacesInParallel (default): one face per task, each task
// rendering with its thread's own Rasterizer; FacesInSequence: one face after another, each with
// the rasterizer's own tile parallelism. Both give bitwise the same maps. Measured on atrium
// with 16 casting point lights at 512^2 (tests/bench/shadow_bench.cpp, README.md here): faces in
// parallel 316 ms vs 373 ms in sequence on 1 thread (a 512^2 face has 16 tiles and most faces
// hold fewer triangles than one set-up batch, 2048, so in sequence the set-up is serial); the
// 2-thread run was taken on an overloaded machine and decides nothing yet.
enum class ShadowSchedule { FacesInParallel, FacesInSequence };

struct ShadowSettings {
    // Side of every shadow map face in texels (a face is mapSize^2 floats).
    int mapSize = 1024;
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
};

// The names parseShadowFilter accepts, for error messages.
inline constexpr const char* kShadowFilterNames = "none|pcf3|pcf5|poisson";

// "none", "pcf3", "pcf5", "poisson" (the CLI and sweep names); nullopt for anything else.
inline std::optional<ShadowFilter> parseShadowFilter(std::string_view name) {
    if (name == "none")
        return ShadowFilter::None;
    if (name == "pcf3")
        return ShadowFilter::Pcf3;
    if (name == "pcf5")
        return ShadowFilter::Pcf5;
    if (name == "poisson")
        return ShadowFilter::Poisson;
    return std::nullopt;
}

inline const char* formatShadowFilter(ShadowFilter filter) {
    switch (filter) {
    case ShadowFilter::None:
        return "none";
    case ShadowFilter::Pcf3:
        return "pcf3";
    case ShadowFilter::Pcf5:
        return "pcf5";
    case ShadowFilter::Poisson:
        return "poisson";
    }
    return "none";
}

} // namespace lighting
