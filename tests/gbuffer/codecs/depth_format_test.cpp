// DepthFormat and position reconstruction against closed forms: names, the projection's depth
// mapping and its inverse, CameraView's matrices, exact code round trips, the "covered never reads
// as background" rule, decoded view depth within each format's analytic bound, the two
// reconstruction methods against the exact position, and the reversed-Z test.
//
// Conventions: view depth d > 0 in metres; "float NDC" is the projection of the exact point
// through the float matrix, z / w in double, rounded once to float (what the rasterizer stores,
// see experiments/studies/DepthStudy.h); relative errors are |p' - p| / d. kEps = 2^-24 is float's
// unit roundoff (half an ulp at 1). Screen 1280x720, 60 degree vertical field of view throughout.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Imath/half.h>

#include "gbuffer/codecs/DepthFormat.h"
#include "gbuffer/visibility/CameraView.h"
#include "scenes/Scene.h"

namespace gbuffer {
void PrintTo(const DepthFormatSpec& spec, std::ostream* os) {
    *os << spec.text();
}
} // namespace gbuffer

namespace {

using gbuffer::CameraView;
using gbuffer::DepthConvention;
using gbuffer::DepthFormatKind;
using gbuffer::DepthFormatSpec;
using gbuffer::DepthProjection;
using gbuffer::PositionMethod;

constexpr double kEps = 0x1.0p-24;
constexpr int kWidth = 1280;
constexpr int kHeight = 720;
constexpr double kFovYRadians = 60.0 * 3.14159265358979323846 / 180.0;
// Float arithmetic of a decode: five roundings (1 - z, f - n, product, sum, n f, quotient) of
// 2^-24 each, first order; 8 leaves slack for the second-order terms.
constexpr double kDecodeArithmetic = 8.0 * kEps;

struct Planes {
    float nearMetres;
    float farMetres;
};
constexpr Planes kCameras[] = {
    {0.01f, 100.0f}, {0.1f, 1000.0f}, {0.1f, 10000.0f}, {1.0f, 10000.0f}};

CameraView viewOf(Planes planes, DepthConvention convention, bool infinite) {
    scenes::Camera camera; // origin, looking down -Z
    camera.verticalFovRadians = float(kFovYRadians);
    camera.nearMetres = planes.nearMetres;
    camera.farMetres = planes.farMetres;
    return CameraView::fromCamera(camera, kWidth, kHeight, convention, infinite);
}

CameraView viewOf(Planes planes, const DepthFormatSpec& format) {
    return viewOf(planes, format.convention(), format.infiniteFar);
}

// n (1 + 1e-6) .. f (1 - 1e-6), log-spaced: just inside both planes (on a plane, rounding decides
// whether the surface is clipped).
std::vector<double> logDistances(double from, double to, int count) {
    from *= 1.0 + 1e-6;
    to *= 1.0 - 1e-6;
    std::vector<double> d;
    for (int i = 0; i < count; ++i)
        d.push_back(from * std::pow(to / from, double(i) / (count - 1)));
    return d;
}

// The exact view-space point at depth d through pixel (x, y)'s centre.
glm::dvec3 exactPoint(int x, int y, double d) {
    const double tanHalf = std::tan(double(float(kFovYRadians)) / 2.0);
    const double ndcX = (x + 0.5) / kWidth * 2.0 - 1.0, ndcY = 1.0 - (y + 0.5) / kHeight * 2.0;
    return {ndcX * d * tanHalf * kWidth / kHeight, ndcY * d * tanHalf, -d};
}

float rasterNdc(const CameraView& view, const glm::dvec3& p) {
    const glm::dvec4 clip = glm::dmat4(view.clipFromView) * glm::dvec4(p, 1.0);
    return float(clip.z / clip.w);
}

std::vector<glm::ivec2> pixelGrid() { // 9 x 5 pixels, corners included
    std::vector<glm::ivec2> pixels;
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 9; ++i)
            pixels.push_back({i * (kWidth - 1) / 8, j * (kHeight - 1) / 4});
    return pixels;
}

glm::vec3 reconstruct(const DepthFormatSpec& format, const CameraView& view, PositionMethod method,
                      glm::ivec2 pixel, float depthNdc) {
    const DepthProjection projection = DepthProjection::of(view);
    const uint32_t code = gbuffer::encodeDepth(format, projection, depthNdc);
    const glm::vec2 ndc = view.ndcOfPixel(pixel.x, pixel.y);
    if (method == PositionMethod::InverseProjection)
        return gbuffer::positionByInverseProjection(
            view, ndc, gbuffer::decodeDepthNdc(format, projection, code));
    return gbuffer::positionByViewRay(view, ndc,
                                      gbuffer::decodeViewDepth(format, projection, code));
}

struct ErrorStats {
    double maxRelative = 0.0;
    int lost = 0; // float NDC equal to the clear value or outside [0, 1]: reads as background
};

ErrorStats positionError(const DepthFormatSpec& format, Planes planes, PositionMethod method,
                         const std::vector<double>& distances) {
    const CameraView view = viewOf(planes, format);
    ErrorStats stats;
    for (double d : distances)
        for (glm::ivec2 pixel : pixelGrid()) {
            const glm::dvec3 p = exactPoint(pixel.x, pixel.y, d);
            const float z = rasterNdc(view, p);
            if (!(z >= 0.0f && z <= 1.0f) || z == view.clearDepth()) {
                ++stats.lost;
                continue;
            }
            const glm::dvec3 got(reconstruct(format, view, method, pixel, z));
            stats.maxRelative = std::max(stats.maxRelative, glm::length(got - p) / d);
        }
    return stats;
}

// ---- names -----------------------------------------------------------------------------------

TEST(DepthFormatNames, TextParsesBackToTheSameSpec) {
    const std::vector<DepthFormatSpec> specs = gbuffer::allDepthFormatSpecs();
    ASSERT_EQ(specs.size(), 10u);
    for (const DepthFormatSpec& spec : specs) {
        EXPECT_EQ(DepthFormatSpec::parse(spec.text()), spec) << spec.text();
        EXPECT_EQ(spec.text().ends_with(":infinite"), spec.infiniteFar) << spec.text();
    }
    EXPECT_EQ(
        gbuffer::depthFormatNames(),
        (std::vector<std::string>{"f32", "f32-reversed", "unorm24", "unorm16", "f16-linear"}));
    EXPECT_EQ(DepthFormatSpec::parse("unorm24").bits(), 24);
    EXPECT_EQ(DepthFormatSpec::parse("unorm16:infinite").bits(), 16);
    EXPECT_EQ(DepthFormatSpec::parse("f16-linear").bits(), 16);
    EXPECT_EQ(DepthFormatSpec::parse("f32").convention(), DepthConvention::Standard);
    EXPECT_EQ(DepthFormatSpec::parse("f32-reversed").convention(), DepthConvention::Reversed);
    for (PositionMethod m : {PositionMethod::InverseProjection, PositionMethod::ViewRay})
        EXPECT_EQ(gbuffer::parsePositionMethod(gbuffer::positionMethodName(m)), m);
}

std::string parseError(const std::string& text) {
    try {
        DepthFormatSpec::parse(text);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(DepthFormatNames, BadNamesGiveOneMessageListingTheValidNames) {
    for (const char* bad : {"f64", "F32", "", ":infinite", "unorm32:infinite"}) {
        const std::string message = parseError(bad);
        EXPECT_NE(message.find("unknown depth format '" + std::string(bad) + "'"),
                  std::string::npos)
            << message;
        EXPECT_NE(message.find("f32, f32-reversed, unorm24, unorm16, f16-linear"),
                  std::string::npos)
            << message;
    }
    for (const char* bad : {"f32:finite", "f32:", "f32:infinite:infinite"})
        EXPECT_NE(parseError(bad).find("the only option is ':infinite'"), std::string::npos)
            << parseError(bad);
    EXPECT_THROW(gbuffer::parsePositionMethod("ray"), std::invalid_argument);
}

// ---- the projection --------------------------------------------------------------------------

struct ProjectionCase {
    bool reversed;
    bool infinite;
};
constexpr ProjectionCase kProjections[] = {
    {false, false}, {true, false}, {false, true}, {true, true}};

TEST(DepthProjection, ViewDepthFromNdcInvertsNdcFromViewDepth) {
    for (const Planes& planes : kCameras)
        for (const ProjectionCase& c : kProjections) {
            const DepthProjection projection{planes.nearMetres, planes.farMetres, c.infinite,
                                             c.reversed};
            const double farEnd = c.infinite ? 1e3 * planes.farMetres : planes.farMetres;
            for (double d : logDistances(planes.nearMetres, farEnd, 500)) {
                const double z = projection.ndcFromViewDepth(d);
                EXPECT_GE(z, 0.0);
                EXPECT_LE(z, 1.0);
                // Standard Z stores 1 - n/d: even in double its inverse loses d/n ulps (the
                // collapse this file is about, at 2^-53 instead of 2^-24).
                const double tolerance =
                    1e-14 + (c.reversed ? 0.0 : 4.0 * 0x1.0p-53 * d / planes.nearMetres);
                EXPECT_NEAR(projection.viewDepthFromNdc(z), d, tolerance * d)
                    << "reversed " << c.reversed << " infinite " << c.infinite << " d " << d;
            }
            // The planes land on 0 and 1.
            const double nearNdc = c.reversed ? 1.0 : 0.0;
            EXPECT_NEAR(projection.ndcFromViewDepth(planes.nearMetres), nearNdc, 1e-15);
            if (!c.infinite) {
                EXPECT_NEAR(projection.ndcFromViewDepth(planes.farMetres), 1.0 - nearNdc, 1e-15);
            }
            EXPECT_EQ(projection.clearDepthNdc(), c.reversed ? 0.0f : 1.0f);
        }
}

// The float inverse costs a few roundings, relative, for EVERY z: in particular no cancellation
// near the far plane in standard Z (the textbook n f / (f - z (f - n)) loses 0.4% at z = 1 on a
// 0.1/10000 camera, the float rounding of f - n alone).
TEST(DepthProjection, FloatInverseIsAccurateToAFewRoundingsEverywhere) {
    for (const Planes& planes : kCameras)
        for (const ProjectionCase& c : kProjections) {
            const DepthProjection projection{planes.nearMetres, planes.farMetres, c.infinite,
                                             c.reversed};
            double worst = 0.0;
            std::vector<float> zs;
            for (int i = 1; i < 4096; ++i)
                zs.push_back(float(i) / 4096.0f);
            for (int k = 1; k < 2000; ++k) { // the last float ulps on both ends
                zs.push_back(std::nextafter(1.0f, 0.0f) - float(k) * 0x1.0p-24f);
                zs.push_back(float(k) * std::numeric_limits<float>::denorm_min() * 1e6f);
            }
            for (float z : zs) {
                if (z <= 0.0f || z >= 1.0f)
                    continue;
                const double exact = projection.viewDepthFromNdc(double(z));
                const double got = projection.viewDepthFromNdcFloat(z);
                if (!std::isfinite(exact) || exact > 1e30)
                    continue;
                worst = std::max(worst, std::abs(got - exact) / exact);
            }
            EXPECT_LE(worst, kDecodeArithmetic)
                << planes.nearMetres << "/" << planes.farMetres << " reversed " << c.reversed
                << " infinite " << c.infinite;
        }
}

TEST(FrameViewDepth, MatricesAgreeWithDepthProjection) {
    for (const Planes& planes : kCameras)
        for (const ProjectionCase& c : kProjections) {
            const CameraView view =
                viewOf(planes, c.reversed ? DepthConvention::Reversed : DepthConvention::Standard,
                       c.infinite);
            const DepthProjection projection = DepthProjection::of(view);
            EXPECT_EQ(projection.reversed, c.reversed);
            EXPECT_EQ(projection.infiniteFar, c.infinite);
            EXPECT_EQ(projection.nearMetres, double(planes.nearMetres));
            const glm::dmat4 clipFromViewExact = glm::inverse(view.viewFromClipExact);
            const double farEnd = c.infinite ? 1e3 * planes.farMetres : planes.farMetres;
            for (double d : logDistances(planes.nearMetres, farEnd, 200))
                for (glm::ivec2 pixel :
                     {glm::ivec2(0, 0), glm::ivec2(640, 360), glm::ivec2(1279, 719)}) {
                    const glm::dvec3 p = exactPoint(pixel.x, pixel.y, d);
                    const double expected = projection.ndcFromViewDepth(d);
                    const glm::dvec4 exactClip = clipFromViewExact * glm::dvec4(p, 1.0);
                    EXPECT_NEAR(exactClip.z / exactClip.w, expected, 1e-12);
                    EXPECT_NEAR(exactClip.w, d, 1e-12 * d);
                    // The float matrix: entries rounded (2^-24 relative each), so z / w moves by
                    // at most ~2 kEps (|m22 d| + |m32| <= 2 d for both conventions) plus one more
                    // for safety.
                    EXPECT_NEAR(rasterNdc(view, p), expected, 4.0 * kEps)
                        << "d " << d << " reversed " << c.reversed << " infinite " << c.infinite;
                    // x, y of the exact point project to the pixel centre; the view ray there
                    // (times d) is the point.
                    const glm::vec3 ray =
                        gbuffer::viewRayOfNdc(view, view.ndcOfPixel(pixel.x, pixel.y));
                    EXPECT_NEAR(glm::length(glm::dvec3(ray) * d - p) / d, 0.0, 4.0 * kEps);
                }
        }
}

// ---- codes -----------------------------------------------------------------------------------

DepthProjection projectionOf(const DepthFormatSpec& format, Planes planes = {0.1f, 10000.0f}) {
    return DepthProjection::of(viewOf(planes, format));
}

TEST(DepthCodes, UnormCodesRoundTripExactly) {
    for (DepthFormatKind kind : {DepthFormatKind::Unorm16, DepthFormatKind::Unorm24})
        for (bool infinite : {false, true})
            for (bool reversed : {false, true}) { // unorm is standard, but works either way
                const DepthFormatSpec format{kind, infinite};
                DepthProjection projection = projectionOf(format);
                projection.reversed = reversed;
                const uint32_t max = (1u << format.bits()) - 1u;
                uint32_t mismatches = 0;
                for (uint32_t code = 0; code <= max; ++code) {
                    const float z = gbuffer::decodeDepthNdc(format, projection, code);
                    mismatches += gbuffer::encodeDepth(format, projection, z) != code;
                }
                EXPECT_EQ(mismatches, 0u) << format.text() << " reversed " << reversed;
                EXPECT_EQ(gbuffer::clearDepthCode(format, projection), reversed ? 0u : max);
            }
}

TEST(DepthCodes, Float32IsBitExact) {
    for (const char* name : {"f32", "f32-reversed", "f32:infinite", "f32-reversed:infinite"}) {
        const DepthFormatSpec format = DepthFormatSpec::parse(name);
        const DepthProjection projection = projectionOf(format);
        // Every 4099th float in [0, 1], both ends included.
        std::vector<uint32_t> bits{0u, 1u, 0x3F800000u, 0x3F7FFFFFu};
        for (uint32_t b = 0; b < 0x3F800000u; b += 4099u)
            bits.push_back(b);
        for (uint32_t b : bits) {
            const float z = std::bit_cast<float>(b);
            const uint32_t code = gbuffer::encodeDepth(format, projection, z);
            EXPECT_EQ(code, b) << name;
            EXPECT_EQ(std::bit_cast<uint32_t>(gbuffer::decodeDepthNdc(format, projection, code)),
                      b);
        }
        EXPECT_EQ(gbuffer::clearDepthCode(format, projection),
                  std::bit_cast<uint32_t>(projection.clearDepthNdc()));
        // -0.0 == 0.0: it is the reversed clear value, so it gets the clear code, not a second one.
        if (projection.reversed) {
            EXPECT_EQ(gbuffer::encodeDepth(format, projection, -0.0f),
                      gbuffer::clearDepthCode(format, projection));
        }
    }
}

TEST(DepthCodes, HalfLinearCodesRoundTripExactly) {
    for (const char* name : {"f16-linear", "f16-linear:infinite"}) {
        const DepthFormatSpec format = DepthFormatSpec::parse(name);
        for (const Planes& planes : kCameras) {
            const DepthProjection projection = projectionOf(format, planes);
            int checked = 0;
            for (uint32_t code = 0; code <= 0x7BFFu; ++code) {
                Imath::half h;
                h.setBits(uint16_t(code));
                const double d = double(float(h));
                if (d <= projection.nearMetres ||
                    (!format.infiniteFar && d >= projection.farMetres))
                    continue; // in front of the near plane or behind the far plane: clipped
                ++checked;
                EXPECT_EQ(gbuffer::decodeViewDepth(format, projection, code), float(h));
                const float z = gbuffer::decodeDepthNdc(format, projection, code);
                ASSERT_EQ(gbuffer::encodeDepth(format, projection, z), code)
                    << name << " " << planes.nearMetres << "/" << planes.farMetres << " d " << d;
            }
            EXPECT_GT(checked, 1000);
        }
    }
}

// A covered pixel never becomes background: values one float step off the clear value, or
// quantising onto it, keep a code one step nearer.
TEST(DepthCodes, CoveredPixelsNeverEncodeToTheClearCode) {
    for (const DepthFormatSpec& format : gbuffer::allDepthFormatSpecs())
        for (const Planes& planes : kCameras) {
            const DepthProjection projection = projectionOf(format, planes);
            const uint32_t clear = gbuffer::clearDepthCode(format, projection);
            const float clearNdc = projection.clearDepthNdc();
            EXPECT_EQ(gbuffer::encodeDepth(format, projection, clearNdc), clear) << format.text();
            // NDC depths from the clear value inwards, 1, 2, 4, ... float steps.
            for (float step = std::numeric_limits<float>::denorm_min(); step < 0.1f; step *= 2.0f) {
                const float z = projection.reversed ? clearNdc + step : clearNdc - step;
                if (z == clearNdc)
                    continue; // 1 - denorm_min rounds back to 1
                EXPECT_NE(gbuffer::encodeDepth(format, projection, z), clear)
                    << format.text() << " " << planes.nearMetres << "/" << planes.farMetres << " z "
                    << z;
            }
        }
    // Depth right at the far plane in unorm: one code nearer, not the clear code.
    for (DepthFormatKind kind : {DepthFormatKind::Unorm24, DepthFormatKind::Unorm16}) {
        const DepthFormatSpec format{kind, false};
        const DepthProjection projection = projectionOf(format);
        const uint32_t max = (1u << format.bits()) - 1u;
        EXPECT_EQ(gbuffer::encodeDepth(format, projection, std::nextafter(1.0f, 0.0f)), max - 1u);
    }
    // f16-linear beyond 65504 m (infinite far plane): the largest finite half, not Inf (= clear).
    const DepthFormatSpec half = DepthFormatSpec::parse("f16-linear:infinite");
    const DepthProjection projection = projectionOf(half);
    for (double d : {65504.0, 70000.0, 1e6, 1e12}) {
        const float z = float(projection.ndcFromViewDepth(d));
        const uint32_t code = gbuffer::encodeDepth(half, projection, z);
        EXPECT_NE(code, gbuffer::clearDepthCode(half, projection));
        EXPECT_EQ(gbuffer::decodeViewDepth(half, projection, code), 65504.0f) << d;
    }
    // NDC past the near plane (reversed, > 1) or wildly behind the far plane (< 0, negative linear
    // depth) saturates to the near end, never to the far end.
    const DepthProjection finite = projectionOf(DepthFormatSpec::parse("f16-linear"));
    for (float z : {1.0000001f, 1.5f, -0.5f})
        EXPECT_LE(gbuffer::decodeViewDepth(
                      DepthFormatSpec::parse("f16-linear"), finite,
                      gbuffer::encodeDepth(DepthFormatSpec::parse("f16-linear"), finite, z)),
                  finite.nearMetres * 1.001)
            << z;
}

// ---- accuracy --------------------------------------------------------------------------------

// Analytic bound of |decodeViewDepth - d| / d for a surface at d whose float NDC is z:
// - f16-linear: half rounding (2^-11 relative) plus the NDC rounding on the way in (reversed Z:
//   relative sensitivity <= 1, so 2^-24) and the float decode;
// - NDC formats: the exact inverse over the quantisation interval z +- dz, plus the float decode.
//   dz: f32 one ulp of z (the rasterizer's rounding is half an ulp); unorm half a step (1.5 steps
//   for the code clamped off the clear value) plus the float roundings of the input and of the
//   decoded NDC value (2^-25 each).
double decodeBound(const DepthFormatSpec& format, const DepthProjection& projection, double d,
                   float z, uint32_t code) {
    if (format.kind == DepthFormatKind::F16Linear)
        return 0x1.0p-11 + 2.0 * kEps + kDecodeArithmetic;
    double dz = 0.0;
    if (format.kind == DepthFormatKind::F32 || format.kind == DepthFormatKind::F32Reversed) {
        dz = double(std::nextafter(z, 2.0f)) - double(z);
    } else {
        const double max = double((1u << format.bits()) - 1u);
        const bool clamped = code == 1u || code == uint32_t(max) - 1u;
        dz = (clamped ? 1.5 : 0.5) / max + 2.0 * 0x1.0p-25;
    }
    double worst = 0.0;
    for (double s : {-1.0, 1.0}) {
        const double zq = std::clamp(double(z) + s * dz, 0.0, 1.0);
        const double dq = projection.viewDepthFromNdc(zq);
        worst = std::max(worst, std::isfinite(dq) ? std::abs(dq - d) / d : 1e300);
    }
    return worst * (1.0 + 1e-6) + kDecodeArithmetic;
}

TEST(DepthAccuracy, DecodedViewDepthIsWithinEachFormatsAnalyticBound) {
    for (const DepthFormatSpec& format : gbuffer::allDepthFormatSpecs()) {
        double worstRatio = 0.0, worstError = 0.0;
        for (const Planes& planes : kCameras) {
            const CameraView view = viewOf(planes, format);
            const DepthProjection projection = DepthProjection::of(view);
            for (double d : logDistances(planes.nearMetres, planes.farMetres, 2000)) {
                if (format.kind == DepthFormatKind::F16Linear && d > 65504.0)
                    continue;
                const float z = float(projection.ndcFromViewDepth(d));
                if (z == projection.clearDepthNdc())
                    continue; // lost: the far-plane band
                const uint32_t code = gbuffer::encodeDepth(format, projection, z);
                const double got = gbuffer::decodeViewDepth(format, projection, code);
                const double error = std::abs(got - d) / d;
                const double bound = decodeBound(format, projection, d, z, code);
                ASSERT_LE(error, bound) << format.text() << " " << planes.nearMetres << "/"
                                        << planes.farMetres << " d " << d << " code " << code;
                worstRatio = std::max(worstRatio, error / bound);
                worstError = std::max(worstError, error);
            }
        }
        std::printf("  %-22s max relative view-depth error %.3g (%.0f%% of its bound)\n",
                    format.text().c_str(), worstError, 100.0 * worstRatio);
        EXPECT_GT(worstRatio, 0.05) << format.text() << ": the bound is far too loose to mean much";
    }
}

TEST(DepthAccuracy, BothMethodsGiveTheExactPositionWithReversedFloatDepth) {
    for (const char* name : {"f32-reversed", "f32-reversed:infinite"})
        for (const Planes& planes : kCameras)
            for (PositionMethod method :
                 {PositionMethod::InverseProjection, PositionMethod::ViewRay}) {
                const ErrorStats stats =
                    positionError(DepthFormatSpec::parse(name), planes, method,
                                  logDistances(planes.nearMetres, planes.farMetres, 100));
                EXPECT_EQ(stats.lost, 0) << name;
                // Measured ~2e-7: a handful of float roundings, times the corner ray's length 1.55.
                EXPECT_LE(stats.maxRelative, 1e-6)
                    << name << " " << gbuffer::positionMethodName(method) << " "
                    << planes.nearMetres << "/" << planes.farMetres;
            }
}

// The test: on the 0.1/10000 camera, reversed-Z float32 depth reconstructs the position
// near the far plane at least 10x more accurately than standard float32 (measured: ~1e4x).
TEST(DepthAccuracy, ReversedFloatBeatsStandardFloatTenfoldAtTheFarPlane) {
    const Planes planes{0.1f, 10000.0f};
    // The last 10% before the far plane, short of the ~30 m band where standard float NDC depth
    // rounds to exactly 1 (the clear value) and the surface is lost altogether.
    const std::vector<double> distances = logDistances(9000.0, 9950.0, 50);
    for (PositionMethod method : {PositionMethod::InverseProjection, PositionMethod::ViewRay}) {
        const ErrorStats standard =
            positionError(DepthFormatSpec::parse("f32"), planes, method, distances);
        const ErrorStats reversed =
            positionError(DepthFormatSpec::parse("f32-reversed"), planes, method, distances);
        std::printf("  %-18s at 9000..9950 m: f32 %.3g, f32-reversed %.3g (%.0fx)\n",
                    gbuffer::positionMethodName(method), standard.maxRelative, reversed.maxRelative,
                    standard.maxRelative / reversed.maxRelative);
        EXPECT_EQ(standard.lost, 0);
        EXPECT_EQ(reversed.lost, 0);
        EXPECT_GE(standard.maxRelative, 10.0 * reversed.maxRelative)
            << gbuffer::positionMethodName(method);
        EXPECT_GT(standard.maxRelative, 1e-4); // the collapse is real, not a tiny test artefact
    }
}

// The collapse itself: in the last ~0.3% before the far plane of a 0.1/10000 camera, standard
// float NDC depth is exactly 1, the clear value: the surface is not drawn at all. Reversed Z
// keeps every one of those depths distinct from its clear value.
TEST(DepthAccuracy, StandardFloatLosesSurfacesJustBeforeTheFarPlane) {
    const Planes planes{0.1f, 10000.0f};
    const CameraView standard = viewOf(planes, DepthConvention::Standard, false);
    const CameraView reversed = viewOf(planes, DepthConvention::Reversed, false);
    for (double d : {9990.0, 9999.0, 9999.9}) {
        EXPECT_EQ(rasterNdc(standard, {0.0, 0.0, -d}), 1.0f) << d;
        EXPECT_GT(rasterNdc(reversed, {0.0, 0.0, -d}), 0.0f) << d;
    }
    EXPECT_LT(rasterNdc(standard, {0.0, 0.0, -9000.0}), 1.0f);
}

} // namespace
