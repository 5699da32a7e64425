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
// Multisampling (the forward stages' hardware-style MSAA: prepare() with a SampleRadiance): the
// opaque depth plane then holds samples per pixel (the SHADING depth of each sample's opaque
// fragment, ForwardGeometry::shadedDepth), blended triangles are rasterized at one sample per
// pixel, and a fragment composites over each sample whose opaque depth its centre depth is
// closer than (the draw's depth test, per sample), in the sample colour buffer. That is exactly
// what the G-buffer stages do per fragment layer (this pass at one sample over the layer's
// centre depths, MultisampleShading.h), so every exact stage keeps one image; coverage of a
// blended triangle's own edges at the samples (what a GPU does) would differ from it there.
// Thread safety: one frame at a time per object; parallel inside (the rasterizer's
// tiles), each pixel composited by the thread owning its tile, in submission order, so the
// result does not depend on the thread count.
#pragma once

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
    // .geometry, .view, .lights. With `samples`, the frame is multisampled and shade()
    // composites per sample into it (see the file comment); it must outlive the frame's shade.
    bool prepare(const StageInputs& inputs, SampleRadiance* samples = nullptr);
    bool active() const { return mActive; }
    // Number of blended triangles this frame.
    size_t triangleCount() const { return mSceneTriangle.size(); }
    // 0 .. lightCount - 1: the list of stages that shade blended surfaces with every light.
    std::span<const uint32_t> everyLight() const { return mEveryLight; }

    // Composites the blended fragments in front of opaqueDepth (the frame's opaque depth plane,
    // the view's convention) over result.radiance, in the pass's order, with the lists of
    // lightsAt (see the file comment). Appends pass::kBlend to result.timingsMs.
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
    // light blended surfaces their own way (inferred's stipple layers).
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

private:
    // The blended surface of a fragment: the visibility pass's surface at the pixel, its
    // position from the fragment's depth (the lossless decoder, as ForwardGeometry), its alpha.
    gbuffer::Surface surfaceOf(const raster::Fragment& fragment, uint32_t triangle,
                               float& alpha) const;
    // Draws the sorted blended triangles over a copy of opaqueDepth. Multisampled (opaqueDepth
    // with several samples per pixel), over each pixel's farthest sample, and each fragment's
    // coverage is set to the samples it is closer than; fragments closer than none are dropped.
    template <class FragmentFn>
    void draw(std::span<const float> opaqueDepth, FragmentFn&& fragmentFn);

    bool mActive = false;
    const StageInputs* mInputs = nullptr;
    gbuffer::VisibilityPass mVisibility;
    std::optional<gbuffer::DepthDecoder> mDepthDecoder;
    std::unique_ptr<raster::Rasterizer> mRasterizer;
    std::vector<float> mDepth;            // the opaque depth, tested, never written
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
    const raster::TriangleList triangles{mVisibility.clipPositions(), mSortedIndices};
    const size_t width = size_t(mVisibility.view().width);
    const size_t pixelCount = width * size_t(mVisibility.view().height);
    const size_t samples = opaqueDepth.size() / pixelCount;
    if (samples <= 1) {
        mDepth.assign(opaqueDepth.begin(), opaqueDepth.end());
        mRasterizer->draw(triangles, state, mDepth.data(), fragmentFn);
        return;
    }
    // The farthest sample of each pixel: a fragment closer than some sample is closer than it.
    mDepth.resize(pixelCount);
    const bool reversed = mVisibility.view().reversedZ();
    for (size_t pixel = 0; pixel < pixelCount; ++pixel) {
        const float* sample = opaqueDepth.data() + pixel * samples;
        float farthest = sample[0];
        for (size_t s = 1; s < samples; ++s)
            farthest = reversed ? std::min(farthest, sample[s]) : std::max(farthest, sample[s]);
        mDepth[pixel] = farthest;
    }
    auto perSample = [&](const raster::Fragment& fragment) {
        const float* sample =
            opaqueDepth.data() + (size_t(fragment.y) * width + size_t(fragment.x)) * samples;
        unsigned coverage = 0;
        for (size_t s = 0; s < samples; ++s)
            if (reversed ? fragment.depth > sample[s] : fragment.depth < sample[s])
                coverage |= 1u << s;
        if (coverage == 0)
            return;
        raster::Fragment covered = fragment;
        covered.coverage = uint8_t(coverage);
        fragmentFn(covered);
    };
    mRasterizer->draw(triangles, state, mDepth.data(), perSample);
}

template <class LightsAt>
void BlendedPass::shade(std::span<const float> opaqueDepth, LightsAt&& lightsAt,
                        StageResult& result, PassTimer& blendPass) {
    mShading.begin(*mInputs, FragmentApply::Over, result, mTarget);
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
    blendPass.stop();
}

} // namespace lighting
