// GBuffer: the planes of one frame's G-buffer, stored as separate arrays (structure of arrays)
// in the encodings of its GBufferLayout, and the decoder every reader goes through.
//
// Depth is NDC z in [0, 1] in the FrameView's convention (reversed by default), cleared to the
// far plane's value, which marks background. View-space
// position is reconstructed from depth and the inverse projection. Decoding is const and
// thread-safe; writing a pixel is safe concurrently with writing other pixels.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/FrameView.h"
#include "gbuffer/GBufferLayout.h"

namespace gbuffer {

// What a lighting stage needs at one pixel, decoded.
struct Surface {
    glm::vec3 positionView{0.0f};
    glm::vec3 normalView{0.0f, 0.0f, 1.0f};
    glm::vec3 albedo{0.0f};
    float specularIntensity = 0.0f;
    float specularPower = 1.0f;
};

class GBuffer {
public:
    GBuffer(const GBufferLayout& layout, const FrameView& view);

    const GBufferLayout& layout() const { return mLayout; }
    const FrameView& view() const { return mView; }
    int width() const { return mView.width; }
    int height() const { return mView.height; }
    size_t pixelCount() const { return size_t(mView.width) * mView.height; }

    // Resets depth to the far plane's value. Other planes are written for every pixel by the G-buffer
    // pass (zero for background), so clearing them too would only cost bandwidth.
    void clearDepth();
    // Writes the background value (zero) to every plane but depth at one pixel.
    void writeBackground(size_t pixel) { writeSurface(pixel, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, 0.0f); }

    // Writes one pixel's surface attributes (depth is written by the rasterizer directly).
    void writeSurface(size_t pixel, const glm::vec3& normalView, const glm::vec3& albedo,
                      float specularIntensity, float specularPower) {
        if (!mNormal[0].empty()) {
            mNormal[0][pixel] = normalView.x;
            mNormal[1][pixel] = normalView.y;
            mNormal[2][pixel] = normalView.z;
        }
        if (!mAlbedo[0].empty()) {
            mAlbedo[0][pixel] = albedo.r;
            mAlbedo[1][pixel] = albedo.g;
            mAlbedo[2][pixel] = albedo.b;
        }
        if (!mSpecular[0].empty()) {
            mSpecular[0][pixel] = specularIntensity;
            mSpecular[1][pixel] = specularPower;
        }
    }

    bool covered(size_t pixel) const { return mDepth[pixel] != mClearDepth; }
    // Reconstructs view-space position from depth and decodes the other channels.
    Surface decode(int x, int y) const;
    glm::vec3 reconstructPositionView(int x, int y, float depth) const;

    float* depthPlane() { return mDepth.data(); }
    const std::vector<float>& depth() const { return mDepth; }
    // Decoded planes for output layers (EXR); empty when the layout has no such channel.
    const std::vector<float>& normalPlane(int component) const { return mNormal[component]; }
    const std::vector<float>& albedoPlane(int component) const { return mAlbedo[component]; }

private:
    GBufferLayout mLayout;
    FrameView mView;
    float mClearDepth;
    std::vector<float> mDepth;
    std::vector<float> mNormal[3];
    std::vector<float> mAlbedo[3];
    std::vector<float> mSpecular[2];
};

}  // namespace gbuffer
