// VisibilityPass: the one vertex transform and visibility draw of a scene's geometry, and the
// surface of a triangle at a pixel. The G-buffer pass is this pass plus a resolve
// (GBufferPass.h); the stages that rasterize the scene again (forward shading, the material
// passes of the light pre-pass and inferred lighting) use the same object, so every pass sees
// bitwise the same clip positions, hence the same coverage, depth and surfaces.
//
// Per frame:
//   transform(scene, geometry, view)  vertices to clip space, normals (and tangents, when the
//                                     geometry has them) to view space (parallel over vertices);
//   draw(rasterizer, depth)           back faces culled, closer-than test in the view's depth
//                                     convention, depth written, and per pixel the visibility
//                                     code of the visible triangle (the visibility buffer,
//                                     codes()); no barycentrics: only the triangle is recorded,
//                                     and the surface is computed once per pixel afterwards;
//   surfaceAt(code, x, y)             the surface of the code's triangle at the pixel centre
//                                     (RowSurfaces: the same along a row, for whole-buffer loops).
// A visibility code is the triangle index, with kBackFaceBit set when its back face is visible
// (the surface's normal is then negated: two-sided draws light the visible side); kNoTriangle
// marks background. A scene may therefore have at most 2^31 - 1 triangles (checked).
//
// Conventions: clip space as raster/Rasterizer.h (zero-to-one depth); view space right-handed,
// camera looking down -Z; depth in the CameraView's convention (reversed by default), so "closer"
// is Greater for reversed Z. The surface's positionView is left zero: position comes from depth,
// through the layout's DepthDecoder (DepthFormat.h).
// Thread safety: transform() and draw() are parallel inside (TBB, under the caller's
// task_arena) and not reentrant per object; the const queries are thread-safe between them.
// Deterministic for any thread count (raster/Rasterizer.h keeps submission order per tile).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/Plane.h"
#include "gbuffer/Surface.h"
#include "gbuffer/visibility/AlphaCoverage.h"
#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "gbuffer/visibility/TriangleCorners.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"

namespace gbuffer {

class VisibilityPass {
public:
    static constexpr uint32_t kNoTriangle = UINT32_MAX;
    static constexpr uint32_t kBackFaceBit = 1u << 31;
    static constexpr uint32_t code(uint32_t triangle, bool frontFacing) {
        return triangle | (frontFacing ? 0u : kBackFaceBit);
    }
    static constexpr uint32_t triangleOf(uint32_t code) { return code & ~kBackFaceBit; }
    static constexpr bool backFaceOf(uint32_t code) { return (code & kBackFaceBit) != 0; }
    // Throws std::length_error naming the scene when its triangles do not fit the codes.
    static void checkTriangleCount(const scenes::Scene& scene, const SceneGeometry& geometry);

    // Transforms `geometry` (of `scene`; both must outlive the pass's use of this frame) for
    // `view`. `alphaToCoverage`: the frame's multisampled draws turn alpha-masked fragments into
    // sample masks (AlphaCoverage.h) instead of alpha-testing them. Cost O(vertices), parallel;
    // reuses the previous frame's storage.
    void transform(const scenes::Scene& scene, const SceneGeometry& geometry,
                   const CameraView& view, bool alphaToCoverage = false);
    const CameraView& view() const { return mView; }
    // How many frames transform() has prepared: what a reader holding codes of an earlier frame
    // checks (GBuffer's visibility layout).
    uint64_t frame() const { return mFrame; }
    const SceneGeometry& geometry() const { return *mGeometry; }
    std::span<const glm::vec4> clipPositions() const { return mClipPositions; }
    // The scene's triangles in clip space, for draws after transform().
    raster::TriangleList triangles() const { return {mClipPositions, mGeometry->indices}; }

    // The state of draw(): back faces culled, closer test, depth writes, no barycentrics. Also
    // what a pass that shades while drawing (forward shading without a pre-pass) uses.
    raster::RasterState drawState() const;
    // The state of a later draw over draw()'s depth (closer-or-equal, no depth writes). A fragment
    // function that shades only fragments for which isVisible() holds then shades each pixel's
    // visible fragment exactly once, even where two triangles tie in depth: an exact "depth
    // equal" test.
    raster::RasterState redrawState() const;

    // The alpha test of the opaque draws (AlphaCoverage.h; inactive when every material is
    // opaque). Every draw of the scene's opaque surfaces keeps exactly the fragments keeps()
    // accepts (multisampled: the samples keptCoverage() returns, which with alpha-to-coverage
    // may be a part of the fragment's coverage): draw() here, the forward stages' draws through
    // lighting::ForwardGeometry. fragment.triangle is the scene's triangle index.
    const AlphaCoverage& alphaCoverage() const { return mAlpha; }
    bool keeps(const raster::Fragment& fragment) const {
        return mAlpha.keeps(*mScene, *mGeometry, mClipPositions, mView, fragment.triangle,
                            fragment.x, fragment.y);
    }
    uint8_t keptCoverage(const raster::Fragment& fragment, int samples) const {
        return mAlpha.keptSamples(*mScene, *mGeometry, mClipPositions, mView, fragment.triangle,
                                  fragment.x, fragment.y, samples, fragment.coverage);
    }
    const scenes::Scene& scene() const { return *mScene; }

    // Clears `depth` (view width x height x `samples` floats) to the view's far value and the
    // visibility buffer to kNoTriangle, then draws the scene with drawState() at `samples` samples
    // per pixel (raster/Rasterizer.h: 1, 2, 4 or 8), recording codes; with an active alpha test,
    // discarded fragments write neither depth nor code (with alpha-to-coverage, multisampled:
    // neither at the samples keptCoverage() drops).
    void draw(raster::Rasterizer& rasterizer, std::span<float> depth, int samples = 1);
    // The visibility buffer of the last draw(): one code per sample, pixel-major
    // (codes()[pixel * sampleCount() + s]), row-major pixels.
    std::span<const uint32_t> codes() const { return mCodes; }
    int sampleCount() const { return mSamples; }
    // Multisampled draws only (else empty): per sample, the depth of its triangle's plane at the
    // PIXEL CENTRE (raster::Fragment::depth), the depth its surface is reconstructed at (shading
    // once per pixel and triangle), as the sample's code.
    std::span<const float> centreDepths() const { return mCentreDepths; }
    // Whether the fragment (of scene triangle `triangle`) is what the last draw() left visible at
    // its pixel: without multisampling, the pixel's code is its triangle's; multisampled, some
    // sample of its coverage shows its triangle (visibleCoverage() != 0).
    bool isVisible(const raster::Fragment& fragment, uint32_t triangle) const {
        if (mSamples == 1)
            return mCodes[size_t(fragment.y) * size_t(mView.width) + size_t(fragment.x)] ==
                   code(triangle, fragment.frontFacing);
        return visibleCoverage(fragment, triangle) != 0;
    }
    // The samples of fragment.coverage at which the last draw() left the fragment's triangle
    // visible (1 or 0 without multisampling): the samples a redraw over draw()'s depth
    // (redrawState) writes, so that each sample is written by exactly its visible fragment.
    uint8_t visibleCoverage(const raster::Fragment& fragment, uint32_t triangle) const {
        const size_t pixel = size_t(fragment.y) * size_t(mView.width) + size_t(fragment.x);
        const uint32_t value = code(triangle, fragment.frontFacing);
        if (mSamples == 1)
            return mCodes[pixel] == value ? 1 : 0;
        const uint32_t* samples = mCodes.data() + pixel * size_t(mSamples);
        unsigned visible = 0;
        for (int s = 0; s < mSamples; ++s)
            if ((fragment.coverage >> s & 1u) && samples[s] == value)
                visible |= 1u << s;
        return uint8_t(visible);
    }

    // The surface of the code's triangle (code != kNoTriangle) at pixel (x, y)'s centre:
    // perspective-correct barycentrics from the clip-space vertices, the interpolated, normalised
    // view-space normal (negated for a back face), the material's albedo (times the base colour
    // texture), specular and index; positionView zero. Pure given the last transform().
    Surface surfaceAt(uint32_t code, int x, int y) const;

    class RowSurfaces;

private:
    const scenes::Scene* mScene = nullptr;
    const SceneGeometry* mGeometry = nullptr;
    CameraView mView;
    std::vector<glm::vec4> mClipPositions;
    std::vector<glm::vec3> mNormalsView;
    std::vector<glm::vec4> mTangentsView;     // empty when the geometry has no tangents
    std::vector<MaterialSampling> mMaterials; // what the resolve reads of each material
    std::vector<float> mNdcXOfColumn; // view.ndcOfPixel(x, y).x per column: no division per pixel
    Plane<uint32_t> mCodes;
    std::vector<float> mCentreDepths; // multisampled draws: per sample (centreDepths())
    int mSamples = 1;
    AlphaCoverage mAlpha;
    uint64_t mFrame = 0;
};

// The surfaces of one pixel row, for loops over the visibility buffer (the G-buffer resolve, the
// material passes): while consecutive pixels show the same triangle (about 3.4 pixels in a row
// on atrium) its corners and row weights are reused, which takes the dependent index -> vertex
// loads off most pixels. at() is bitwise surfaceAt(). One object per row and task; valid while
// the pass is not transformed again.
class VisibilityPass::RowSurfaces {
public:
    RowSurfaces(const VisibilityPass& pass, int y)
        : mPass(pass), mNdcXOfColumn(pass.mNdcXOfColumn.data()),
          mNdcY(pass.mView.ndcOfPixel(0, y).y) {}

    // The surface at pixel x of the row; code != kNoTriangle. The reference stays valid until
    // the next call.
    [[gnu::always_inline]] const Surface& at(uint32_t code, int x) {
        const uint32_t triangle = triangleOf(code);
        if (triangle != mCornersOf) {
            mCorners =
                TriangleCorners::load(*mPass.mGeometry, mPass.mMaterials, mPass.mClipPositions,
                                      mPass.mNormalsView, mPass.mTangentsView, triangle);
            mRow = RowWeights::of(mCorners, mNdcY);
            mSurface = triangleSurface(mCorners);
            mCornersOf = triangle;
        }
        updateSurfaceAt(mSurface, mCorners, mRow, backFaceOf(code), mNdcXOfColumn[x]);
        return mSurface;
    }

private:
    const VisibilityPass& mPass;
    const float* mNdcXOfColumn;
    float mNdcY;
    uint32_t mCornersOf = kNoTriangle; // the triangle mCorners and mRow describe
    TriangleCorners mCorners;
    RowWeights mRow;
    Surface mSurface;
};

} // namespace gbuffer
