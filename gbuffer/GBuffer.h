// GBuffer: the planes of one frame's G-buffer, stored as separate arrays (structure of arrays)
// in the encodings of its GBufferLayout, and the decoder every reader goes through.
//
// Storage (see GBufferLayout.h for the encodings):
// - Depth: one float plane of NDC depth in the CameraView's convention (reversed by default),
//   cleared to the far plane's value, which marks background. The rasterizer depth-tests in it;
//   afterwards quantiseDepth() rounds every covered pixel through the layout's depth format, so
//   every reader (decode, and the culling code that reads depth() directly) sees exactly what the
//   format can hold. It stays a float array in memory whatever the format (allocatedBytesPerPixel
//   says so); the layout's bits are the format's.
// - Normals: three float planes for float32, else one array of codes (32- or 64-bit words).
//   pixel-view codes are built on the pixel's view ray, which encode and decode compute.
// - Albedo: three float planes (f32), one packed RGB8 sRGB word, or nothing (material index,
//   constant, none). Specular: two float planes, one packed word, or nothing. Roughness and
//   metallic: two float planes, one packed 16-bit word (8 bits each), or nothing. Material index:
//   one 16-bit array when something decodes from the material table. Emission: three float planes
//   or nothing (material index, none). The material model is not
//   stored per pixel: it is the layout's constant or the material's (GBufferLayout.h).
// - Visibility buffer (layout.visibilityBuffer): depth and one u32 plane of visibility codes, no
//   attribute plane. decode() and emission() fetch the surface from the VisibilityPass that drew
//   the codes (fetchSurfacesFrom, set by the G-buffer pass): bitwise the surface the G-buffer pass
//   resolves into the lossless layouts' planes. That pass must outlive the reads and must not
//   transform another frame before them (checked: std::logic_error).
// View-space position is reconstructed from depth by the layout's DepthDecoder (DepthFormat.h:
// inverse projection or view ray). Decoding is const and thread-safe; writing a pixel is safe
// concurrently with writing other pixels.
#pragma once

#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include "gbuffer/GBufferLayout.h"
#include "gbuffer/Plane.h"
#include "gbuffer/Surface.h"
#include "gbuffer/codecs/DepthFormat.h"
#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/VisibilityPass.h"

namespace gbuffer {

class GBuffer {
public:
    // Throws std::invalid_argument when the layout's depth format does not match the view's depth
    // convention or far plane (CameraView::fromCamera must be called with the format's).
    GBuffer(const GBufferLayout& layout, const CameraView& view);

    const GBufferLayout& layout() const { return mLayout; }
    const CameraView& view() const { return mDepthDecoder.view(); }
    // The layout's depth decoder on this view: how depth() reads back as view-space position.
    const DepthDecoder& depthDecoder() const { return mDepthDecoder; }
    int width() const { return view().width; }
    int height() const { return view().height; }
    size_t pixelCount() const { return size_t(view().width) * view().height; }
    // Rounds every covered pixel's depth through the layout's format (no-op for the float format
    // of the view's own convention). Parallel (TBB). A covered pixel stays covered.
    void quantiseDepth();
    // Writes pixels' attributes into the planes (depth is written by the rasterizer directly).
    // It holds the planes' raw pointers, so the G-buffer pass' stores per pixel are inline and
    // branch only on which planes exist (the same at every pixel); planes that need encoding
    // (normal codes, packed albedo or specular) go through GBuffer::writeEncoded. Safe
    // concurrently for different pixels; valid while the GBuffer lives and is not moved.
    class Writer {
    public:
        explicit Writer(GBuffer& target);
        void write(size_t pixel, const Surface& s) const {
            if (mNormal[0]) {
                mNormal[0][pixel] = s.normalView.x;
                mNormal[1][pixel] = s.normalView.y;
                mNormal[2][pixel] = s.normalView.z;
            }
            if (mAlbedo[0]) {
                mAlbedo[0][pixel] = s.albedo.r;
                mAlbedo[1][pixel] = s.albedo.g;
                mAlbedo[2][pixel] = s.albedo.b;
            }
            if (mSpecular[0]) {
                mSpecular[0][pixel] = s.specularIntensity;
                mSpecular[1][pixel] = s.specularPower;
            }
            if (mRoughnessMetallic[0]) {
                mRoughnessMetallic[0][pixel] = s.roughness;
                mRoughnessMetallic[1][pixel] = s.metallic;
            }
            if (mOcclusion)
                mOcclusion[pixel] = s.occlusion;
            if (mEmission[0]) {
                mEmission[0][pixel] = s.emissive.r;
                mEmission[1][pixel] = s.emissive.g;
                mEmission[2][pixel] = s.emissive.b;
            }
            if (mMaterial)
                mMaterial[pixel] = uint16_t(s.material);
            if (mEncoded)
                mEncoded->writeEncoded(pixel, s);
        }
        // The background value in every plane but depth: Surface's defaults.
        void writeBackground(size_t pixel) const { write(pixel, Surface{}); }

    private:
        float* mNormal[3] = {};
        float* mAlbedo[3] = {};
        float* mSpecular[2] = {};
        float* mRoughnessMetallic[2] = {};
        float* mOcclusion = nullptr;
        float* mEmission[3] = {};
        uint16_t* mMaterial = nullptr;
        GBuffer* mEncoded = nullptr; // the target when it has encoded planes
    };
    Writer writer() { return Writer(*this); }

    bool covered(size_t pixel) const { return mDepth[pixel] != mClearDepth; }
    // Reconstructs view-space position from depth (depthDecoder()) and decodes the other channels;
    // channels the layout does not provide are left at Surface's defaults.
    Surface decode(int x, int y) const;
    // Whether the layout stores emitted radiance (some used material emits): when false,
    // emission() is zero at every pixel and the stages skip adding it.
    bool hasEmission() const { return mLayout.emission != EmissionEncoding::None; }
    // The emitted radiance of a covered pixel, decoded alone (decode() sets Surface::emissive
    // too): what the stages add once per pixel after their light sum.
    glm::vec3 emission(size_t pixel) const {
        if (mLayout.visibilityBuffer)
            return fetchedSurface(int(pixel % size_t(width())), int(pixel / size_t(width())))
                .emissive;
        switch (mLayout.emission) {
        case EmissionEncoding::Float32:
            return {mEmission[0][pixel], mEmission[1][pixel], mEmission[2][pixel]};
        case EmissionEncoding::Material:
            return mMaterial[pixel] < mLayout.materials.size()
                       ? mLayout.materials[mMaterial[pixel]].emission
                       : glm::vec3(0.0f);
        case EmissionEncoding::None:
            break;
        }
        return glm::vec3(0.0f);
    }
    // decode(x, y) into `s` when the pixel is covered; false (and `s` untouched) for background.
    bool surfaceAt(int x, int y, Surface& s) const {
        if (!covered(size_t(y) * size_t(width()) + size_t(x)))
            return false;
        s = decode(x, y);
        return true;
    }

    // The covered pixels x0 .. x0 + count - 1 of row y in order, visit(x, surface) for each:
    // bitwise decode(x, y). For the visibility buffer, pixels of one triangle in the run share
    // its fetched corners and row weights (VisibilityPass::RowSurfaces), the way the G-buffer
    // pass resolves them, instead of fetching per pixel.
    template <class Visit> void decodeRun(int x0, int count, int y, Visit&& visit) const {
        const size_t row = size_t(y) * size_t(width());
        if (!mLayout.visibilityBuffer) {
            for (int x = x0; x < x0 + count; ++x)
                if (covered(row + size_t(x)))
                    visit(x, decode(x, y));
            return;
        }
        checkSurfaceSource();
        VisibilityPass::RowSurfaces surfaces(*mSurfaceSource, y);
        for (int x = x0; x < x0 + count; ++x) {
            const uint32_t code = mVisibilityCodes[row + size_t(x)];
            if (code == VisibilityPass::kNoTriangle)
                continue;
            Surface s = surfaces.at(code, x);
            s.positionView = mDepthDecoder.positionView(x, y, mDepth[row + size_t(x)]);
            visit(x, s);
        }
    }

    // The working depth plane the G-buffer pass draws into: NDC depth in the view's convention,
    // the far plane's value where nothing was drawn.
    std::span<float> depthPlane() { return mDepth; }
    std::span<const float> depth() const { return mDepth; }
    // The stored planes, for readers that decode many pixels at once (the shading kernel's
    // PacketDecoder, lighting/kernel/); an empty span for a plane the layout does not store.
    // Encoded planes (normal codes, packed albedo, specular, roughness-metallic or occlusion) are
    // not exposed: such layouts are read through decode().
    std::span<const float> normalPlane(int axis) const { return mNormal[axis]; }
    std::span<const float> albedoPlane(int channel) const { return mAlbedo[channel]; }
    std::span<const float> specularPlane(int index) const { return mSpecular[index]; }
    std::span<const uint16_t> materialPlane() const { return mMaterial; }
    // f32 roughness (index 0) and metallic (1); f32 ambient occlusion.
    std::span<const float> roughnessMetallicPlane(int index) const {
        return mRoughnessMetallic[index];
    }
    std::span<const float> occlusionPlane() const { return mOcclusion; }

    // Visibility-buffer layouts (else empty): the codes the G-buffer pass stores (one per pixel,
    // VisibilityPass::kNoTriangle for background) and the pass whose triangles they index.
    std::span<uint32_t> visibilityCodePlane() { return mVisibilityCodes; }
    std::span<const uint32_t> visibilityCodes() const { return mVisibilityCodes; }
    void fetchSurfacesFrom(const VisibilityPass& pass);

private:
    // The surface of a covered pixel of a visibility-buffer layout, positionView left zero.
    Surface fetchedSurface(int x, int y) const;
    // Throws std::logic_error unless the visibility codes' pass still holds their frame.
    void checkSurfaceSource() const;
    glm::vec3 viewRayOfPixel(size_t pixel) const;
    bool hasEncodedPlanes() const;
    // The planes Writer cannot store directly: normal codes, packed albedo, packed specular.
    void writeEncoded(size_t pixel, const Surface& surface);

    GBufferLayout mLayout;
    DepthDecoder mDepthDecoder;
    glm::mat3 mWorldFromView{
        1.0f}; // for world-space normal codes (viewFromWorldNormal is a rotation)
    float mClearDepth;
    Plane<float> mDepth;
    Plane<float> mNormal[3];                        // float32 normals
    Plane<uint32_t> mNormalCode32;                  // codes of up to 32 bits
    Plane<uint64_t> mNormalCode64;                  // longer codes (xyz:48)
    Plane<float> mAlbedo[3];                        // f32
    Plane<uint32_t> mAlbedoPacked;                  // rgb8-srgb
    Plane<float> mSpecular[2];                      // f32
    Plane<uint32_t> mSpecularPacked;                // unorm8+f16, unorm8+log8
    Plane<float> mRoughnessMetallic[2];             // f32 roughness, metallic
    Plane<uint16_t> mRoughnessMetallicPacked;       // unorm8 roughness | unorm8 metallic << 8
    Plane<float> mOcclusion;                        // f32 ambient occlusion
    Plane<uint8_t> mOcclusionPacked;                // unorm8 ambient occlusion
    Plane<float> mEmission[3];                      // f32 emitted radiance
    Plane<uint16_t> mMaterial;                      // material index
    Plane<uint32_t> mVisibilityCodes;               // visibility buffer: triangle + back-face bit
    const VisibilityPass* mSurfaceSource = nullptr; // visibility buffer: what the codes index
    uint64_t mSurfaceSourceFrame = 0;               // its frame() when the codes were stored
};

} // namespace gbuffer
