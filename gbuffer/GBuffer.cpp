#include "gbuffer/GBuffer.h"

#include <algorithm>

namespace gbuffer {

GBuffer::GBuffer(const GBufferLayout& layout, const FrameView& view)
    : mLayout(layout), mView(view), mClearDepth(view.clearDepth()) {
    const size_t n = pixelCount();
    mDepth.assign(n, mClearDepth);  // depth is always there: coverage and positions come from it
    if (layout.has(Channel::Normal))
        for (auto& plane : mNormal) plane.assign(n, 0.0f);
    if (layout.has(Channel::Albedo))
        for (auto& plane : mAlbedo) plane.assign(n, 0.0f);
    if (layout.has(Channel::Specular))
        for (auto& plane : mSpecular) plane.assign(n, 0.0f);
}

void GBuffer::clearDepth() { std::fill(mDepth.begin(), mDepth.end(), mClearDepth); }

glm::vec3 GBuffer::reconstructPositionView(int x, int y, float depth) const {
    const glm::vec2 ndc = mView.ndcOfPixel(x, y);
    const glm::vec4 p = mView.viewFromClip * glm::vec4(ndc, depth, 1.0f);
    return glm::vec3(p) / p.w;
}

Surface GBuffer::decode(int x, int y) const {
    const size_t pixel = size_t(y) * mView.width + x;
    Surface s;
    s.positionView = reconstructPositionView(x, y, mDepth[pixel]);
    if (!mNormal[0].empty())
        s.normalView = glm::vec3(mNormal[0][pixel], mNormal[1][pixel], mNormal[2][pixel]);
    if (!mAlbedo[0].empty())
        s.albedo = glm::vec3(mAlbedo[0][pixel], mAlbedo[1][pixel], mAlbedo[2][pixel]);
    if (!mSpecular[0].empty()) {
        s.specularIntensity = mSpecular[0][pixel];
        s.specularPower = mSpecular[1][pixel];
    }
    return s;
}

}  // namespace gbuffer
