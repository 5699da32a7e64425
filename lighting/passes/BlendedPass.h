// BlendedPass: the forward pass for blended surfaces (glTF alphaMode BLEND), written once and run
// by every stage after its opaque pass (lighting/README.md, "Transparency"). The opaque passes
// never see blended surfaces (gbuffer::AlphaCoverage discards them from every opaque draw); this
// pass then rasterizes the blended triangles over the frame's opaque depth (closer test, no
// depth writes), shades each fragment with the lights the stage gives for it, and composites it
// over the pixel with the "over" operator: radiance = alpha * lit + (1 - alpha) * radiance.
//
// Order. Stages composite in the order the literature's forward passes use: blended triangles
// sorted back to front once per frame by the view depth of their centroid (per-triangle sort,
// farthest first; ties by triangle index), then drawn in that order, so every pixel composites
// its fragments in that order (the rasterizer keeps submission order per pixel). Where
// triangles intersect or overlap out of centroid order, the order is wrong at some pixels: those
// are the sorting artefacts every stage's error against the reference shows. The reference
// (compositeExact) instead sorts every pixel's fragments by their exact distance.
//
// Light lists. shade() takes lightsAt(x, y, surface, triangle), which returns the stage's
// light list for that fragment (ascending indices; a std::span<const uint32_t> into storage that
// stays put until shade() returns, whose address identifies the list): every light
// (everyLight()), the tile's or cluster's list, the object's list. `ideal`'s per-fragment lists
// go through shadeWithContributingLights(). A fragment's radiance sums its list in that order on
// the shared light kernel, so stages whose lists keep every contributing light give bitwise
// brute's composite on the same ISA.
//
// Shading. Fragments are queued and shaded on the light kernel in packets of 16 consecutive
// fragments of a raster tile (FragmentShading.h, FragmentApply::Over), on inputs.isa, and
// composited lane by lane in fragment order; the pass's SIMT lane slots and kernel counters are
// added to the opaque pass's (KernelWork.h), so a stage's figures cover its whole frame.
//
// Counting. shade() adds each fragment's list length to lightsEvaluated, and, when
// lightsOracle is non-empty (stages that count the oracle themselves, brute), its contributing
// lights (the kernel's count) to lightsOracle; addOracle() adds the latter for the oracle the
// runner counts (lighting/Oracle.h); compositeExact() counts both for the reference. The pass is
// timed as pass::kBlend. With the tests' light trace on (StageResult::traceLights), each composited
// fragment's list goes into StageResult::blendedTrace (the reference: every light), so the
// identity check covers blended fragments too (tests/lighting/LightIdentity.h).
//
// Emission. A blended fragment's emitted radiance (Surface::emissive) is added to its light sum,
// once, before compositing: radiance = alpha * (lit + emitted) + (1 - alpha) * radiance. glTF
// 2.0 (material.alphaMode, BLEND): "The rendered output is combined with the background using
// the normal painting operation (i.e. the Porter and Duff over operator)", and the rendered
// output of a surface is its lit colour plus its emission (Appendix B adds the emissive term to
// the BRDF's result), so the emission is weighted by alpha like the lit colour; a pane of
// alpha 0 neither reflects nor emits. KHR_materials_emissive_strength only scales the factor.
// Multisampling: blended triangles are rasterized at the frame's sample count, each sample
// covered and depth-tested (closer, no writes) against the rasterizer's depth of that sample's
// opaque surface, as a GPU blends into a multisampled target. A fragment is shaded once, at the
// pixel centre like every attribute (raster/Rasterizer.h; a centre depth extrapolated to or past
// the far plane is moved one float step nearer, as gbuffer::FragmentLayers does for opaque
// fragments), and composited over each sample of its coverage. So a pane's own edges and the
// opaque edges behind it are both anti-aliased, not only the latter.
//  - Forward stages (prepare() with their SampleRadiance; they pass their per-sample depth
//    plane): the composite goes into their sample colour buffer, which they resolve.
//  - G-buffer stages (inputs.fragmentLayers, MultisampleShading.h: one run per fragment layer and
//    one over the background samples): a run owns the samples of its layer's fragment at each
//    pixel (layer 0 of an uncovered pixel: all of them; the background run: the background
//    samples of partially covered pixels), tests them against inputs.sampleDepths, and keeps
//    only coverage within them. A pixel's samples start at the run's opaque radiance the first
//    time a fragment reaches it (SampleRadiance, filled on demand), take the composite, and the
//    run's radiance there becomes the mean of its own samples. The layers' resolve weights that
//    mean by the run's share of samples, so the frame is the per-sample composite averaged over
//    every sample: what the forward stages give, up to float rounding of the means.
//  - Tile lists (shadeWithTileLists): they are bounded, per pixel, by the farthest of the tested
//    sample depths and of the depths at which the pixel's fragments are shaded (a fragment may
//    pass at a sample while its centre lies behind it), so they stay conservative.
// Thread safety: one frame at a time per object; parallel inside (the rasterizer's
// tiles), each pixel composited by the thread owning its tile, in submission order, so the
// result does not depend on the thread count.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "gbuffer/codecs/DepthFormat.h"
#include "gbuffer/visibility/VisibilityPass.h"
#include "lighting/ShadingStage.h"
#include "lighting/brdf/Brdf.h"
#include "lighting/passes/FragmentShading.h"
#include "lighting/passes/PassNames.h"
#include "lighting/passes/SampleRadiance.h"
#include "raster/Rasterizer.h"

namespace lighting {

class BlendedPass {
public:
    // Per frame: false (and nothing else done, O(materials)) when no material of inputs.scene is
    // BLEND; else transforms the scene (its own gbuffer::VisibilityPass, so the clip positions
    // are bitwise the opaque pass's) and sorts the blended triangles. Requires inputs.scene,
    // .geometry, .view, .lights. With `samples` (a forward stage's colour buffer), the frame is
    // multisampled at samples->samples() and shade() composites per sample into it; it must
    // outlive the frame's shade. Without, a frame with inputs.fragmentLayers and inputs.samples > 1
    // is a layered multisampled run (see the file comment), which needs inputs.sampleDepths.
    bool prepare(const StageInputs& inputs, SampleRadiance* samples = nullptr);
    // Another run of the frame prepare() was called for (a fragment layer of the same
    // multisampled frame, MultisampleShading.h): keeps the transform and the order, and takes
    // this run's inputs (its layer, hence its samples), which must outlive the run's shade.
    void switchRun(const StageInputs& inputs) { mInputs = &inputs; }
    bool active() const { return mActive; }
    // Number of blended triangles this frame.
    size_t triangleCount() const { return mSceneTriangle.size(); }
    // 0 .. lightCount - 1: the list of stages that shade blended surfaces with every light.
    std::span<const uint32_t> everyLight() const { return mEveryLight; }

    // Composites the blended fragments in front of opaqueDepth (the frame's opaque depth plane,
    // the view's convention: one sample per pixel, or a forward stage's samples; a layered
    // multisampled run tests inputs.sampleDepths instead) over result.radiance, in the pass's
    // order, with the lists of lightsAt (see the file comment). Appends pass::kBlend.
    template <class LightsAt>
    void shade(std::span<const float> opaqueDepth, LightsAt&& lightsAt, StageResult& result) {
        PassTimer blendPass(result, pass::kBlend);
        shade(opaqueDepth, lightsAt, result, blendPass);
    }
    // The same, timed by the caller's `blendPass` (started before list building that belongs to
    // the pass), which this stops.
    template <class LightsAt>
    void shade(std::span<const float> opaqueDepth, LightsAt&& lightsAt, StageResult& result,
               PassTimer& blendPass);

    // shade() with every light for every fragment: brute, and the stages that state they use
    // brute force for blended surfaces (lighting/README.md).
    void shadeWithEveryLight(std::span<const float> opaqueDepth, StageResult& result) {
        shade(
            opaqueDepth,
            [this](int, int, const gbuffer::Surface&, uint32_t) { return everyLight(); }, result);
    }
    // The lights that contribute at a blended fragment's surface (every light tested,
    // ascending; valid until the calling thread's next call): the lists of `ideal`.
    std::span<const uint32_t> contributingLights(const gbuffer::Surface& point) const;
    // shade() with each fragment's contributingLights(): `ideal`, whose blended lists are built
    // inside the blend pass's time (its untimed lists are the opaque surfaces').
    void shadeWithContributingLights(std::span<const float> opaqueDepth, StageResult& result);
    // shade() with the tile lists of BlendedTileLists.h on tiles of tileSizePixels (the tiled
    // stages; the list building is timed in the blend pass).
    void shadeWithTileLists(std::span<const float> opaqueDepth, int tileSizePixels,
                            bool viewFrustumCulling, StageResult& result);

    // The reference's composite: per pixel every blended fragment in front of opaqueDepth,
    // sorted by its exact distance (ties by triangle index), each lit with every light in double
    // at its exact hit (gbuffer::ExactSurface::hit; material values and alpha as the stages
    // read them), composited back to front over the pixel's opaque radiance in double, then
    // rounded to float once. Appends pass::kBlend.
    void compositeExact(std::span<const float> opaqueDepth, StageResult& result);

    // Calls fn(fragment, triangle, surface, alpha) for every blended fragment in front of
    // opaqueDepth, in the pass's order per pixel (the composite order of shade()), with its scene
    // triangle and its surface (position from its depth) and alpha; concurrently for pixels of
    // different raster tiles, so fn writes only data of the fragment's pixel. For stages that
    // light blended surfaces their own way (inferred's stipple layers), which composite with
    // compositeOver() between beginComposite() and endComposite().
    template <class Fn> void forEachFragment(std::span<const float> opaqueDepth, Fn&& fn) {
        draw(opaqueDepth, [&](const raster::Fragment& fragment) {
            const uint32_t triangle = mSceneTriangle[fragment.triangle];
            float alpha = 0.0f;
            const gbuffer::Surface point = surfaceOf(fragment, triangle, alpha);
            fn(fragment, triangle, point, alpha);
        });
    }

    // Adds the blended fragments' contributing lights (every light tested) to `oracle`.
    void addOracle(std::span<const float> opaqueDepth, std::vector<uint32_t>& oracle);

    // A composite of the caller's own (forEachFragment): beginComposite() before the first
    // compositeOver(), endComposite() after the last. compositeOver() composites `lit` (light
    // plus emission) with `alpha` over the fragment's pixel, or multisampled over each sample of
    // its coverage; from the thread that was given the fragment.
    void beginComposite(StageResult& result);
    void compositeOver(const raster::Fragment& fragment, const glm::vec3& lit, float alpha,
                       StageResult& result);
    void endComposite(StageResult& result);

private:
    // The blended surface of a fragment: the visibility pass's surface at the pixel, its
    // position from the fragment's depth (the lossless decoder, as ForwardGeometry), its alpha.
    gbuffer::Surface surfaceOf(const raster::Fragment& fragment, uint32_t triangle,
                               float& alpha) const;
    // Draws the sorted blended triangles over the tested depth (testedDepth(opaqueDepth)),
    // without writing it, at mSamples samples per pixel; multisampled, a fragment's coverage is
    // the samples it covers and is closer than, within the run's samples (layered runs), and its
    // centre depth is kept nearer than the far plane (see the file comment).
    template <class FragmentFn>
    void draw(std::span<const float> opaqueDepth, FragmentFn&& fragmentFn);
    // The depth plane the draw tests: inputs.sampleDepths in a layered multisampled run, else
    // opaqueDepth; throws std::invalid_argument unless it holds mSamples floats per pixel.
    std::span<const float> testedDepth(std::span<const float> opaqueDepth) const;
    // Layered multisampled runs: the samples of `pixel` this run composites over (file comment).
    uint8_t runSamples(size_t pixel) const;
    // Per pixel, a depth no shaded fragment lies behind (file comment, "Tile lists").
    std::span<const float> listBounds(std::span<const float> opaqueDepth);

    bool mActive = false;
    const StageInputs* mInputs = nullptr;
    gbuffer::VisibilityPass mVisibility;
    std::optional<gbuffer::DepthDecoder> mDepthDecoder;
    std::unique_ptr<raster::Rasterizer> mRasterizer;
    int mSamples = 1;                     // the draw's samples per pixel
    bool mLayered = false;                // a layered multisampled run (file comment)
    SampleRadiance mLayerSamples;         // layered runs: the run's samples, filled on demand
    SampleRadiance* mComposite = nullptr; // the composite's sample buffer (null: pixels)
    std::vector<float> mBounds;           // listBounds()
    std::vector<uint32_t> mSortedIndices; // vertex indices of the sorted triangles
    std::vector<uint32_t> mSceneTriangle; // drawn triangle -> scene triangle
    std::vector<uint32_t> mEveryLight;
    FragmentShading mShading;          // the blended fragments on the light kernel
    SampleRadiance* mTarget = nullptr; // multisampled frames: the per-sample colour
};

template <class FragmentFn>
void BlendedPass::draw(std::span<const float> opaqueDepth, FragmentFn&& fragmentFn) {
    raster::RasterState state = mVisibility.drawState();
    state.depthWrite = false;
    state.samples = mSamples;
    const raster::TriangleList triangles{mVisibility.clipPositions(), mSortedIndices};
    // With depthWrite off the rasterizer only reads the plane.
    float* depth = const_cast<float*>(testedDepth(opaqueDepth).data());
    if (mSamples == 1) {
        mRasterizer->draw(triangles, state, depth, fragmentFn);
        return;
    }
    const size_t width = size_t(mVisibility.view().width);
    const bool reversed = mVisibility.view().reversedZ();
    const float clear = mVisibility.view().clearDepth();
    const float nearestToClear = std::nextafter(clear, reversed ? 1.0f : 0.0f);
    auto covered = [&](const raster::Fragment& fragment) {
        raster::Fragment kept = fragment;
        if (mLayered) {
            kept.coverage &= runSamples(size_t(fragment.y) * width + size_t(fragment.x));
            if (kept.coverage == 0)
                return;
        }
        if (!(reversed ? kept.depth > clear : kept.depth < clear))
            kept.depth = nearestToClear;
        fragmentFn(kept);
    };
    mRasterizer->draw(triangles, state, depth, covered);
}

template <class LightsAt>
void BlendedPass::shade(std::span<const float> opaqueDepth, LightsAt&& lightsAt,
                        StageResult& result, PassTimer& blendPass) {
    beginComposite(result);
    mShading.begin(*mInputs, FragmentApply::Over, result, mComposite);
    draw(opaqueDepth, [&](const raster::Fragment& fragment) {
        const uint32_t triangle = mSceneTriangle[fragment.triangle];
        float alpha = 0.0f;
        const gbuffer::Surface point = surfaceOf(fragment, triangle, alpha);
        const std::span<const uint32_t> list = lightsAt(fragment.x, fragment.y, point, triangle);
        mShading.add(fragment, triangle, point, uint64_t(reinterpret_cast<uintptr_t>(list.data())),
                     list, alpha);
    });
    mShading.flush();
    mShading.end();
    endComposite(result);
    blendPass.stop();
}

} // namespace lighting
