// FlipInternal: the pieces of ꟻLIP (Flip.h) that Flip.cpp, FlipColour.cpp, FlipFeatures.cpp and
// FlipExposure.cpp share, and that tests/experiments/compare/flip_test.cpp checks stage by stage.
// Not an interface for other code: include Flip.h.
//
// Everything here is float, as in the papers' reference implementation, whose per-pixel maps we
// reproduce to 1e-3 (README.md of ../shared/flip). The per-pixel functions are inline and free of
// branches (conditions are selects) so that GCC vectorises the row loops that call them; each
// lane computes exactly what the scalar call computes (IEEE operations only, no reassociation, no
// fused multiply-add under -ffp-contract=off), so results do not depend on vector width or on how
// rows are split between threads.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace experiments::compare::flip {

// ---- The papers' constants (HPG 2020, section 4; EGSR 2021, section 3) ----

// Exponent on the HyAB colour distance (qc) and on the feature difference (qf).
inline constexpr float kColourExponent = 0.7f;
inline constexpr float kFeatureExponent = 0.5f;
// The colour error is compressed piecewise-linearly: distances below kCutoffFraction * cmax map
// to [0, kCutoffError], the rest to [kCutoffError, 1] (pc and pt).
inline constexpr float kCutoffFraction = 0.4f;
inline constexpr float kCutoffError = 0.95f;
// Peak-to-trough width of the human edge detector, in degrees of visual angle (w); the feature
// filters' standard deviation is half of it.
inline constexpr float kFeatureWidthDegrees = 0.082f;
// HDR-ꟻLIP aims its exposures so that the tone mapper puts a luminance at this display value.
inline constexpr float kExposureTargetValue = 0.85f;

// The contrast sensitivity functions, as sums of two Gaussians a * sqrt(pi / b) *
// exp(-pi^2 x^2 / b) over visual angle x in degrees: achromatic, red-green, blue-yellow.
struct CsfGaussians {
    float a1, b1, a2, b2;
};
inline constexpr CsfGaussians kCsfAchromatic{1.0f, 0.0047f, 0.0f, 1.0e-5f};
inline constexpr CsfGaussians kCsfRedGreen{1.0f, 0.0053f, 0.0f, 1.0e-5f};
inline constexpr CsfGaussians kCsfBlueYellow{34.1f, 0.04f, 13.5f, 0.025f};
inline constexpr float kPi = 3.14159265358979f;

// ACES filmic tone mapper (Narkowicz's fit) as the rational (c0 x^2 + c1 x + c2) /
// (c3 x^2 + c4 x + c5), with its 0.6 pre-exposure folded into the coefficients as HDR-ꟻLIP does.
inline constexpr float kAces[6] = {0.6f * 0.6f * 2.51f, 0.6f * 0.03f, 0.0f,
                                   0.6f * 0.6f * 2.43f, 0.6f * 0.59f, 0.14f};

// ---- Colour spaces ----
//
// sRGB primaries, D65 white. The matrix is the exact rational one (Lindbloom via
// image-engineering.de, as in the reference implementation); its inverse is exact in double.

inline constexpr double kRgbToXyzDouble[3][3] = {
    {10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0},
    {2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0},
    {1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0}};

struct Matrix3 {
    float m[3][3];
};

constexpr Matrix3 toFloat(const double (&d)[3][3]) {
    Matrix3 out{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            out.m[i][j] = static_cast<float>(d[i][j]);
    return out;
}

constexpr Matrix3 inverseToFloat(const double (&a)[3][3]) {
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    double inv[3][3] = {
        {a[1][1] * a[2][2] - a[1][2] * a[2][1], a[0][2] * a[2][1] - a[0][1] * a[2][2],
         a[0][1] * a[1][2] - a[0][2] * a[1][1]},
        {a[1][2] * a[2][0] - a[1][0] * a[2][2], a[0][0] * a[2][2] - a[0][2] * a[2][0],
         a[0][2] * a[1][0] - a[0][0] * a[1][2]},
        {a[1][0] * a[2][1] - a[1][1] * a[2][0], a[0][1] * a[2][0] - a[0][0] * a[2][1],
         a[0][0] * a[1][1] - a[0][1] * a[1][0]}};
    for (auto& row : inv)
        for (double& v : row)
            v /= det;
    return toFloat(inv);
}

inline constexpr Matrix3 kRgbToXyz = toFloat(kRgbToXyzDouble);
inline constexpr Matrix3 kXyzToRgb = inverseToFloat(kRgbToXyzDouble);
// The white point: XYZ of linear RGB (1, 1, 1), i.e. the matrix's row sums (Y is 1 exactly).
inline constexpr double kWhiteXDouble = (10135552.0 + 8788810.0 + 4435075.0) / 24577794.0;
inline constexpr double kWhiteZDouble = (1425312.0 + 8788810.0 + 70074185.0) / 73733382.0;
inline constexpr float kWhite[3] = {static_cast<float>(kWhiteXDouble), 1.0f,
                                    static_cast<float>(kWhiteZDouble)};
inline constexpr float kInverseWhite[3] = {static_cast<float>(1.0 / kWhiteXDouble), 1.0f,
                                           static_cast<float>(1.0 / kWhiteZDouble)};
// Luminance weights of linear sRGB (Rec. 709), used only to place HDR-ꟻLIP's exposures.
inline constexpr float kLuminanceWeights[3] = {0.2126f, 0.7152f, 0.0722f};

inline void multiply(Matrix3 m, float a, float b, float c, float& x, float& y, float& z) {
    x = m.m[0][0] * a + m.m[0][1] * b + m.m[0][2] * c;
    y = m.m[1][0] * a + m.m[1][1] * b + m.m[1][2] * c;
    z = m.m[2][0] * a + m.m[2][1] * b + m.m[2][2] * c;
}

// Clamps through the bit patterns: non-negative floats order like their bit patterns read as
// int32, and every negative float reads as a negative int32. Integer min and max are plain
// operations for GCC, where a float select with a constant arm (v < 0 ? 0 : v) lets it thread
// jumps (fold the constant path into a branch of its own) and then not vectorise the loop.
inline float clampBits(float v, float lo, float hi) {
    const std::int32_t bits = std::bit_cast<std::int32_t>(v);
    const std::int32_t low = std::bit_cast<std::int32_t>(lo),
                       high = std::bit_cast<std::int32_t>(hi);
    return std::bit_cast<float>(std::min(std::max(bits, low), high));
}
// c ? a : b through bit masks. A plain ternary lets GCC sink the arms' arithmetic into branches
// of their own, which it then may not if-convert back (float operations may trap under the
// default -ftrapping-math), and the loop is not vectorised. Both arms are always computed.
inline float select(bool c, float a, float b) {
    const std::int32_t mask = -static_cast<std::int32_t>(c);
    return std::bit_cast<float>((std::bit_cast<std::int32_t>(a) & mask) |
                                (std::bit_cast<std::int32_t>(b) & ~mask));
}
// v clamped to [0, 1] (v not NaN).
inline float clamp01(float v) {
    return clampBits(v, 0.0f, 1.0f);
}
// max(v, lo) for lo >= 0 (v not NaN).
inline float atLeast(float v, float lo) {
    return clampBits(v, lo, 3.40282347e38f);
}

// Linear RGB -> YCxCz, the linearised CIELAB opponent space ꟻLIP filters in: Y = 116 y - 16,
// Cx = 500 (x - y), Cz = 200 (y - z) of white-normalised XYZ.
inline void linearRgbToYCxCz(float r, float g, float b, float& yy, float& cx, float& cz) {
    float x, y, z;
    multiply(kRgbToXyz, r, g, b, x, y, z);
    x *= kInverseWhite[0];
    z *= kInverseWhite[2];
    yy = 116.0f * y - 16.0f;
    cx = 500.0f * (x - y);
    cz = 200.0f * (y - z);
}

inline void yCxCzToLinearRgb(float yy, float cx, float cz, float& r, float& g, float& b) {
    const float y = (yy + 16.0f) / 116.0f;
    const float x = (y + cx / 500.0f) * kWhite[0];
    const float z = (y - cz / 200.0f) * kWhite[2];
    multiply(kXyzToRgb, x, y, z, r, g, b);
}

// ---- Fast, vectorisable transcendental functions ----
//
// glibc's cbrtf and powf are scalar calls; these are plain arithmetic on bit patterns and
// polynomials, so the per-pixel loops vectorise. Accuracy (tested against double std::cbrt and
// std::pow in flip_test.cpp): a few float ulps, far inside the 1e-3 contract.

// t^(1/3) for t in [1e-3, 2]: a bit-pattern guess (exponent divided by 3), two Halley steps.
inline float cubeRoot(float t) {
    // Dividing a float's bit pattern by three divides its exponent by three; the constant puts
    // the bias back (3 * 127 / 3 - 127 / 3) and centres the mantissa error at about 3%.
    const float third = static_cast<float>(std::bit_cast<std::int32_t>(t)) * (1.0f / 3.0f);
    float y = std::bit_cast<float>(static_cast<std::int32_t>(third) + 0x2a5137a0);
    for (int i = 0; i < 2; ++i) {
        const float y3 = y * y * y;
        y = y * (y3 + 2.0f * t) / (2.0f * y3 + t);
    }
    return y;
}

// log2(x) for normal x > 0 (and about -127 for 0 and subnormals: finite, never NaN).
inline float log2Positive(float x) {
    // x = m * 2^e with m in [sqrt(1/2), sqrt(2)); log(m) = 2 atanh(s), s = (m - 1) / (m + 1),
    // |s| <= 0.172, by its odd series to s^11 (next term below 1e-10).
    constexpr std::int32_t kSqrtHalfBits = 0x3f3504f3;
    const std::int32_t bits = std::bit_cast<std::int32_t>(x);
    const std::int32_t e = (bits - kSqrtHalfBits) >> 23;
    const float m =
        std::bit_cast<float>(bits - static_cast<std::int32_t>(static_cast<std::uint32_t>(e) << 23));
    const float s = (m - 1.0f) / (m + 1.0f);
    const float s2 = s * s;
    const float series =
        1.0f +
        s2 * (1.0f / 3.0f +
              s2 * (1.0f / 5.0f + s2 * (1.0f / 7.0f + s2 * (1.0f / 9.0f + s2 * (1.0f / 11.0f)))));
    constexpr float kTwoOverLn2 = 2.88539008177792681f;
    return static_cast<float>(e) + s * series * kTwoOverLn2;
}

// 2^z for z in [-127, 127]; 0 below -126.5 (callers need no subnormals). No clamp: a clamp's
// constant arm would cost the loops their vectorisation (see clampBits), and the callers' z stay
// in range (powNonNegative's z = y log2 x with y in [0, 1] and log2 x in [-127, 128)).
inline float exp2InRange(float z) {
    // Round to nearest by the 1.5 * 2^23 trick (plain float adds: vectorises without SSE4.1's
    // round, and -ffp-contract=off / no -ffast-math keep the compiler from folding it).
    constexpr float kRound = 12582912.0f;
    const float n = (z + kRound) - kRound;
    const float u = (z - n) * 0.693147180559945309f; // |u| <= ln(2) / 2
    // e^u by Taylor to u^7: remainder below 6e-9 relative on |u| <= 0.347.
    const float p =
        1.0f +
        u * (1.0f +
             u * (1.0f / 2.0f +
                  u * (1.0f / 6.0f +
                       u * (1.0f / 24.0f +
                            u * (1.0f / 120.0f + u * (1.0f / 720.0f + u * (1.0f / 5040.0f)))))));
    // n = -127 gives the bit pattern of +0.
    const std::int32_t scaleBits = (static_cast<std::int32_t>(n) + 127) << 23;
    return p * std::bit_cast<float>(scaleBits);
}

// x^y for x in [0, 2^127], y in [0, 1], with std::pow's values at x = 0 (0, or 1 when y = 0).
// log2Positive reads 0 as 2^-127 and a subnormal as about that, so no clamp is needed; results
// below 2^-126 come out 0 or about 2^-127, which is 0 for every purpose here.
inline float powNonNegative(float x, float y) {
    const float r = exp2InRange(y * log2Positive(x));
    return select(x > 0.0f, r, select(y > 0.0f, 0.0f, 1.0f));
}

// ---- The colour pipeline (FlipColour.cpp) ----

// CIELAB f(t): the cube root above (6/29)^3, the linear segment below.
inline float labF(float t) {
    constexpr float kDelta = 6.0f / 29.0f;
    constexpr float kDeltaCube = kDelta * kDelta * kDelta;
    const float linear = t * (1.0f / (3.0f * kDelta * kDelta)) + 4.0f / 29.0f;
    const float root = cubeRoot(atLeast(t, kDeltaCube));
    return select(t > kDeltaCube, root, linear);
}

// Linear RGB -> CIELAB with the Hunt effect applied to the chroma: (L, 0.01 L a, 0.01 L b).
inline void linearRgbToHuntLab(float r, float g, float b, float& l, float& ha, float& hb) {
    float x, y, z;
    multiply(kRgbToXyz, r, g, b, x, y, z);
    const float fx = labF(x * kInverseWhite[0]);
    const float fy = labF(y);
    const float fz = labF(z * kInverseWhite[2]);
    l = 116.0f * fy - 16.0f;
    ha = 0.01f * l * (500.0f * (fx - fy));
    hb = 0.01f * l * (200.0f * (fy - fz));
}

// HyAB: city-block lightness difference plus Euclidean chroma difference.
inline float hyab(float l1, float a1, float b1, float l2, float a2, float b2) {
    const float da = a1 - a2, db = b1 - b2;
    return std::fabs(l1 - l2) + std::sqrt(da * da + db * db);
}

// cmax: the HyAB distance between Hunt-adjusted green and blue, raised to kColourExponent.
float maxColourDistance();

// The colour error's compression: d = HyAB^qc in [0, cmax] -> [0, 1], linear with slope
// pt / (pc cmax) up to pc cmax, then linear from pt to 1 at cmax.
inline float redistributeColourError(float d, float cmax) {
    const float cut = kCutoffFraction * cmax;
    const float below = d * (kCutoffError / cut);
    const float above = kCutoffError + ((d - cut) / (cmax - cut)) * (1.0f - kCutoffError);
    return select(d < cut, below, above);
}

// ---- Filters (FlipColour.cpp, FlipFeatures.cpp) ----

// A one-dimensional kernel, taps[0] at offset -radius.
struct Kernel1d {
    int radius = 0;
    std::vector<float> taps;
};

// The separable contrast sensitivity filters at `ppd` pixels per degree: the 2D filter of each
// channel is the outer product of a 1D kernel with itself (the blue-yellow one a sum of two such
// products), normalised so that the 2D filter sums to 1. All share one radius: 3 standard
// deviations of the widest Gaussian.
struct CsfKernels {
    Kernel1d achromatic, redGreen, blueYellow1, blueYellow2;
};
CsfKernels makeCsfKernels(float ppd);
int csfRadius(float ppd);

// The feature detectors at `ppd`: a Gaussian of standard deviation 0.5 w ppd pixels, its first
// derivative (edges) and its second (points), each with positive weights summing to 1 and
// negative weights to -1 (the Gaussian to 1). The 2D edge detector in x is derivative(x)
// gaussian(y), and so on.
struct FeatureKernels {
    Kernel1d gaussian, firstDerivative, secondDerivative;
};
FeatureKernels makeFeatureKernels(float ppd);

// ---- Exposures (FlipExposure.cpp) ----

// The tone mapper with its clamp to [0, 1], on a channel v >= 0 already multiplied by
// 2^exposure. Above about 1.8e19, v^2 overflows and the quotient is inf / inf = NaN (or inf):
// the final select maps both to 1, the tone mapper's limit c0 / c3 = 1.033 clamped. (A clamp of
// v before the division would cost the loop its vectorisation, see clampBits.)
inline float toneMapAces(float v) {
    const float numerator = (v * v) * kAces[0] + v * kAces[1] + kAces[2];
    const float denominator = (v * v) * kAces[3] + v * kAces[4] + kAces[5];
    const float mapped = numerator / denominator;
    return select(mapped < 1.0f, mapped, 1.0f); // false for NaN
}

// The tone mapper's input that it maps to kExposureTargetValue (the larger root of its
// quadratic).
float toneMapperInputForTarget();

struct ExposureStatistics {
    float maxLuminance = 0.0f;
    float medianLuminance = 0.0f;    // what the exposures use (see usedPositiveMedian)
    bool usedPositiveMedian = false; // the median of all was 0: the median of positive ones
    bool fromTestImage = false;      // the reference had no positive luminance
    std::size_t pixelsCounted = 0;
};

// Luminance statistics of the pixels whose `valid` flag is set (all when `valid` is null), with
// negative channels read as 0. Returns false when no such pixel has positive luminance.
bool luminanceStatistics(const float* r, const float* g, const float* b, std::size_t count,
                         const unsigned char* valid, ExposureStatistics& out);

// An image's planes as the exposure statistics read them: `valid` (null: all) flags the pixels
// that count.
struct LuminanceSource {
    const float* r;
    const float* g;
    const float* b;
    std::size_t count;
    const unsigned char* valid;
};

struct ExposureBracket {
    float start = 0.0f, stop = 0.0f;
    int count = 0;
};

// HDR-ꟻLIP's exposures: those given, the rest from the reference's luminance (or the test's,
// when the reference has none that is positive; see Flip.h). Warnings say what was fallen back
// on. Throws std::invalid_argument for a non-finite exposure, start > stop, or a count below 1
// or above 1024 (given, or from a given range).
ExposureBracket exposureBracket(const LuminanceSource& reference, const LuminanceSource& test,
                                std::optional<float> givenStart, std::optional<float> givenStop,
                                std::optional<int> givenCount, std::vector<std::string>& warnings);

// ---- Pooling (FlipPooling.cpp) ----

struct PooledValues {
    double mean = 0.0, weightedMedian = 0.0, p95 = 0.0, p99 = 0.0, max = 0.0;
};
// The statistics of an error map of rows `width` long (values in [0, 1]; Flip.h defines each).
// Sums are taken per fixed block of rows, then the blocks in order: no thread-count dependence.
PooledValues poolValues(const std::vector<float>& map, int width);

} // namespace experiments::compare::flip
