#include "gbuffer/GBuffer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <Imath/half.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gbuffer {

namespace {

// Specular power range of the 8-bit log encoding: 2^0 .. 2^13 (Blinn-Phong exponents of 1..8192).
constexpr float kLogPowerBits = 13.0f;

float srgbFromLinear(float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

const std::array<float, 256>& linearOfSrgb8() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) {
            const double s = i / 255.0;
            t[size_t(i)] = float(s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table;
}

uint32_t unorm8(float v) {
    return uint32_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

} // namespace

GBuffer::GBuffer(const GBufferLayout& layout, const CameraView& view)
    : mLayout(layout), mDepthDecoder(layout.depthDecoder(view)), mClearDepth(view.clearDepth()) {
    if (layout.depth.convention() != view.depthConvention ||
        layout.depth.infiniteFar != view.infiniteFar)
        throw std::invalid_argument(
            "G-buffer layout '" + layout.name + "' stores depth as " + layout.depth.text() +
            ", which needs a " +
            (layout.depth.convention() == DepthConvention::Reversed ? "reversed" : "standard") +
            "-Z view" + (layout.depth.infiniteFar ? " with an infinite far plane" : "") +
            "; the frame's view differs");
    mWorldFromView = glm::transpose(view.viewFromWorldNormal);
    const size_t n = pixelCount();
    mDepth.assign(n, mClearDepth); // depth is always there: coverage and positions come from it
    if (layout.visibilityBuffer) {
        mVisibilityCodes.assign(n, VisibilityPass::kNoTriangle);
        return; // every other channel is fetched from the triangle
    }
    if (layout.hasNormals) {
        if (layout.normals.kind == NormalCodecKind::Float32)
            for (auto& plane : mNormal)
                plane.assign(n, 0.0f);
        else if (layout.normals.bits <= 32)
            mNormalCode32.assign(n, 0);
        else
            mNormalCode64.assign(n, 0);
    }
    if (layout.albedo == AlbedoEncoding::Float32)
        for (auto& plane : mAlbedo)
            plane.assign(n, 0.0f);
    if (layout.albedo == AlbedoEncoding::Rgb8Srgb)
        mAlbedoPacked.assign(n, 0);
    if (layout.specular == SpecularEncoding::Float32)
        for (auto& plane : mSpecular)
            plane.assign(n, 0.0f);
    if (layout.specular == SpecularEncoding::Unorm8Half ||
        layout.specular == SpecularEncoding::Unorm8Log8)
        mSpecularPacked.assign(n, 0);
    if (layout.roughnessMetallic == RoughnessMetallicEncoding::Float32)
        for (auto& plane : mRoughnessMetallic)
            plane.assign(n, 0.0f);
    if (layout.roughnessMetallic == RoughnessMetallicEncoding::Unorm8)
        mRoughnessMetallicPacked.assign(n, 0);
    if (layout.occlusion == RoughnessMetallicEncoding::Float32)
        mOcclusion.assign(n, 0.0f);
    if (layout.occlusion == RoughnessMetallicEncoding::Unorm8)
        mOcclusionPacked.assign(n, 0);
    if (layout.emission == EmissionEncoding::Float32)
        for (auto& plane : mEmission)
            plane.assign(n, 0.0f);
    if (layout.hasMaterialIndex())
        mMaterial.assign(n, 0);
}

void GBuffer::quantiseDepth() {
    if (mDepthDecoder.lossless())
        return;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mDepth.size(), 16384), [&](const auto& range) {
        for (size_t pixel = range.begin(); pixel != range.end(); ++pixel) {
            const float z = mDepth[pixel];
            if (z != mClearDepth)
                mDepth[pixel] = mDepthDecoder.storedDepthNdc(z);
        }
    });
}

glm::vec3 GBuffer::viewRayOfPixel(size_t pixel) const {
    const CameraView& v = view();
    const int x = int(pixel % size_t(v.width)), y = int(pixel / size_t(v.width));
    return viewRayOfNdc(v, v.ndcOfPixel(x, y));
}

GBuffer::Writer::Writer(GBuffer& target) {
    auto pointer = [](auto& plane) { return plane.empty() ? nullptr : plane.data(); };
    for (int c = 0; c < 3; ++c) {
        mNormal[c] = pointer(target.mNormal[c]);
        mAlbedo[c] = pointer(target.mAlbedo[c]);
        mEmission[c] = pointer(target.mEmission[c]);
    }
    for (int c = 0; c < 2; ++c) {
        mSpecular[c] = pointer(target.mSpecular[c]);
        mRoughnessMetallic[c] = pointer(target.mRoughnessMetallic[c]);
    }
    mOcclusion = pointer(target.mOcclusion);
    mMaterial = pointer(target.mMaterial);
    mEncoded = target.hasEncodedPlanes() ? &target : nullptr;
}

bool GBuffer::hasEncodedPlanes() const {
    return !mNormalCode32.empty() || !mNormalCode64.empty() || !mAlbedoPacked.empty() ||
           !mSpecularPacked.empty() || !mRoughnessMetallicPacked.empty() ||
           !mOcclusionPacked.empty();
}

void GBuffer::writeEncoded(size_t pixel, const Surface& s) {
    if (!mNormalCode32.empty() || !mNormalCode64.empty()) {
        const glm::vec3 normal = mLayout.normalSpace == NormalSpace::World
                                     ? mWorldFromView * s.normalView
                                     : s.normalView;
        const NormalCode code = encodeNormal(mLayout.normals, normal, viewRayOfPixel(pixel));
        if (!mNormalCode32.empty())
            mNormalCode32[pixel] = uint32_t(code.low);
        else
            mNormalCode64[pixel] = code.low;
    }
    if (!mAlbedoPacked.empty()) {
        mAlbedoPacked[pixel] = unorm8(srgbFromLinear(s.albedo.r)) |
                               unorm8(srgbFromLinear(s.albedo.g)) << 8 |
                               unorm8(srgbFromLinear(s.albedo.b)) << 16;
    }
    if (!mSpecularPacked.empty()) {
        uint32_t power = 0;
        if (mLayout.specular == SpecularEncoding::Unorm8Half) {
            power = Imath::half(std::clamp(s.specularPower, 0.0f, 65504.0f)).bits();
        } else {
            power = unorm8(std::log2(std::clamp(s.specularPower, 1.0f, 8192.0f)) / kLogPowerBits);
        }
        mSpecularPacked[pixel] = unorm8(s.specularIntensity) | power << 8;
    }
    if (!mRoughnessMetallicPacked.empty())
        mRoughnessMetallicPacked[pixel] = uint16_t(unorm8(s.roughness) | unorm8(s.metallic) << 8);
    if (!mOcclusionPacked.empty())
        mOcclusionPacked[pixel] = uint8_t(unorm8(s.occlusion));
}

void GBuffer::fetchSurfacesFrom(const VisibilityPass& pass) {
    if (!mLayout.visibilityBuffer)
        throw std::logic_error("G-buffer layout '" + mLayout.name +
                               "' stores its attributes: it fetches no surface");
    mSurfaceSource = &pass;
    mSurfaceSourceFrame = pass.frame();
}

void GBuffer::checkSurfaceSource() const {
    // A pass that has moved on to another frame would hand out another frame's triangles: wrong
    // surfaces with no sign of it. One integer compare per decode keeps that loud.
    if (!mSurfaceSource || mSurfaceSource->frame() != mSurfaceSourceFrame)
        throw std::logic_error("visibility G-buffer decoded " +
                               std::string(mSurfaceSource
                                               ? "after its pass transformed another frame"
                                               : "before the G-buffer pass filled it"));
}

Surface GBuffer::fetchedSurface(int x, int y) const {
    checkSurfaceSource();
    const uint32_t code = mVisibilityCodes[size_t(y) * size_t(width()) + size_t(x)];
    return code == VisibilityPass::kNoTriangle ? Surface{} : mSurfaceSource->surfaceAt(code, x, y);
}

Surface GBuffer::decode(int x, int y) const {
    const CameraView& view = mDepthDecoder.view();
    const size_t pixel = size_t(y) * view.width + x;
    if (mLayout.visibilityBuffer) {
        Surface s = fetchedSurface(x, y);
        s.positionView = mDepthDecoder.positionView(x, y, mDepth[pixel]);
        return s;
    }
    Surface s;
    s.positionView = mDepthDecoder.positionView(x, y, mDepth[pixel]);
    if (!mNormal[0].empty()) {
        s.normalView = glm::vec3(mNormal[0][pixel], mNormal[1][pixel], mNormal[2][pixel]);
    } else if (!mNormalCode32.empty() || !mNormalCode64.empty()) {
        NormalCode code;
        code.low = !mNormalCode32.empty() ? mNormalCode32[pixel] : mNormalCode64[pixel];
        s.normalView =
            decodeNormal(mLayout.normals, code, viewRayOfNdc(view, view.ndcOfPixel(x, y)));
        if (mLayout.normalSpace == NormalSpace::World)
            s.normalView = view.viewFromWorldNormal * s.normalView;
    }
    if (!mMaterial.empty())
        s.material = mMaterial[pixel];
    const MaterialConstants* material = !mMaterial.empty() && s.material < mLayout.materials.size()
                                            ? &mLayout.materials[s.material]
                                            : nullptr;
    switch (mLayout.albedo) {
    case AlbedoEncoding::Float32:
        s.albedo = {mAlbedo[0][pixel], mAlbedo[1][pixel], mAlbedo[2][pixel]};
        break;
    case AlbedoEncoding::Rgb8Srgb: {
        const uint32_t packed = mAlbedoPacked[pixel];
        const auto& linear = linearOfSrgb8();
        s.albedo = {linear[packed & 0xff], linear[(packed >> 8) & 0xff],
                    linear[(packed >> 16) & 0xff]};
        break;
    }
    case AlbedoEncoding::Material:
        s.albedo = material ? material->albedo : glm::vec3(0.0f);
        break;
    case AlbedoEncoding::Constant:
        s.albedo = mLayout.constant.albedo;
        break;
    case AlbedoEncoding::None:
        break;
    }
    switch (mLayout.specular) {
    case SpecularEncoding::Float32:
        s.specularIntensity = mSpecular[0][pixel];
        s.specularPower = mSpecular[1][pixel];
        break;
    case SpecularEncoding::Unorm8Half:
    case SpecularEncoding::Unorm8Log8: {
        const uint32_t packed = mSpecularPacked[pixel];
        s.specularIntensity = float(packed & 0xff) / 255.0f;
        if (mLayout.specular == SpecularEncoding::Unorm8Half) {
            Imath::half power;
            power.setBits(uint16_t(packed >> 8));
            s.specularPower = float(power);
        } else {
            s.specularPower = std::exp2(float((packed >> 8) & 0xff) / 255.0f * kLogPowerBits);
        }
        break;
    }
    case SpecularEncoding::Material:
        if (material) {
            s.specularIntensity = material->specularIntensity;
            s.specularPower = material->specularPower;
        }
        break;
    case SpecularEncoding::Constant:
        s.specularIntensity = mLayout.constant.specularIntensity;
        s.specularPower = mLayout.constant.specularPower;
        break;
    case SpecularEncoding::None:
        break;
    }
    if (mLayout.modelPerMaterial)
        s.model = material ? material->model : scenes::MaterialModel::BlinnPhong;
    else
        s.model = mLayout.constant.model;
    switch (mLayout.roughnessMetallic) {
    case RoughnessMetallicEncoding::Float32:
        s.roughness = mRoughnessMetallic[0][pixel];
        s.metallic = mRoughnessMetallic[1][pixel];
        break;
    case RoughnessMetallicEncoding::Unorm8: {
        const uint16_t packed = mRoughnessMetallicPacked[pixel];
        s.roughness = float(packed & 0xff) / 255.0f;
        s.metallic = float(packed >> 8) / 255.0f;
        break;
    }
    case RoughnessMetallicEncoding::Material:
        if (material) {
            s.roughness = material->roughness;
            s.metallic = material->metallic;
        }
        break;
    case RoughnessMetallicEncoding::Constant:
        s.roughness = mLayout.constant.roughness;
        s.metallic = mLayout.constant.metallic;
        break;
    case RoughnessMetallicEncoding::None:
        break;
    }
    if (!mOcclusion.empty())
        s.occlusion = mOcclusion[pixel];
    else if (!mOcclusionPacked.empty())
        s.occlusion = float(mOcclusionPacked[pixel]) / 255.0f;
    s.emissive = emission(pixel);
    return s;
}

} // namespace gbuffer
