// ForwardGeometry: the per-frame geometry of the forward stages (`forward`, `forward-multipass`,
// `tiled-forward`), which shade while rasterizing instead of reading a G-buffer.
//
// Per frame, prepare() runs the G-buffer pass's own transform (gbuffer::VisibilityPass: vertices
// to clip space, normals to view space), splits the triangle list into objects (runs of
// consecutive triangles of one scenes::Instance) and bounds each object with a view-space AABB.
// A fragment's surface is the visibility pass's surface of its triangle at its pixel, and its
// position comes from the fragment's depth through the lossless layout's gbuffer::DepthDecoder
// (a forward stage's depth is the rasterizer's float depth, kept as is). So the visible
// fragment's Surface is bitwise the one `brute` decodes from a G-buffer of the lossless layout
// (the same triangles through the same rasterizer give the same depth), and evaluating lights in
// ascending index order gives bitwise brute's radiance there.
//
// Conventions: view space right-handed, camera down -Z; depth in the CameraView's convention
// (reversed by default). Culling is conservative: lights are tested with the widened spheres of
// LightBounds.h against object boxes widened by the receiver slack of culling/CullingTests.h
// (positions reconstructed from float depth stray from the float-transformed vertices by a few
// ulps of the distance to the camera), so rounding only ever adds work.
//
// Multisampling (inputs.samples > 1: hardware-style MSAA, the forward stages' own): every draw
// runs at inputs.samples samples per pixel over a per-sample depth plane (the pre-pass is the
// multisampled visibility draw), each fragment is shaded ONCE at the pixel centre (the
// rasterizer's contract: Fragment::depth is the centre depth) and written to the samples it
// shows (VisibilityPass::visibleCoverage after a pre-pass, its whole coverage without one) of
// the per-sample colour buffer sampleTarget(); endFrame() resolves it. A sample's surface is then
// bitwise the one `brute` shades in the G-buffer layer that holds the sample's fragment
// (gbuffer/msaa/FragmentLayers.h: same code, same centre depth), so per sample the forward image
// is brute's layer image and the resolve differs from brute's layered resolve only by the
// summation order (mean of samples vs coverage-weighted layers).
//
// Thread safety: prepare() is parallel inside and not reentrant per object; the const queries
// are thread-safe.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/Surface.h"
#include "gbuffer/codecs/DepthFormat.h"
#include "gbuffer/visibility/VisibilityPass.h"
#include "lighting/ShadingStage.h"
#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightIndexLists.h"
#include "lighting/passes/PassNames.h"
#include "lighting/passes/SampleRadiance.h"
#include "raster/Rasterizer.h"

namespace lighting {

class BlendedPass;

// A run of consecutive triangles of one instance, drawn as one unit, and its view-space bounds.
struct ForwardObject {
    uint32_t firstTriangle = 0;
    uint32_t triangleCount = 0;
    uint32_t instance = 0;
    ViewBox boundsView; // widened (CullingTests.h)
};

class ForwardGeometry {
public:
    // Transforms the scene, builds the objects and their bounds for inputs.view and sizes the
    // rasterizer and the depth plane (inputs.samples per pixel; std::invalid_argument for a
    // count the rasterizer does not take). Requires inputs.scene, inputs.geometry, inputs.view.
    // Cost O(vertices + triangles), parallel.
    void prepare(const StageInputs& inputs);
    // The same, timed as the pass "transform" in `result` (the forward stages' first pass).
    void prepare(const StageInputs& inputs, StageResult& result) {
        PassTimer transform(result, pass::kTransform);
        prepare(inputs);
    }

    // The start of every forward stage's frame: sizes `result` to the view (no oracle plane),
    // prepare() timed as "transform", then the depth pre-pass timed as "prepass"
    // (drawDepthPrepass) or, without one, clearDepth(). Multisampled, also clears
    // sampleTarget() (part of "transform").
    void beginFrame(const StageInputs& inputs, StageResult& result, bool depthPrepass) {
        result.resize(inputs.view->width, inputs.view->height, false);
        {
            PassTimer transform(result, pass::kTransform);
            prepare(inputs);
            if (mSamples > 1)
                mSampleRadiance.reset(inputs.view->width, inputs.view->height, mSamples,
                                      result.tracing());
        }
        if (depthPrepass)
            drawDepthPrepass(result);
        else
            clearDepth();
    }
    // The end of every forward stage's frame: multisampled, resolves sampleTarget() into
    // result.radiance (and the light trace), timed as "resolve"; nothing otherwise.
    void endFrame(StageResult& result) const {
        if (mSamples > 1)
            mSampleRadiance.resolve(result);
    }

    // The depth pre-pass: the visibility draw into depth() and visibility().codes() (and,
    // multisampled, shadedDepth()).
    void drawDepthPrepass();
    // The same, timed as the pass "prepass" in `result`.
    void drawDepthPrepass(StageResult& result) {
        PassTimer prepass(result, pass::kPrepass);
        drawDepthPrepass();
    }
    // Clears depth() (and shadedDepth()) to the view's far value, for a first draw without a
    // pre-pass.
    void clearDepth() {
        std::fill(mDepth.begin(), mDepth.end(), mVisibility.view().clearDepth());
        std::fill(mCentreDepth.begin(), mCentreDepth.end(), mVisibility.view().clearDepth());
    }
    // Samples per pixel of this frame (inputs.samples).
    int samples() const { return mSamples; }
    // Multisampled frames: the per-sample colour buffer the stage's FragmentShading writes (and
    // BlendedPass composites over), cleared by beginFrame, resolved by endFrame; null otherwise
    // (the fragments then go to result.radiance, as always).
    SampleRadiance* sampleTarget() { return mSamples > 1 ? &mSampleRadiance : nullptr; }
    // Per sample, the depth at which its visible surface is shaded: its fragment's centre depth
    // (the clear depth for background). Without multisampling that is depth(); multisampled it
    // is filled by drawDepthPrepass() or, without a pre-pass, by noteShaded(). What bounds the
    // shaded surfaces (tiled-forward's tiles) and what blended fragments are tested against.
    std::span<const float> shadedDepth() const {
        return mSamples > 1 ? std::span<const float>(mCentreDepth) : depth();
    }
    // Without a pre-pass, multisampled: the fragment was applied to the samples of `coverage`
    // (Replace: it is now what they show), so their shadedDepth() becomes its centre depth.
    // Called from the draw's fragment function (its pixel only: thread-safe per tile).
    void noteShaded(const raster::Fragment& fragment, uint8_t coverage) {
        float* samples =
            mCentreDepth.data() +
            (size_t(fragment.y) * size_t(mVisibility.view().width) + size_t(fragment.x)) *
                size_t(mSamples);
        const float depth = shadingDepth(fragment.depth);
        for (int s = 0; s < mSamples; ++s)
            if (coverage >> s & 1u)
                samples[s] = depth;
    }
    // Draws `triangles` (visibility().triangles(), or a subset indexing its clip positions) with
    // `state` over depth(), calling fragmentFn per fragment (raster::Rasterizer::draw). With an
    // alpha test (gbuffer::AlphaCoverage) the fragments the visibility draw discards are
    // discarded here too, before the depth write, and with alpha-to-coverage (inputs
    // .alphaToCoverage, multisampled) fragmentFn sees the fragment's coverage reduced to the
    // samples the visibility draw keeps (VisibilityPass::keptCoverage: the same function of the
    // same alpha at the same pixel) and only those are depth-written; `toSceneTriangle` maps a
    // drawn triangle index to the scene's (identity for visibility().triangles()).
    template <class FragmentFn, class ToSceneTriangle = std::identity>
    void draw(const raster::TriangleList& triangles, const raster::RasterState& state,
              FragmentFn&& fragmentFn, ToSceneTriangle toSceneTriangle = {}) {
        raster::RasterState multisampled = state;
        multisampled.samples = mSamples;
        if (!mVisibility.alphaCoverage().active()) {
            mRasterizer->draw(triangles, multisampled, mDepth.data(), fragmentFn);
            return;
        }
        mRasterizer->draw(triangles, multisampled, mDepth.data(),
                          [&](const raster::Fragment& fragment) {
                              raster::Fragment scene = fragment;
                              scene.triangle = toSceneTriangle(fragment.triangle);
                              raster::Fragment kept = fragment;
                              kept.coverage = mVisibility.keptCoverage(scene, mSamples);
                              if (kept.coverage != 0)
                                  fragmentFn(kept);
                              return raster::SampleMask{kept.coverage};
                          });
    }
    // The forward stages' depth plane (the frame's convention; samples() floats per pixel, as
    // raster/Rasterizer.h), as the last draws left it.
    std::span<const float> depth() const { return mDepth; }

    // The transformed scene: triangles(), drawState(), redrawState(), the visibility buffer of
    // the pre-pass (codes(), isVisible()) and surfaces.
    const gbuffer::VisibilityPass& visibility() const { return mVisibility; }
    const std::vector<ForwardObject>& objects() const { return mObjects; }
    // Multisampled frames, after the pre-pass: grows each object's box to hold the shading
    // position of every sample that shows it. A fragment is shaded at the pixel CENTRE (no
    // centroid sampling), which for a fragment covering only off-centre samples is its plane
    // extrapolated beyond the triangle, possibly beyond the box of the object's vertices; the
    // per-object lists must see those positions too or culling would drop lights there.
    // Parallel over rows; the points outside their box are merged in row order (min/max: the
    // result does not depend on the order anyway). No-op without multisampling.
    void boundShadedSamples();
    // Whether `positionView` lies in the object's box (for a fragment shaded without a pre-pass,
    // whose extrapolated centre boundShadedSamples could not see).
    bool insideBounds(uint32_t object, const glm::vec3& positionView) const {
        const ViewBox& box = mObjects[object].boundsView;
        return glm::all(glm::greaterThanEqual(positionView, box.lo)) &&
               glm::all(glm::lessThanEqual(positionView, box.hi));
    }
    // Per object, the lights whose sphere touches its box (sphereTouchesObject), ascending: the
    // per-object lists of `forward`, and transposed, the illumination sets of
    // `forward-multipass`. Objects in parallel, each into its own list, concatenated in object
    // order (deterministic). Not reentrant (scratch storage).
    void objectLightLists(const std::vector<LightSphere>& spheres, LightIndexLists& lists);
    uint32_t objectOfTriangle(uint32_t triangle) const { return mObjectOfTriangle[triangle]; }

    // The fragment's view-space position, bitwise surfaceAt's (the depth decode alone).
    glm::vec3 positionAt(const raster::Fragment& fragment) const {
        return mDepthDecoder->positionView(fragment.x, fragment.y, shadingDepth(fragment.depth));
    }
    // The depth a fragment is shaded at: its centre depth, except that a multisampled fragment
    // whose extrapolated centre depth clamps to the clear depth (a silhouette against the far
    // plane) is moved one float step nearer, as gbuffer::FragmentLayers stores it (a fragment
    // that passed the one-sample depth test is never at the clear depth).
    float shadingDepth(float centreDepth) const {
        return centreDepth == mClearDepth ? mNearerThanClear : centreDepth;
    }
    // The fragment's surface as `brute` sees it in the G-buffer (see the file comment).
    gbuffer::Surface surfaceAt(const raster::Fragment& fragment, uint32_t triangle) const {
        gbuffer::Surface s = mVisibility.surfaceAt(
            gbuffer::VisibilityPass::code(triangle, fragment.frontFacing), fragment.x, fragment.y);
        s.positionView = positionAt(fragment);
        return s;
    }
    // Adds the emission of every pixel's visible triangle (the pre-pass's visibility buffer,
    // drawDepthPrepass) to result.radiance, once (multisampled: of every sample's, to
    // sampleTarget()): for a stage that accumulates light by light.
    // Nothing to do (no pass over the pixels) when no material of the scene emits.
    void addEmission(StageResult& result);
    // The blended pass of the forward stages (BlendedPass.h), after their opaque draws: each
    // blended fragment lit with its object's lights (`objectLights`, objectLightLists), over
    // shadedDepth() (multisampled: composited per sample into sampleTarget()). Nothing to do
    // when the scene has no blended surface.
    void shadeBlended(const StageInputs& inputs, BlendedPass& blended,
                      const LightIndexLists& objectLights, StageResult& result);
    // How the forward stages read their own depth planes: the lossless layout's decoder.
    const gbuffer::DepthDecoder& depthDecoder() const { return *mDepthDecoder; }

private:
    gbuffer::VisibilityPass mVisibility;
    std::optional<gbuffer::DepthDecoder> mDepthDecoder;
    std::unique_ptr<raster::Rasterizer> mRasterizer;
    std::vector<float> mDepth;
    int mSamples = 1;
    float mClearDepth = 0.0f;
    float mNearerThanClear = 0.0f;         // the float next to the clear depth, towards the camera
    std::vector<float> mCentreDepth;       // multisampled: shadedDepth(), else empty
    SampleRadiance mSampleRadiance;        // multisampled: the per-sample colour
    std::vector<glm::vec3> mPositionsView; // for the object bounds only
    std::vector<ForwardObject> mObjects;
    std::vector<uint32_t> mObjectOfTriangle;
    std::vector<std::vector<uint32_t>> mPerObject; // objectLightLists scratch
    bool mEmits = false;                           // some material of the scene emits
};

// True when the (widened) light sphere may touch the object's box; unbounded lights always do.
inline bool sphereTouchesObject(const LightSphere& sphere, const ForwardObject& object) {
    return sphereTouchesBox(sphere, object.boundsView);
}

// Ensures `rasterizer` matches the view's size (recreated only when it changes).
void fitRasterizer(std::unique_ptr<raster::Rasterizer>& rasterizer,
                   const gbuffer::CameraView& view);

} // namespace lighting
