// DepthFormat implementation. Mappings are evaluated in double and rounded once, so that a
// format's error is its quantisation, not the arithmetic around it. IEEE half comes from Imath
// (OpenEXR's half type), not hand-written bit twiddling.
#include "gbuffer/codecs/DepthFormat.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Imath/half.h>

namespace gbuffer {

namespace {

struct FormatInfo {
    DepthFormatKind kind;
    const char* name;
    int bits;
};

constexpr FormatInfo kFormats[] = {
    {DepthFormatKind::F32, "f32", 32},
    {DepthFormatKind::F32Reversed, "f32-reversed", 32},
    {DepthFormatKind::Unorm24, "unorm24", 24},
    {DepthFormatKind::Unorm16, "unorm16", 16},
    {DepthFormatKind::F16Linear, "f16-linear", 16},
};

constexpr const char* kInfiniteSuffix = ":infinite";

uint32_t unormMax(DepthFormatKind kind) {
    return kind == DepthFormatKind::Unorm24 ? (1u << 24) - 1u : (1u << 16) - 1u;
}

// Largest finite half (65504 m): farther linear depths saturate there rather than becoming Inf,
// which is the clear code.
constexpr uint16_t kHalfMaxFiniteBits = 0x7BFF;
constexpr uint16_t kHalfInfinityBits = 0x7C00;

} // namespace

const char* depthFormatName(DepthFormatKind kind) {
    for (const FormatInfo& f : kFormats)
        if (f.kind == kind)
            return f.name;
    return "?";
}

std::vector<std::string> depthFormatNames() {
    std::vector<std::string> names;
    for (const FormatInfo& f : kFormats)
        names.emplace_back(f.name);
    return names;
}

std::vector<DepthFormatSpec> allDepthFormatSpecs() {
    std::vector<DepthFormatSpec> specs;
    for (bool infinite : {false, true})
        for (const FormatInfo& f : kFormats)
            specs.push_back({f.kind, infinite});
    return specs;
}

std::string DepthFormatSpec::text() const {
    return std::string(depthFormatName(kind)) + (infiniteFar ? kInfiniteSuffix : "");
}

DepthFormatSpec DepthFormatSpec::parse(const std::string& text) {
    DepthFormatSpec spec;
    std::string name = text;
    const size_t colon = text.find(':');
    if (colon != std::string::npos) {
        if (text.substr(colon) != kInfiniteSuffix)
            throw std::invalid_argument("depth format '" + text +
                                        "': the only option is ':infinite' (infinite far plane)");
        spec.infiniteFar = true;
        name = text.substr(0, colon);
    }
    for (const FormatInfo& f : kFormats)
        if (name == f.name) {
            spec.kind = f.kind;
            return spec;
        }
    std::string valid;
    for (const FormatInfo& f : kFormats)
        valid += std::string(valid.empty() ? "" : ", ") + f.name;
    throw std::invalid_argument("unknown depth format '" + text + "'; valid: " + valid +
                                " (each optionally with ':infinite')");
}

int DepthFormatSpec::bits() const {
    for (const FormatInfo& f : kFormats)
        if (f.kind == kind)
            return f.bits;
    return 0;
}

DepthConvention DepthFormatSpec::convention() const {
    return kind == DepthFormatKind::F32Reversed || kind == DepthFormatKind::F16Linear
               ? DepthConvention::Reversed
               : DepthConvention::Standard;
}

DepthProjection DepthProjection::of(const CameraView& view) {
    return {double(view.nearMetres), double(view.farMetres), view.infiniteFar, view.reversedZ()};
}

double DepthProjection::ndcFromViewDepth(double d) const {
    const double n = nearMetres, f = farMetres;
    const double standard = infiniteFar ? 1.0 - n / d : f * (d - n) / (d * (f - n));
    // Reversed computed directly (not 1 - standard) so that far depths keep their precision.
    const double reversedZ = infiniteFar ? n / d : n * (f - d) / (d * (f - n));
    return reversed ? reversedZ : standard;
}

double DepthProjection::viewDepthFromNdc(double z) const {
    const double n = nearMetres, f = farMetres;
    if (infiniteFar)
        return reversed ? n / z : n / (1.0 - z);
    return reversed ? n * f / (n + z * (f - n)) : n * f / (f - z * (f - n));
}

float DepthProjection::viewDepthFromNdcFloat(float z) const {
    const float n = float(nearMetres), f = float(farMetres);
    // Written in terms of the distance from the far plane's value, w = z (reversed) or 1 - z
    // (standard; exact in float for z >= 1/2 by Sterbenz), so that the denominator n + w (f - n)
    // has no cancellation. The textbook standard form f - z (f - n) cancels near the far plane:
    // the float rounding of f - n alone then costs ~eps f / n relative (0.4% at 0.1/10000), as
    // much as the format's own quantisation.
    const float w = reversed ? z : 1.0f - z;
    if (infiniteFar)
        return n / w;
    return n * f / (n + w * (f - n));
}

uint32_t clearDepthCode(const DepthFormatSpec& format, const DepthProjection& projection) {
    switch (format.kind) {
    case DepthFormatKind::F32:
    case DepthFormatKind::F32Reversed:
        return std::bit_cast<uint32_t>(projection.clearDepthNdc());
    case DepthFormatKind::Unorm24:
    case DepthFormatKind::Unorm16:
        return projection.reversed ? 0u : unormMax(format.kind);
    case DepthFormatKind::F16Linear:
        return kHalfInfinityBits;
    }
    return 0;
}

uint32_t encodeDepth(const DepthFormatSpec& format, const DepthProjection& projection,
                     float depthNdc) {
    const uint32_t clear = clearDepthCode(format, projection);
    switch (format.kind) {
    case DepthFormatKind::F32:
    case DepthFormatKind::F32Reversed:
        // -0.0 compares equal to the reversed clear value 0.0 (GBuffer::covered compares floats):
        // give it the clear code, not a second bit pattern that means the same.
        return depthNdc == projection.clearDepthNdc() ? clear : std::bit_cast<uint32_t>(depthNdc);
    case DepthFormatKind::Unorm24:
    case DepthFormatKind::Unorm16: {
        const uint32_t max = unormMax(format.kind);
        const double clamped = std::clamp(double(depthNdc), 0.0, 1.0);
        uint32_t code = uint32_t(std::lround(clamped * max));
        if (depthNdc != projection.clearDepthNdc() && code == clear)
            code = projection.reversed ? 1u : max - 1u; // covered stays covered
        return code;
    }
    case DepthFormatKind::F16Linear: {
        if (depthNdc == projection.clearDepthNdc())
            return clear;
        // Clamped to [0, 65504]: NDC depth outside [0, 1] (unclipped input; reversed z < 0 far
        // enough gives a negative linear depth) must not give a negative half, whose bits the
        // final min would turn into 65504 m, the far end.
        const double d = projection.viewDepthFromNdc(double(depthNdc));
        const Imath::half h(float(std::clamp(d, 0.0, 65504.0)));
        return std::min<uint32_t>(h.bits(), kHalfMaxFiniteBits);
    }
    }
    return clear;
}

float decodeDepthNdc(const DepthFormatSpec& format, const DepthProjection& projection,
                     uint32_t code) {
    switch (format.kind) {
    case DepthFormatKind::F32:
    case DepthFormatKind::F32Reversed:
        return std::bit_cast<float>(code);
    case DepthFormatKind::Unorm24:
    case DepthFormatKind::Unorm16:
        return float(double(code & unormMax(format.kind)) / double(unormMax(format.kind)));
    case DepthFormatKind::F16Linear: {
        if (code == kHalfInfinityBits)
            return projection.clearDepthNdc();
        Imath::half h;
        h.setBits(uint16_t(code));
        return float(projection.ndcFromViewDepth(double(float(h))));
    }
    }
    return projection.clearDepthNdc();
}

float decodeViewDepth(const DepthFormatSpec& format, const DepthProjection& projection,
                      uint32_t code) {
    if (format.kind == DepthFormatKind::F16Linear) {
        if (code == kHalfInfinityBits)
            return std::numeric_limits<float>::infinity();
        Imath::half h;
        h.setBits(uint16_t(code));
        return float(h);
    }
    return projection.viewDepthFromNdcFloat(decodeDepthNdc(format, projection, code));
}

const char* positionMethodName(PositionMethod method) {
    return method == PositionMethod::InverseProjection ? "inverse-projection" : "view-ray";
}

PositionMethod parsePositionMethod(const std::string& text) {
    if (text == "inverse-projection")
        return PositionMethod::InverseProjection;
    if (text == "view-ray")
        return PositionMethod::ViewRay;
    throw std::invalid_argument("unknown position reconstruction '" + text +
                                "'; valid: inverse-projection, view-ray");
}

glm::vec3 positionByInverseProjection(const CameraView& view, glm::vec2 ndc, float depthNdc) {
    const glm::vec4 p = view.viewFromClip * glm::vec4(ndc, depthNdc, 1.0f);
    return glm::vec3(p) / p.w;
}

glm::vec3 viewRayOfNdc(const CameraView& view, glm::vec2 ndc) {
    // clipFromView[0][0] = 1 / (aspect tan(fov/2)), [1][1] = 1 / tan(fov/2); [2][0] and [2][1]
    // are minus the jitter's NDC shift (CameraView::pixelOffset), exactly 0 without one, so the
    // unjittered ray is bitwise what it was (ndc + 0 = ndc: no NDC is -0).
    return {(ndc.x + view.clipFromView[2][0]) / view.clipFromView[0][0],
            (ndc.y + view.clipFromView[2][1]) / view.clipFromView[1][1], -1.0f};
}

glm::vec3 positionByViewRay(const CameraView& view, glm::vec2 ndc, float viewDepthMetres) {
    return viewRayOfNdc(view, ndc) * viewDepthMetres;
}

DepthDecoder::DepthDecoder(const DepthFormatSpec& format, PositionMethod method,
                           const CameraView& view)
    : mFormat(format), mMethod(method), mView(view), mProjection(DepthProjection::of(view)) {}

bool DepthDecoder::lossless() const {
    return mFormat.kind == DepthFormatKind::F32 || mFormat.kind == DepthFormatKind::F32Reversed;
}

float DepthDecoder::storedDepthNdc(float depthNdc) const {
    const float clear = mProjection.clearDepthNdc();
    if (lossless() || depthNdc == clear)
        return depthNdc;
    const float stored =
        decodeDepthNdc(mFormat, mProjection, encodeDepth(mFormat, mProjection, depthNdc));
    const bool covered = mProjection.reversed ? stored > clear : stored < clear;
    return covered ? stored : std::nextafter(clear, mProjection.reversed ? 1.0f : 0.0f);
}

glm::vec3 DepthDecoder::positionView(int x, int y, float storedDepthNdc) const {
    const glm::vec2 ndc = mView.ndcOfPixel(x, y);
    if (mMethod == PositionMethod::InverseProjection)
        return positionByInverseProjection(mView, ndc, storedDepthNdc);
    return positionByViewRay(mView, ndc, mProjection.viewDepthFromNdcFloat(storedDepthNdc));
}

} // namespace gbuffer
