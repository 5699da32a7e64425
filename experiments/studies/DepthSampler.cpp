#include "experiments/studies/DepthSampler.h"

#include <bit>
#include <cmath>
#include <limits>

#include <Imath/half.h>

#include "scenes/Scene.h"

namespace experiments {

namespace {

using gbuffer::DepthFormatKind;
using gbuffer::DepthFormatSpec;
using gbuffer::PositionMethod;

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Largest finite half's bits; the bit patterns of non-negative halves are ordered like their
// values.
constexpr uint64_t kHalfMaxFiniteBits = 0x7BFF;
constexpr uint64_t kFloatOneBits = 0x3F800000; // NDC depth never exceeds 1

} // namespace

DepthSampler::DepthSampler(const DepthStudyOptions& options, DepthStudyCamera camera,
                           DepthFormatSpec format)
    : mFormat(format) {
    scenes::Camera c; // at the origin, looking down -Z, +Y up: view space is world space
    c.verticalFovRadians = float(options.verticalFovDegrees * kPi / 180.0);
    c.nearMetres = float(camera.nearMetres);
    c.farMetres = float(camera.farMetres);
    mView = gbuffer::CameraView::fromCamera(c, options.width, options.height, format.convention(),
                                            format.infiniteFar);
    mProjection = gbuffer::DepthProjection::of(mView);
    mRasterClipFromView = glm::dmat4(mView.clipFromView);
    // glm::perspective: [1][1] = 1 / tan(fovY / 2), [0][0] = [1][1] / aspect, from the same
    // float field of view the CameraView was built from.
    const double tanHalf = std::tan(double(c.verticalFovRadians) / 2.0);
    mViewYPerNdc = tanHalf;
    mViewXPerNdc = tanHalf * double(options.width) / double(options.height);
}

glm::dvec3 DepthSampler::exactPointView(int x, int y, double d) const {
    const double ndcX = (double(x) + 0.5) / double(mView.width) * 2.0 - 1.0;
    const double ndcY = 1.0 - (double(y) + 0.5) / double(mView.height) * 2.0;
    return {ndcX * d * mViewXPerNdc, ndcY * d * mViewYPerNdc, -d};
}

float DepthSampler::rasterDepthNdc(const glm::dvec3& pointView) const {
    const glm::dvec4 clip = mRasterClipFromView * glm::dvec4(pointView, 1.0);
    return float(clip.z / clip.w);
}

bool DepthSampler::lost(float depthNdc) const {
    return !(depthNdc >= 0.0f && depthNdc <= 1.0f) || depthNdc == mProjection.clearDepthNdc();
}

glm::vec3 DepthSampler::reconstruct(PositionMethod method, int x, int y, float depthNdc) const {
    const uint32_t code = gbuffer::encodeDepth(mFormat, mProjection, depthNdc);
    const glm::vec2 ndc = mView.ndcOfPixel(x, y);
    if (method == PositionMethod::InverseProjection)
        return gbuffer::positionByInverseProjection(
            mView, ndc, gbuffer::decodeDepthNdc(mFormat, mProjection, code));
    return gbuffer::positionByViewRay(mView, ndc,
                                      gbuffer::decodeViewDepth(mFormat, mProjection, code));
}

bool DepthSampler::validCode(uint64_t code) const {
    if (code == gbuffer::clearDepthCode(mFormat, mProjection))
        return false;
    switch (mFormat.kind) {
    case DepthFormatKind::F32:
    case DepthFormatKind::F32Reversed:
        return code <= kFloatOneBits;
    case DepthFormatKind::Unorm24:
    case DepthFormatKind::Unorm16:
        return code < (uint64_t(1) << mFormat.bits());
    case DepthFormatKind::F16Linear:
        return code <= kHalfMaxFiniteBits;
    }
    return false;
}

double DepthSampler::codeViewDepthExact(uint32_t code) const {
    switch (mFormat.kind) {
    case DepthFormatKind::F32:
    case DepthFormatKind::F32Reversed:
        return mProjection.viewDepthFromNdc(double(std::bit_cast<float>(code)));
    case DepthFormatKind::Unorm24:
    case DepthFormatKind::Unorm16:
        return mProjection.viewDepthFromNdc(double(code) /
                                            double((uint64_t(1) << mFormat.bits()) - 1));
    case DepthFormatKind::F16Linear: {
        Imath::half h;
        h.setBits(uint16_t(code));
        return double(float(h));
    }
    }
    return kNaN;
}

double DepthSampler::depthStepMetres(double viewDepthMetres) const {
    const float depthNdc = rasterDepthNdc({0.0, 0.0, -viewDepthMetres});
    if (lost(depthNdc))
        return kNaN;
    const uint32_t code = gbuffer::encodeDepth(mFormat, mProjection, depthNdc);
    const double here = codeViewDepthExact(code);
    double farther = kNaN, nearer = kNaN;
    for (int64_t delta : {-1, 1}) {
        const int64_t neighbour = int64_t(code) + delta;
        if (neighbour < 0 || !validCode(uint64_t(neighbour)))
            continue;
        const double d = codeViewDepthExact(uint32_t(neighbour));
        if (!(std::isfinite(d) && d > 0.0))
            continue;
        (d > here ? farther : nearer) = d;
    }
    return !std::isnan(farther) ? farther - here : here - nearer;
}

} // namespace experiments
