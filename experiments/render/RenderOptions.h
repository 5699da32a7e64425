// RenderOptions: every option of one render (the CLI's `testbed render` and every job of a
// sweep), their defaults in one place, setting them from text by name, and their validation.
// Validation is cheap (it loads no scene and allocates no image) and names the first bad option;
// planRender (RenderPlan.h) validates once and keeps what validation built on the way.
//
// Errors: UsageError, one clear message naming the option and what was expected. A bad G-buffer
// name reported by the gbuffer library as std::invalid_argument becomes a UsageError through
// usageErrorFrom, the one place that conversion is written.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/ShadingStage.h"
#include "lighting/postaa/PostAa.h"
#include "lighting/shadows/ShadowSettings.h"
#include "scenes/SceneRequest.h"
#include "scenes/input/Limits.h"

namespace experiments {

// The view value that stands for every view of the scene: `render --view all` renders each into
// OUT/views/NAME/ (and OUT/views.json), a sweep makes one job per view (SweepFile.h).
inline constexpr const char* kEveryView = "all";

// Every option of a render, with its default in one place (the CLI's --help shows these).
struct RenderOptions {
    std::string scene = "atrium";
    std::map<std::string, std::string> sceneOptions; // --scene-option key=value
    // The scene's view (named camera, scenes/Viewpoints.h) to render: "" = its first view. "all"
    // is resolved by `testbed render` and the sweep into one render per view before planning.
    std::string view;
    std::string stage = "brute";
    // Generated point lights. Unset: a JSON scene's own lightGenerator decides (the file wins);
    // every other scene gets kDefaultLights. Set (--lights, a sweep's `lights`), it replaces a
    // JSON scene's generator count and seed (requestedLights).
    std::optional<int> lights;
    uint64_t seed = 1;
    // --light-density fixed|constant-overlap (scenes/SceneRequest.h LightDensity).
    scenes::LightDensity lightDensity = scenes::LightDensity::FixedRadius;
    int width = 1280;
    int height = 720;
    int threads = 0; // 0 = every hardware thread
    // The shading kernel's instruction set (lighting/kernel/KernelIsa.h): "auto" (the widest this
    // CPU runs), "scalar" (evaluateLight per pixel), or a target name (sse4, avx2, avx3...).
    std::string isa = "auto";
    int simtWarp = 32; // lanes of the SIMT cost model's warp: 32 (8x4 pixels) or 64 (8x8)
    // Anti-aliasing: samples per pixel of the G-buffer pass (1, 2, 4, 8; raster/Rasterizer.h) and
    // how complex pixels are found (primitive | discontinuity; gbuffer/msaa/FragmentLayers.h).
    int msaa = 1;
    std::string complexDetect = "primitive";
    // Alpha-masked (glTF MASK) materials at msaa > 1: "off" alpha-tests each fragment against its
    // alphaCutoff (all of its samples or none); "on" keeps round(alpha * msaa) of its samples in a
    // fixed 2x2-dithered pattern (raster/AlphaToCoverage.h), in every draw that must keep the same
    // fragments (G-buffer pass, forward stages, their pre-passes). Refused with --msaa 1.
    std::string alphaToCoverage = "off";
    bool compareReference = false;
    // Samples per pixel of the reference compared with (lighting/SupersampledReference.h): a
    // square 1..256; 1 is the pixel-centre reference, 16 the D3D 16x pattern, other squares a
    // stratified grid. Every stage is measured against the same anti-aliased truth.
    int referenceSpp = 16;
    // G-buffer: a preset name ("" = derived from the scene and the stage,
    // gbuffer/LayoutDerivation.h), then overrides of its normal encoding ("NAME:BITS"), depth
    // format and position method.
    std::string layout;
    std::string normals;
    std::string depth;
    std::string position;
    std::string normalSpace; // "view" (default) or "world"
    // Material model every material is shaded with: "auto" (what each material says),
    // "blinn-phong" or "metallic-roughness" (forced, for studies; scenes::forceMaterialModel).
    std::string brdf = "auto";
    // Post-process anti-aliasing of the stage's image (lighting/postaa/PostAa.h): "none",
    // "edge-blur" (G-buffer depth and normal edges, blurred; adds depth and normals to the derived
    // layout) or "fxaa" (luminance edges, FXAA 3.11). Timed as the pass post_aa, applied before
    // the error is measured.
    std::string postAa = "none";
    // Shadows (lighting/shadows, issue 29): "off", or "maps": shadow maps rendered by the
    // rasterizer's depth-only path and looked up in the shading kernel by every stage, the
    // reference then ray-tracing the same lights' visibility (Embree) as the truth. Casting
    // lights: those the scene marks (JSON castsShadows, every glTF punctual light), or every
    // non-ambient light when it marks none; shadowLights keeps the N that matter most in view.
    // The light-count oracle culling efficiency is measured against (lighting/Oracle.h):
    // "unshadowed" (lights whose radiance at the surface is non-zero, occlusion ignored) or
    // "visibility" (only those that also reach it: one Embree shadow ray per contributing pair).
    std::string oracle = "unshadowed";
    std::string shadows = "off";
    int shadowMapSize = 1024;          // texels per face side (ShadowSettings::mapSize)
    std::string shadowBias;            // "CONSTANT,SLOPE" (metres, texels); "" = the defaults
    std::string shadowFilter = "pcf3"; // none | pcf3 | pcf5 | poisson
    std::string shadowPoint = "cube";  // point lights' maps: cube | dual-paraboloid
    std::string shadowDepthFormat = "float32"; // float32 | unorm16 (ShadowDepthFormat)
    std::string shadowLights = "all";          // N or all
    int shadowCascades = 1;                    // directional lights' cascades, 1..8
    // Shadow-casting sets (lighting/shadows/ShadowCasterSets.h): "on" draws into each light's
    // maps only the objects that can cast onto a visible receiver; "off" every object in range.
    std::string shadowCasterSets = "on";
    // Peak memory a render may need (MemoryEstimate.h), bytes; 0 = kDefaultMaxMemoryFraction of
    // the machine's memory. A render estimated over it is refused before allocating.
    uint64_t maxMemoryBytes = 0;
    int warmup = 0;      // untimed runs of the G-buffer pass and the stage before the timed ones
    int repetitions = 1; // timed runs; timings are reported as median, min and max over them
};

// The generated lights of a scene whose file does not choose them, when --lights is not given.
inline constexpr int kDefaultLights = 256;

// Whether the scene is a JSON scene file, whose lightGenerator chooses its generated lights.
bool isJsonSceneFile(const std::string& scene);
// The generated lights to ask the scene for: options.lights when set; else none asked for a JSON
// scene (its file decides), kDefaultLights for the others.
std::optional<int> requestedLights(const RenderOptions& options);
// The light count as text for names and keys: the number, or "file" when a JSON scene's
// generator decides.
std::string lightsText(const RenderOptions& options);

// Sets one option from text, by the name the CLI and sweep files use: scene, stage, lights,
// seed, width, height, resolution (WxH), threads, isa, simt-warp, msaa, complex-detect,
// alpha-to-coverage, reference-spp, layout, normals, normal-space, depth, position, view, brdf,
// post-aa, oracle, shadows, shadow-map-size, shadow-bias, shadow-filter, shadow-point,
// shadow-depth-format, shadow-lights, shadow-cascades, shadow-caster-sets, max-memory (bytes,
// K/M/G/T suffixes) and scene-option.KEY. Values are checked later by validate(); a malformed
// number or an unknown key throws UsageError naming it. The sweep runner goes through this, so
// every stage, encoding or scene added later is reachable without touching the runner.
void setRenderOption(RenderOptions& options, const std::string& key, const std::string& value);
// The keys setRenderOption accepts (scene-option.KEY listed once as "scene-option.<key>").
std::vector<std::string> renderOptionKeys();

// Limits checked before any work or allocation (issue: 100000x100000 must be refused up front);
// the memory-sizing ones are defined, with their reasons, in scenes/input/Limits.h.
inline constexpr int kMaxImageSide = scenes::limits::kMaxImageSide;
inline constexpr uint64_t kMaxPixels = scenes::limits::kMaxPixels;
inline constexpr int kMaxLights = scenes::limits::kMaxLights;
inline constexpr int kMaxThreads = 1024;
inline constexpr int kMaxRepetitions = 1000;

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// What validating the options builds on its way: the stage (made from its spec, options parsed)
// and the G-buffer layout request (names parsed). planRender keeps them instead of building them
// again.
struct CheckedOptions {
    std::unique_ptr<lighting::ShadingStage> stage;
    gbuffer::LayoutRequest layoutRequest;
    lighting::kernel::KernelIsa isa = lighting::kernel::KernelIsa::scalar(); // options.isa resolved
    lighting::postaa::PostAa postAa = lighting::postaa::PostAa::None;        // options.postAa
    std::optional<lighting::ShadowSettings> shadows; // options.shadow*; empty: shadows off
};

// Checks every option in a fixed order (size, lights, threads, stage, scene, repetitions, G-buffer
// names, isa, simt warp, reference samples per pixel, brdf, post-aa) and throws UsageError
// (lighting::StageError for a bad stage spec, listing the valid names) for the first bad one.
// Cheap: loads nothing.
CheckedOptions checkOptions(const RenderOptions& options);
// The shadow settings the options ask for (empty: --shadows off); UsageError naming the first bad
// shadow option.
std::optional<lighting::ShadowSettings> shadowSettings(const RenderOptions& options);
// checkOptions for its verdict alone (the sweep checks every job this way before running any).
void validate(const RenderOptions& options);

// Runs `build`; a std::invalid_argument it throws (the gbuffer library's way of refusing a name
// or a layout) becomes a UsageError with the same message.
template <typename Build> auto usageErrorFrom(Build&& build) -> decltype(build()) {
    try {
        return build();
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
}

} // namespace experiments
