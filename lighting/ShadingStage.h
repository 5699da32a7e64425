// ShadingStage: the interface every lighting pipeline implements (one stage per file under
// lighting/stages/, each registering itself by name: StageRegistry.h), and what it reads and
// writes.
//
// Declare, then run. The runner (experiments/RenderJob, the tests and the benchmarks through
// PreparedScene) first asks requirements(), derives the G-buffer layout from it and the scene
// (gbuffer/LayoutDerivation.h), renders the G-buffer, then calls shade() once per frame (several
// times for timing repetitions, on the same inputs).
//
// The contract of each method:
//
// name()          The registry name (`brute`, `tiled-backface`...). Pure.
//
// requirements()  What shade() reads: the G-buffer channels (the layout provides at least these,
//                 or layout derivation fails naming the stage and the channel) and whether it
//                 needs the exact surface. Cheap, pure, the same for the life of the object;
//                 called any number of times, before and between shade() calls; thread-safe.
//
// shade(inputs, result)
//   May assume:
//   - inputs.scene, .geometry, .view, .gbuffer and .lights are set; .exact is set when
//     requirements().exactSurface (it may be set otherwise: ignore it). .view is the G-buffer's
//     view (*inputs.view == inputs.gbuffer->view()); width and height are the view's.
//   - The G-buffer may be lossy and in any layout that provides the declared channels: read it
//     only through GBuffer::decode / surfaceAt / covered / depth() and its depthDecoder() (never
//     the planes, never a format); channels not declared may be absent (decoded as defaults).
//   - The lights are LightList's (view space; float for stages, double in lightsExact).
//   - The call runs inside the caller's tbb::task_arena: parallelise with TBB (it sets the
//     thread count), start no threads of your own.
//   - The inputs live for the duration of the call only: keep no pointer into them afterwards.
//     Scratch storage may be kept in the stage object between calls (it is reused across
//     repetitions), and successive calls may bring other scenes, sizes and layouts.
//   Must fill:
//   - result.resize(width, height, withOracle) first (it clears every plane, the timings and
//     the parameters; a result object is reused across calls).
//   - radiance: linear HDR R, G, B of every covered pixel; background pixels (not covered in the
//     G-buffer, or with no visible fragment for stages that rasterize the scene) stay zero.
//   - lightsEvaluated: per pixel, the light evaluations the stage actually did there (a forward
//     stage's overdrawn fragments included; zero on background). An exact stage evaluates at
//     least the contributing lights at every pixel (StageKind::Exact, StageRegistry.h).
//   - lightsOracle: either left empty (resize(..., false): the runner counts the contributing
//     lights itself, lighting/Oracle.h) or, when the stage evaluates every light anyway, the
//     number of lights with non-zero radiance at every pixel.
//   - lightingSamples: left empty, except by a stage that evaluates lights at some pixels only
//     and fills the others from them (inferred): 1 at the pixels it lit, 0 elsewhere.
//   - timingsMs: one entry per pass the stage runs, in execution order, with short lowercase
//     names ("cull", "shading"...), measured with PassTimer; not the G-buffer pass (the
//     runner adds "gbuffer" and "total").
//   - parameters: the effective value of every option that applies (defaults included) under its
//     option key, and the stage's counters (e.g. tile_light_pairs), as strings.
//   Thread safety and determinism: not reentrant per object (one shade() at a time; separate
//   objects are independent). The same inputs give bitwise the same result for any thread count
//   and on every repetition: no atomics or scheduling-dependent sums in per-pixel work, light
//   sums in ascending light order.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferLayout.h"
#include "gbuffer/msaa/FragmentLayers.h"
#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/ExactSurface.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/culling/LightList.h"
#include "lighting/kernel/KernelIsa.h"
#include "lighting/shadows/ShadowLookup.h"
#include "scenes/Scene.h"

namespace lighting {

struct StageRequirements {
    std::vector<gbuffer::Channel> channels; // G-buffer channels the stage reads
    bool exactSurface = false;              // reads gbuffer::ExactSurface (the reference)

    // Every channel the BRDF reads (depth, normal, albedo, specular) and the emission added once
    // per pixel: what a stage that shades from the G-buffer declares.
    static StageRequirements wholeSurface() {
        return {{gbuffer::Channel::Depth, gbuffer::Channel::Normal, gbuffer::Channel::Albedo,
                 gbuffer::Channel::Specular, gbuffer::Channel::Emission},
                false};
    }
};

// The inputs of a stage for one frame: everything it may read (see shade() above for which
// pointers are set).
struct StageInputs {
    const scenes::Scene* scene = nullptr;
    const gbuffer::SceneGeometry* geometry = nullptr;
    const gbuffer::CameraView* view = nullptr;
    const gbuffer::GBuffer* gbuffer = nullptr;
    const gbuffer::ExactSurface* exact = nullptr;
    const LightList* lights = nullptr;
    // How the G-buffer stages' shading loop evaluates lights (LightAccumulation.h): the kernel's
    // instruction set (`--isa`; scalar = evaluateLight per pixel) and the SIMT cost model's warp
    // size in lanes (32 = 8x4 pixels, 64 = 8x8).
    kernel::KernelIsa isa = kernel::KernelIsa::best();
    int simtWarpLanes = 32;
    // The frame's samples per pixel (1, or 2, 4, 8 with --msaa: PreparedScene sets it from its
    // Multisampling). A stage that multisamples natively (multisamplesNatively()) rasterizes at
    // this count and resolves itself; the G-buffer stages ignore it (their G-buffer is one
    // fragment layer, MultisampleShading.h).
    int samples = 1;
    // Multisampled frames only (null and 0 otherwise): the frame's fragment layers
    // (gbuffer/msaa/FragmentLayers.h) and which of them this call shades: 0, the main fragments
    // (always shaded first in a frame), k >= 1, the k-th other fragments of the complex pixels,
    // or kBackgroundRun, the run over an empty G-buffer that shades the blended surfaces over the
    // background samples (MultisampleShading.h). A stage that shades from the G-buffer alone
    // ignores both. A stage with a second geometry pass (MaterialPass) pairs its own fragments
    // with the layer's through them, and may reuse what it computed on layer 0 for the layers
    // above in the same frame (inferred's L-buffer).
    const gbuffer::FragmentLayers* fragmentLayers = nullptr;
    int fragmentLayer = 0;
    static constexpr int kBackgroundRun = -1;
    // With fragmentLayers: the G-buffer pass's per-sample depth buffer (samples floats per pixel,
    // pixel-major, the rasterizer's depth of each sample's visible triangle), against which the
    // blended pass depth-tests each sample of a blended triangle (BlendedPass.h).
    const std::vector<float>* sampleDepths = nullptr;
    // Alpha-to-coverage (`--alpha-to-coverage on`, gbuffer/visibility/AlphaCoverage.h): at
    // samples > 1 alpha-masked fragments keep round(alpha * samples) of their samples instead of
    // being alpha-tested. The G-buffer pass drew the frame this way (Multisampling); a stage that
    // rasterizes the scene itself (the forward stages, the material passes) draws it the same way,
    // so that it keeps the same fragments. Shadow maps ignore it (every caster is opaque).
    bool alphaToCoverage = false;
    // The frame's shadows (lighting/shadows/ShadowLookup.h; `--shadows`), or null: no light casts
    // one. Every stage that shades through the kernel applies them there (KernelLights).
    const shadows::ShadowLookup* shadows = nullptr;
    // The reference's shadows for the same lights (ray-traced), or null.
    const shadows::ExactShadowLookup* exactShadows = nullptr;
};

// What shade() fills (see the file comment for each field's contract).
struct StageResult {
    int width = 0;
    int height = 0;
    std::vector<float> radiance[3];        // linear HDR R, G, B
    std::vector<uint32_t> lightsEvaluated; // per pixel: lights the stage evaluated
    std::vector<uint32_t> lightsOracle;    // per pixel: lights that contribute; empty when the
                                           // stage cannot know (the runner then computes it)
    // Stages that light at reduced resolution (inferred): 1 at the full-res pixels whose lights
    // the stage evaluated (its L-buffer samples), 0 at the pixels it only filtered; empty for
    // every other stage (all pixels). The runner counts evaluated and oracle lights over these
    // pixels only, so that culling efficiency compares the same samples.
    std::vector<uint8_t> lightingSamples;
    std::vector<std::pair<std::string, double>> timingsMs; // per pass, in execution order
    std::map<std::string, std::string> parameters;         // the stage's effective options

    // Test hook, off by default: which lights were evaluated at each pixel, for the identity
    // check of the tests (every contributing light is among them, not just as many). A caller
    // sets traceLights before shade(); resize() then gives lightTrace one empty list per pixel
    // and the shared loops fill it (shadeWithEveryLight, accumulateLights, FragmentShading and the
    // light-volume loops): the lights whose sum the pixel holds, in the order they were added (a
    // forward stage's overdrawn fragments are replaced, as their radiance is). Approximate stages
    // do not trace. Off, it costs one predictable branch per pixel list (per light and pixel in
    // the additive loops) and no memory. Each pixel's list is written by the task that owns the
    // pixel, like its radiance.
    bool traceLights = false;
    std::vector<std::vector<uint32_t>> lightTrace;
    // The same hook for blended fragments (lighting/passes/BlendedPass.h): per pixel, one entry per
    // blended fragment the pass composited there, in composite order, with the lights evaluated
    // for it (the list's order). Filled by BlendedPass::shade and compositeExact when tracing;
    // the tests check each entry against the fragment's contributing lights. Off, it costs one
    // predictable branch per blended fragment and no memory.
    struct BlendedFragmentTrace {
        uint32_t triangle = 0; // scene triangle
        bool frontFacing = true;
        std::vector<uint32_t> lights;
    };
    std::vector<std::vector<BlendedFragmentTrace>> blendedTrace;

    // Sizes every plane to w x h, zero-filled (lightsOracle empty unless withOracle), and clears
    // lightingSamples, timingsMs and parameters; lightTrace and blendedTrace get w x h empty
    // lists when traceLights, else none.
    void resize(int w, int h, bool withOracle);

    bool tracing() const { return !lightTrace.empty(); }
    // The pixel's lights are exactly `lightIndices` (a loop that overwrites the pixel).
    void traceLightList(size_t pixel, std::span<const uint32_t> lightIndices) {
        if (tracing())
            lightTrace[pixel].assign(lightIndices.begin(), lightIndices.end());
    }
    // The pixel's lights are 0 .. lightCount - 1 (every light, in order).
    void traceEveryLight(size_t pixel, size_t lightCount) {
        if (tracing()) {
            lightTrace[pixel].resize(lightCount);
            for (size_t i = 0; i < lightCount; ++i)
                lightTrace[pixel][i] = uint32_t(i);
        }
    }
    // A blended fragment of `triangle` was composited at the pixel, lit by `lightIndices`.
    void traceBlendedFragment(size_t pixel, uint32_t triangle, bool frontFacing,
                              std::span<const uint32_t> lightIndices) {
        if (tracing())
            blendedTrace[pixel].push_back(
                {triangle, frontFacing, {lightIndices.begin(), lightIndices.end()}});
    }
    // `light` was added to the pixel (a loop that accumulates light by light).
    void traceAddedLight(size_t pixel, uint32_t light) {
        if (tracing())
            lightTrace[pixel].push_back(light);
    }
};

// The one clock of the stages: a steady-clock stopwatch that runs in spans, from construction (or
// resume()) to pause(); milliseconds() is the sum of the spans so far, the running one included.
// What PassTimer measures with, and what a stage uses alone for a figure that is no pass (ideal's
// untimed list build).
class Stopwatch {
public:
    Stopwatch() : mStart(std::chrono::steady_clock::now()) {}
    void pause() {
        if (mRunning) {
            mMilliseconds += span();
            mRunning = false;
        }
    }
    void resume() {
        if (!mRunning) {
            mStart = std::chrono::steady_clock::now();
            mRunning = true;
        }
    }
    double milliseconds() const { return mMilliseconds + (mRunning ? span() : 0.0); }

private:
    double span() const {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - mStart)
            .count();
    }

    std::chrono::steady_clock::time_point mStart;
    double mMilliseconds = 0.0;
    bool mRunning = true;
};

// How stages time their passes: a pass runs from the timer's construction to stop() (or the end
// of its scope), and is then appended to result.timingsMs under `pass` (a PassNames.h constant),
// so passes are recorded in execution order. A pass done in several spans (inferred's blend:
// stipple, light, composite, with other passes between) pause()s and resume()s its timer and is
// recorded once, at stop(), as the sum. discard() ends the timer without recording (a pass that
// turned out not to run). stop() returns the milliseconds; calls after the first return the same
// value and record nothing. Not copyable; one timer per pass.
class PassTimer {
public:
    PassTimer(StageResult& result, const char* pass) : mResult(result), mPass(pass) {}
    ~PassTimer() { stop(); }
    PassTimer(const PassTimer&) = delete;
    PassTimer& operator=(const PassTimer&) = delete;

    void pause() { mClock.pause(); }
    void resume() { mClock.resume(); }
    double stop() {
        if (!mStopped) {
            mStopped = true;
            mMilliseconds = mClock.milliseconds();
            mResult.timingsMs.emplace_back(mPass, mMilliseconds);
        }
        return mMilliseconds;
    }
    void discard() { mStopped = true; }

private:
    StageResult& mResult;
    const char* mPass;
    Stopwatch mClock;
    bool mStopped = false;
    double mMilliseconds = 0.0;
};

class ShadingStage {
public:
    virtual ~ShadingStage() = default;
    // Each method's contract is in the file comment above.
    virtual std::string name() const = 0;
    virtual StageRequirements requirements() const = 0;
    virtual void shade(const StageInputs& inputs, StageResult& result) = 0;
    // True for a stage that rasterizes the scene itself at inputs.samples samples per pixel and
    // resolves its own per-sample colour (the forward stages: hardware-style MSAA): a
    // multisampled frame is then shaded by ONE shade() call on the full frame
    // (MultisampleShading.h), not once per fragment layer. Pure, cheap; matches the stage's
    // StageInfo::msaaNative.
    virtual bool multisamplesNatively() const { return false; }
};

} // namespace lighting
