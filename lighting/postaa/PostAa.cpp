#include "lighting/postaa/PostAa.h"

#include <stdexcept>

#include "scenes/input/ClosestName.h"

namespace lighting::postaa {

const char* postAaName(PostAa mode) {
    switch (mode) {
    case PostAa::None:
        return "none";
    case PostAa::EdgeBlur:
        return "edge-blur";
    case PostAa::Fxaa:
        return "fxaa";
    }
    return "none";
}

std::vector<std::string> postAaNames() {
    return {postAaName(PostAa::None), postAaName(PostAa::EdgeBlur), postAaName(PostAa::Fxaa)};
}

PostAa parsePostAa(const std::string& text) {
    for (PostAa mode : {PostAa::None, PostAa::EdgeBlur, PostAa::Fxaa})
        if (text == postAaName(mode))
            return mode;
    std::string valid;
    for (const std::string& name : postAaNames()) {
        if (!valid.empty())
            valid += ", ";
        valid += name;
    }
    throw std::invalid_argument("unknown post-process anti-aliasing '" + text + "'" +
                                scenes::didYouMean(text, postAaNames()) + "; valid: " + valid);
}

std::vector<gbuffer::Channel> requiredChannels(PostAa mode) {
    if (mode == PostAa::EdgeBlur)
        return {gbuffer::Channel::Depth, gbuffer::Channel::Normal};
    return {};
}

std::map<std::string, std::string> PostAaPass::describe() const {
    switch (mMode) {
    case PostAa::EdgeBlur:
        return mEdgeBlur.describe();
    case PostAa::Fxaa:
        return mFxaa.describe();
    case PostAa::None:
        break;
    }
    return {};
}

void PostAaPass::apply(const gbuffer::GBuffer& gbuffer, std::vector<float> (&radiance)[3],
                       std::vector<float>& edges) {
    if (mMode == PostAa::None) {
        edges.clear();
        return;
    }
    const size_t n = gbuffer.pixelCount();
    for (const std::vector<float>& plane : radiance)
        if (plane.size() != n)
            throw std::invalid_argument("post-aa: a radiance plane has " +
                                        std::to_string(plane.size()) + " pixels, the G-buffer " +
                                        std::to_string(n));
    edges.resize(n);
    for (std::vector<float>& plane : mOut)
        plane.resize(n);
    const RadianceIn in{gbuffer.width(),
                        gbuffer.height(),
                        {radiance[0].data(), radiance[1].data(), radiance[2].data()}};
    const RadianceOut out{{mOut[0].data(), mOut[1].data(), mOut[2].data()}, edges.data()};
    if (mMode == PostAa::EdgeBlur) {
        mSurface.extract(gbuffer);
        edgeBlur(mSurface, mEdgeBlur, in, out);
    } else {
        fxaa(mFxaa, in, out, mLuma);
    }
    for (int c = 0; c < 3; ++c)
        radiance[c].swap(mOut[c]);
}

} // namespace lighting::postaa
