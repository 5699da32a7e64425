// ForwardShading: the machinery shared by the forward stages (`forward`, `forward-multipass`),
// which shade while rasterizing instead of reading a G-buffer.
//
// Per frame, ForwardFrame::prepare transforms the scene's vertices to clip space and normals to
// view space with the SAME expressions as gbuffer::GBufferPass, splits the triangle list into
// objects (runs of consecutive triangles of one scenes::Instance) and bounds each object with a
// view-space AABB. A fragment's surface comes from gbuffer::surfaceOfTriangle and its position
// from the fragment's depth through the lossless layout's gbuffer::DepthDecoder, the functions
// the G-buffer pass and GBuffer::decode use, so the visible fragment's Surface is bitwise the one
// `brute` reads from the G-buffer (the same triangles through the same rasterizer give the same
// depth), and evaluating lights in ascending index order gives bitwise brute's radiance.
//
// Conventions: view space right-handed, camera down -Z; depth in the CameraView's convention
// (reversed by default), so "closer" is Greater for reversed Z. Culling is conservative: lights
// are tested with the widened spheres of LightBounds.h against object boxes padded by
// kObjectBoxSlack, so rounding only ever adds work.
//
// Thread safety: prepare() is parallel inside and not reentrant per object; the const queries
// are thread-safe.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/GBufferPass.h"
#include "lighting/Brdf.h"
#include "lighting/LightBounds.h"
#include "lighting/ShadingStage.h"
#include "raster/Rasterizer.h"

namespace lighting {

// Relative padding of object boxes (times the largest view-space coordinate magnitude of the
// box): positions reconstructed from float depth stray from the float-transformed vertices by a
// few ulps of the distance to the camera; 1e-5 is ~100x that and only ever adds lights.
inline constexpr float kObjectBoxSlack = 1e-5f;

// A run of consecutive triangles of one instance, drawn as one unit, and its view-space bounds.
struct ForwardObject {
    uint32_t firstTriangle = 0;
    uint32_t triangleCount = 0;
    uint32_t instance = 0;
    glm::vec3 minView{0.0f};
    glm::vec3 maxView{0.0f};
};

// Visibility code of a fragment: the triangle, top bit set when its back face is seen (as the
// G-buffer pass's visibility buffer). kNoVisibleTriangle marks background.
inline constexpr uint32_t kBackFaceBit = 1u << 31;
inline constexpr uint32_t kNoVisibleTriangle = UINT32_MAX;
inline uint32_t visibilityCode(uint32_t triangle, bool frontFacing) {
    return triangle | (frontFacing ? 0u : kBackFaceBit);
}

class ForwardFrame {
public:
    // Transforms vertices, builds the objects and their bounds for inputs.view. Requires
    // inputs.scene, inputs.geometry, inputs.view. Cost O(vertices + triangles), parallel.
    void prepare(const StageInputs& inputs);

    const std::vector<glm::vec4>& clipPositions() const { return mClipPositions; }
    const std::vector<glm::vec3>& normalsView() const { return mNormalsView; }
    const std::vector<ForwardObject>& objects() const { return mObjects; }
    uint32_t objectOfTriangle(uint32_t triangle) const { return mObjectOfTriangle[triangle]; }
    raster::TriangleList triangles() const { return {mClipPositions, mGeometry->indices}; }

    // The fragment's surface as `brute` sees it in the G-buffer (see the file comment).
    gbuffer::Surface surfaceAt(const raster::Fragment& fragment, uint32_t triangle) const {
        gbuffer::Surface s = gbuffer::surfaceOfTriangle(
            *mGeometry, *mScene, mClipPositions, mNormalsView, triangle, !fragment.frontFacing,
            mView->ndcOfPixel(fragment.x, fragment.y));
        s.positionView = mDepthDecoder->positionView(fragment.x, fragment.y, fragment.depth);
        return s;
    }
    // How the forward stages read their own depth planes: the decoder of the lossless layout
    // (their depth is the rasterizer's float depth, kept as is), so positions are bitwise those
    // GBuffer::decode gives on that layout.
    const gbuffer::DepthDecoder& depthDecoder() const { return *mDepthDecoder; }

private:
    const scenes::Scene* mScene = nullptr;
    const gbuffer::SceneGeometry* mGeometry = nullptr;
    const gbuffer::CameraView* mView = nullptr;
    std::optional<gbuffer::DepthDecoder> mDepthDecoder;
    std::vector<glm::vec4> mClipPositions;
    std::vector<glm::vec3> mNormalsView;
    std::vector<glm::vec3> mPositionsView; // for the object bounds only
    std::vector<ForwardObject> mObjects;
    std::vector<uint32_t> mObjectOfTriangle;
};

// True when the (widened) light sphere may touch the object's box; unbounded lights always do.
inline bool sphereTouchesObject(const LightSphere& sphere, const ForwardObject& object) {
    if (sphere.unbounded)
        return true;
    const glm::vec3 outside =
        glm::max(glm::max(object.minView - sphere.centreView, sphere.centreView - object.maxView),
                 glm::vec3(0.0f));
    return glm::dot(outside, outside) <= sphere.radius * sphere.radius;
}

// Depth tests of the frame's convention: strictly closer (first draw / pre-pass) and closer or
// equal (a draw after a pre-pass, which lets the visible fragment pass again).
inline raster::DepthTest closerTest(const gbuffer::CameraView& view) {
    return view.reversedZ() ? raster::DepthTest::Greater : raster::DepthTest::Less;
}
inline raster::DepthTest closerOrEqualTest(const gbuffer::CameraView& view) {
    return view.reversedZ() ? raster::DepthTest::GreaterEqual : raster::DepthTest::LessEqual;
}

// Depth pre-pass: clears `depth` to the far value and `visible` to kNoVisibleTriangle, draws the
// whole scene (back faces culled, closer test, depth writes) and records the visible fragment's
// visibilityCode. A later draw with closerOrEqualTest and no depth writes that shades only the
// fragments whose code equals visible[pixel] implements an exact "depth equal" test: it shades
// each pixel's visible fragment once, even where two triangles tie in depth.
void depthPrepass(raster::Rasterizer& rasterizer, const ForwardFrame& forward,
                  const gbuffer::CameraView& view, std::vector<float>& depth,
                  std::vector<uint32_t>& visible);

// Ensures `rasterizer` matches the view's size (recreated only when it changes).
void fitRasterizer(std::unique_ptr<raster::Rasterizer>& rasterizer,
                   const gbuffer::CameraView& view);

inline double forwardElapsedMs(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

} // namespace lighting
