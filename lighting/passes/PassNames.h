// PassNames: the names of the timed passes of a frame, as they appear in StageResult::timingsMs,
// stats.json (timings_ms, timings.passes_ms) and the sweep's result columns
// (time_<pass>_median_ms). The stages report their passes by these constants and the experiments
// read them by the same constants, so a name is spelled in one place; adding a pass means adding
// it here (and to kPipelineOrder, which orders the result tables' columns).
#pragma once

#include <array>
#include <string_view>

namespace lighting::pass {

// Timed by the runner around the stage (not reported by stages):
inline constexpr const char* kGBuffer = "gbuffer";            // transform + raster + resolve
inline constexpr const char* kExactSurface = "exact_surface"; // reference surface (reference only)
// `--shadows maps`: every casting light's maps, depth-only (lighting/shadows/ShadowMaps.h).
inline constexpr const char* kShadowMaps = "shadow_maps";

// Reported by stages in StageResult::timingsMs:
inline constexpr const char* kTransform = "transform"; // vertices to clip/view space (forward)
inline constexpr const char* kPrepass = "prepass";     // depth-only pre-pass (forward)
inline constexpr const char* kCull = "cull";           // light culling, tile / light lists
inline constexpr const char* kClusters = "clusters";   // explicit clusters: keys, bounds
inline constexpr const char* kAssign = "assign";       // clustered light assignment
inline constexpr const char* kIndex = "index";         // light-indexed per-pixel lists
inline constexpr const char* kShading = "shading";     // evaluating the lights
inline constexpr const char* kLighting = "lighting";   // light buffer accumulation (pre-pass)
inline constexpr const char* kMaterial = "material";   // second geometry pass (pre-pass)
inline constexpr const char* kBlend = "blend"; // blended surfaces, after the opaque (BlendedPass.h)
// Multisampled frames: the layers' images weighted into the pixel (MultisampleShading.h).
inline constexpr const char* kResolve = "resolve";

// Timed by the runner after the stage, when `--post-aa` is not none (lighting/postaa/PostAa.h):
inline constexpr const char* kPostAa = "post_aa";

// The order passes run in within a frame; tables list passes this way, others after by name.
inline constexpr std::array<std::string_view, 15> kPipelineOrder = {
    kGBuffer, kExactSurface, kShadowMaps, kTransform, kPrepass, kCull,    kClusters, kAssign,
    kIndex,   kShading,      kLighting,   kMaterial,  kBlend,   kResolve, kPostAa};

} // namespace lighting::pass
