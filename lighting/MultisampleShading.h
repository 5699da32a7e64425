// MultisampleShading: how a stage shades a multisampled frame (PreparedScene with Multisampling)
// and how its samples are resolved, for every stage that shades from the G-buffer.
//
// The stage runs first on layer 0 (gbuffer/msaa/FragmentLayers.h), the full-screen G-buffer of
// every pixel's main fragment. The other fragments (the layers above, covered only at complex
// pixels) are then shaded one of two ways:
// - packed (msaa_shading=packed): a stage with a packed run (PackedFragmentShading,
//   passes/PackedFragments.h: tiled, tiled-backface, clustered with a fixed grid) shades all of
//   them in ONE run, gathered into full SIMD packets by screen block, with its lists made once for
//   them (Lauritzen 2010; the survey's per-tile MSAA choice: tiles without a complex pixel get no
//   work). Not for scenes with blended surfaces, nor for a stage that counts its own oracle.
// - per layer (msaa_shading=layers): the stage runs once on each layer above. Nothing in the
//   stage changes: a tiled or clustered stage finds no covered pixel in most tiles of an upper
//   layer and skips them, a light-volume stage tests its volumes against the layer's depth. It
//   costs what the layer's 4x4 packets hold (mostly empty), plus the stage's whole-screen work
//   per layer.
// Scenes with blended surfaces get one more run over an empty G-buffer: the blended surfaces over
// the background, for the background samples of partially covered pixels. In each run the blended
// pass composites per sample over the run's own samples and leaves their mean
// (passes/BlendedPass.h), so the resolve below gives the per-sample composite averaged over the
// pixel.
// Resolve ("resolve" pass): radiance = sum over layers of weight x the layer's radiance
// (FragmentLayers::weight: the fraction of the pixel's samples the fragment covers), plus the
// background run weighted by the background samples. lightsEvaluated adds every run's evaluations
// (all of them were done); a stage-filled lightsOracle adds the layers' at the pixels where the
// layer has a fragment. Passes of the same name are summed over the runs, in first-run order, and
// "resolve" is appended. Parameters are the first run's, plus msaa_* counters, except the
// kernel's work counters (simt_lane_slots and the packet counters, KernelWork::kCounterKeys),
// which are summed over every run like the evaluations: simt_efficiency divides the layers' oracle
// by the lane slots of every run.
//
// Which stages: every stage without a StageInfo::msaaRefusal (StageRegistry.h). A stage that
// multisamples natively (ShadingStage::multisamplesNatively: the forward stages, which rasterize
// the scene themselves at inputs.samples with per-sample colour, ForwardGeometry.h) is shaded
// ONCE on the full frame and resolves itself: no layers, no background run, parameters "msaa"
// and msaa_shading=native (the layered path records msaa_shading=layers). The stages with a
// material pass (light pre-pass, inferred) take the layers too: their material pass rasterizes
// the scene at the sample count once per frame, on layer 0, and gives each layer's fragments
// (StageInputs::fragmentLayer, MaterialPass.h). The reference refuses (it is supersampled).
//
// Exactness: a layer's image is the stage's own on that layer's G-buffer, so the exactness of each
// stage per layer (tested against brute per layer) carries over, and the resolve is the same
// weighted sum for every stage: bitwise brute's resolve for a stage that is bitwise brute per
// layer. A packed fragment's radiance is bitwise its layer run's (tested against brute on the
// fragment's layer, with every contributing light evaluated), and the resolve adds a pixel's
// fragments in the same layer order. Deterministic: per-pixel sums in layer order.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "lighting/PreparedScene.h"
#include "lighting/ShadingStage.h"
#include "lighting/passes/PackedFragments.h"

namespace lighting {

// Shades `prepared` (multisampled or not: without layers this is stage.shade) into `result`.
// Keeps the upper layers' results and the background run's empty G-buffer between calls (one
// object per run and stage, like the stage's own scratch), so that timed repetitions do not pay
// for fresh allocations. Not reentrant.
class MultisampleShading {
public:
    void shade(ShadingStage& stage, const PreparedScene& prepared, StageResult& result);

    // The last shade()'s runs, wall milliseconds each: layer 0 (the whole frame when not
    // multisampled or shaded natively), then the packed run or each layer above, then the
    // background run when there was one. Where a multisampled frame's shading goes (the
    // benchmarks report it; not in StageResult, whose figures are the frame's).
    const std::vector<double>& runMs() const { return mRunMs; }

private:
    std::vector<double> mRunMs;
    PackedFragments mFragments; // the other fragments, for a stage with a packed run
    StageResult mPacked;        // its result, per fragment
    std::vector<StageResult> mUpper;
    StageResult mBackground;
    std::unique_ptr<gbuffer::GBuffer> mEmpty;
};

// The contributing lights per pixel summed over the layers' fragments (layer 0 alone when not
// multisampled): the oracle that matches shadeMultisampled's lightsEvaluated.
std::vector<uint32_t> countContributingLightsOverLayers(const PreparedScene& prepared);

} // namespace lighting
