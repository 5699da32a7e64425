// NormalCodec implementation. Every codec first turns its input into a unit double vector
// (unitOrFallback) and does its maths in double, so the only float rounding is the final cast of
// the decoded direction; the quantisation error then dominates even at 16 bits per component.
// Singular points of each map (poles, -Z, folds) are handled with atan2/tan forms and explicit
// clamps instead of the shader formulas of the papers, which divide by zero there.
#include "gbuffer/codecs/NormalCodec.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "scenes/input/ClosestName.h"

namespace gbuffer {

namespace {

constexpr double kPi = std::numbers::pi;
// The thesis' stereographic scale: maps |a| <= 1.7777 (z >= -0.519) into the stored square, trading
// precision for back-facing normals that perspective still shows.
constexpr double kStereographicScale = 1.7777;
// Best-fit normals store RGB8 SNORM: integer vectors in [-127, 127]^3.
constexpr int kBestFitComponentMax = 127;

struct CodecInfo {
    NormalCodecKind kind;
    const char* name;
    std::vector<int> bits;
};

const std::vector<CodecInfo>& codecTable() {
    static const std::vector<CodecInfo> table = {
        {NormalCodecKind::Float32, "float32", {96}},
        {NormalCodecKind::Xyz, "xyz", {24, 30, 48}},
        {NormalCodecKind::XyReconstructZ, "xy-z", {16, 20, 24, 32}},
        {NormalCodecKind::Spherical, "spherical", {16, 20, 24, 32}},
        {NormalCodecKind::Spheremap, "spheremap", {16, 20, 24, 32}},
        {NormalCodecKind::Stereographic, "stereographic", {16, 20, 24, 32}},
        {NormalCodecKind::StereographicScaled, "stereographic-scaled", {16, 20, 24, 32}},
        {NormalCodecKind::PixelView, "pixel-view", {16, 20, 24, 32}},
        {NormalCodecKind::BestFit, "best-fit", {24}},
        {NormalCodecKind::Octahedral, "octahedral", {16, 20, 24, 32}},
        {NormalCodecKind::OctahedralPrecise, "octahedral-precise", {16, 20, 24, 32}},
    };
    return table;
}

const CodecInfo& codecInfo(NormalCodecKind kind) {
    for (const CodecInfo& info : codecTable())
        if (info.kind == kind)
            return info;
    throw std::invalid_argument("unknown NormalCodecKind value");
}

// Bits per stored component; validates the spec (cheap switch, no allocation on the hot path).
int componentBits(const NormalCodecSpec& spec) {
    const int b = spec.bits;
    switch (spec.kind) {
    case NormalCodecKind::Float32:
        if (b == 96)
            return 32;
        break;
    case NormalCodecKind::Xyz:
        if (b == 24 || b == 30 || b == 48)
            return b / 3;
        break;
    case NormalCodecKind::BestFit:
        if (b == 24)
            return 8;
        break;
    default:
        if (b == 16 || b == 20 || b == 24 || b == 32)
            return b / 2;
        break;
    }
    throw std::invalid_argument("normal codec " + std::string(normalCodecName(spec.kind)) +
                                " does not support " + std::to_string(b) + " bits");
}

std::uint64_t fieldMask(int b) {
    return (std::uint64_t{1} << b) - 1;
}
std::uint64_t field(std::uint64_t code, int index, int b) {
    return (code >> (index * b)) & fieldMask(b);
}
std::int64_t snormMax(int b) {
    return (std::int64_t{1} << (b - 1)) - 1;
}

std::uint64_t quantizeSnorm(double v, int b) {
    const std::int64_t n = snormMax(b);
    v = std::isnan(v) ? 0.0 : std::clamp(v, -1.0, 1.0);
    return static_cast<std::uint64_t>(std::llround(v * static_cast<double>(n)) + n);
}
double dequantizeSnorm(std::uint64_t stored, int b) {
    const std::int64_t n = snormMax(b);
    // The one code above 2n (2^b - 1) is never written; saturate it like D3D SNORM does.
    const std::int64_t q = std::min<std::int64_t>(static_cast<std::int64_t>(stored), 2 * n) - n;
    return static_cast<double>(q) / static_cast<double>(n);
}
std::uint64_t pack2(std::uint64_t a, std::uint64_t c, int b) {
    return a | (c << b);
}

glm::dvec3 unitOrFallback(glm::vec3 v) {
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        return glm::dvec3(kFallbackNormalView);
    const glm::dvec3 d(v);
    // Squares of float values (<= 1.2e77, >= 2e-90 when nonzero) cannot overflow or vanish in
    // double, so subnormal and huge inputs normalise exactly enough.
    const double length = std::sqrt(glm::dot(d, d));
    if (!(length > 0.0))
        return glm::dvec3(kFallbackNormalView);
    return d / length;
}

glm::vec3 toUnitFloat(glm::dvec3 d) {
    const double length = std::sqrt(glm::dot(d, d));
    if (!(length > 0.0) || !std::isfinite(length))
        return kFallbackNormalView;
    return glm::vec3(d / length);
}

double signNotZero(double v) {
    return v >= 0.0 ? 1.0 : -1.0;
}

// Azimuthal direction of xy, with +X for the poles (any direction is right there).
glm::dvec2 azimuthDirection(const glm::dvec3& d, double& radius) {
    radius = std::hypot(d.x, d.y);
    return radius > 0.0 ? glm::dvec2(d.x, d.y) / radius : glm::dvec2(1.0, 0.0);
}

// --- octahedral -------------------------------------------------------------------------------

glm::dvec2 octahedralFromUnit(const glm::dvec3& d) {
    const double l1 = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
    glm::dvec2 p(d.x / l1, d.y / l1);
    if (d.z < 0.0) // fold the lower hemisphere onto the corners of the square
        p = glm::dvec2((1.0 - std::abs(p.y)) * signNotZero(p.x),
                       (1.0 - std::abs(p.x)) * signNotZero(p.y));
    return p;
}

glm::vec3 octahedralDecode(std::uint64_t code, int b) {
    const double px = dequantizeSnorm(field(code, 0, b), b);
    const double py = dequantizeSnorm(field(code, 1, b), b);
    glm::dvec3 n(px, py, 1.0 - std::abs(px) - std::abs(py));
    if (n.z < 0.0)
        n = glm::dvec3((1.0 - std::abs(py)) * signNotZero(px),
                       (1.0 - std::abs(px)) * signNotZero(py), n.z);
    return toUnitFloat(n);
}

std::uint64_t octahedralEncode(const glm::dvec3& d, int b) {
    const glm::dvec2 p = octahedralFromUnit(d);
    return pack2(quantizeSnorm(p.x, b), quantizeSnorm(p.y, b), b);
}

// Tries floor/ceil in both axes and keeps the code whose decoded float direction has the smallest
// normalAngleRadians to `reference` (compared in double). Plain rounding is one of the four and
// wins ties, so this is never worse than `octahedral` under that metric.
std::uint64_t octahedralPreciseEncode(const glm::dvec3& d, glm::vec3 reference, int b) {
    const glm::dvec2 p = octahedralFromUnit(d);
    const double n = static_cast<double>(snormMax(b));
    std::uint64_t best = pack2(quantizeSnorm(p.x, b), quantizeSnorm(p.y, b), b);
    double bestError = normalAngleRadians(reference, octahedralDecode(best, b));
    const double xs[2] = {std::floor(p.x * n), std::ceil(p.x * n)};
    const double ys[2] = {std::floor(p.y * n), std::ceil(p.y * n)};
    for (double x : xs) {
        for (double y : ys) {
            const std::uint64_t candidate =
                pack2(quantizeSnorm(x / n, b), quantizeSnorm(y / n, b), b);
            if (candidate == best)
                continue; // plain rounding, already measured
            const double error = normalAngleRadians(reference, octahedralDecode(candidate, b));
            if (error < bestError) {
                bestError = error;
                best = candidate;
            }
        }
    }
    return best;
}

// --- best-fit ---------------------------------------------------------------------------------

// Kaplanyan's best-fit normals: among integer vectors k in [-127,127]^3, store one pointing close
// to d. The candidates for a direction are, for each major-axis length m = 1..127, the vector
// d * m / |d_major| with its two minor components rounded. Folded by symmetry (absolute values,
// major axis first, the two minors sorted), a direction is the point (1, u, v) with
// 1 >= u >= v >= 0 (u, v = larger and smaller minor / major), and the best m depends on (u, v)
// only.
//
// Choice: Kaplanyan (CryEngine 3, SIGGRAPH 2010) / Hillaire's lookup table of the best length,
// indexed by (u, v), as the issue asks, and not a per-input search: the table costs one load and
// two candidates per encode instead of 128. Each cell stores the best m for the direction through
// its centre (ties: the longest m); a direction elsewhere in the cell reuses that m, so the
// table is worse than the per-direction search (bestFitEncodeBySearch, the tests' oracle) where
// the rounding residuals of u m and v m drift across the cell (by up to 127 / N in m units).
//
// Resolution N = 1024 cells per axis, Hillaire's published 1024 x 1024 layout, storing only its
// triangular half u >= v: N (N + 1) / 2 bytes = 512.5 KiB (one uint8 m per cell). Measured over
// 2e6 uniform directions (mean / max error in degrees): search 0.0305 / 0.302; N = 512 (128 KiB)
// 0.0448 / 0.311; N = 1024 0.0345 / 0.302; N = 2048 (2 MiB, 4x the build) 0.0315 / 0.302. 1024 is
// the knee: within 13 % of the search's mean at a size that still fits a per-core L2; doubling N
// buys 10 % more at 4x the memory, which random per-pixel lookups pay in cache misses.
//
// The naive candidate m = 127 (the minors rounded along the ray) is always compared as well, one
// extra dot product: it keeps the derived bound (see "Derived bounds") a proof for every input,
// whatever length the table chose, and means the table can never lose to plain RGB8 rounding
// along the ray.
constexpr int kBestFitTableResolution = 1024;
constexpr std::size_t kBestFitTableCellCount =
    std::size_t{kBestFitTableResolution} * (kBestFitTableResolution + 1) / 2;
static_assert(kBestFitComponentMax <= 255, "table cells store the length in one byte");

// Ranks candidate k against the direction d (any length, k . d > 0 for every candidate here) by
// cos^2 = (k.d)^2 / (k.k), compared by cross-multiplication: no division or sqrt.
struct BestFitCandidate {
    glm::dvec3 k;
    double dot = 0.0;     // k . d
    double length2 = 1.0; // k . k
    bool closerThan(const BestFitCandidate& other) const {
        return dot * dot * other.length2 > other.dot * other.dot * length2;
    }
};

// The candidate of major length m for the folded ray r = |d| / |d_major| (so r[major] == 1),
// signs restored from d. nearbyint is one SSE4.1 instruction; its tie rule does not matter for a
// candidate. copysign keeps -0 for negative zero minors (stored as 127 all the same).
BestFitCandidate bestFitCandidate(const glm::dvec3& d, const glm::dvec3& r, int m) {
    BestFitCandidate c;
    for (int i = 0; i < 3; ++i)
        c.k[i] = std::copysign(std::nearbyint(r[i] * m), d[i]);
    c.dot = glm::dot(c.k, d);
    c.length2 = glm::dot(c.k, c.k);
    return c;
}

// Best major length for the folded direction (1, u, v) over m = 1..127. Ties are multiples of
// one direction (e.g. (1, 0, 0) and (127, 0, 0)): keep the longest, as the search does (it starts
// from the naive round(127 d)), so both store the axes as (0, 0, +-127).
int bestFitLengthBySearch(double u, double v) {
    const glm::dvec3 ray(1.0, u, v);
    BestFitCandidate best = bestFitCandidate(ray, ray, kBestFitComponentMax);
    int bestLength = kBestFitComponentMax;
    for (int m = kBestFitComponentMax - 1; m >= 1; --m) {
        const BestFitCandidate c = bestFitCandidate(ray, ray, m);
        if (c.closerThan(best)) {
            best = c;
            bestLength = m;
        }
    }
    return bestLength;
}

std::size_t bestFitTableIndex(int row, int column) {
    return std::size_t(row) * std::size_t(row + 1) / 2 + std::size_t(column);
}

// The table, built on first use (a function-local static: thread-safe initialisation, concurrent
// first callers wait for one build). Rows are independent, so TBB builds them in parallel and
// the contents do not depend on scheduling. Measured build: 0.6 s on one core, 0.47 s on two
// (66 M candidates; gbuffer/README.md).
const std::vector<std::uint8_t>& bestFitLengthTable() {
    static const std::vector<std::uint8_t> table = [] {
        std::vector<std::uint8_t> lengths(kBestFitTableCellCount);
        constexpr double n = kBestFitTableResolution;
        tbb::parallel_for(0, kBestFitTableResolution, [&](int row) {
            for (int column = 0; column <= row; ++column)
                lengths[bestFitTableIndex(row, column)] = static_cast<std::uint8_t>(
                    bestFitLengthBySearch((row + 0.5) / n, (column + 0.5) / n));
        });
        return lengths;
    }();
    return table;
}

int majorAxis(const glm::dvec3& d) {
    int major = 0;
    for (int i = 1; i < 3; ++i)
        if (std::abs(d[i]) > std::abs(d[major]))
            major = i;
    return major;
}

std::uint64_t packBestFit(const glm::dvec3& k) {
    std::uint64_t code = 0;
    for (int i = 0; i < 3; ++i)
        code |= static_cast<std::uint64_t>(k[i] + kBestFitComponentMax) << (8 * i);
    return code;
}

// The table encoder: look up the length for the folded direction, scale, round, restore signs.
std::uint64_t bestFitEncode(const glm::dvec3& d) {
    const int major = majorAxis(d);
    const glm::dvec3 ray = glm::abs(d) / std::abs(d[major]); // ray[major] == 1 exactly
    const double minorA = ray[(major + 1) % 3], minorB = ray[(major + 2) % 3];
    const double u = std::max(minorA, minorB), v = std::min(minorA, minorB); // 1 >= u >= v >= 0
    constexpr double n = kBestFitTableResolution;
    const int row = std::min(kBestFitTableResolution - 1, static_cast<int>(u * n));
    const int column = std::min(row, static_cast<int>(v * n));
    const int length = bestFitLengthTable()[bestFitTableIndex(row, column)];
    const BestFitCandidate fromTable = bestFitCandidate(d, ray, length);
    const BestFitCandidate longest = bestFitCandidate(d, ray, kBestFitComponentMax);
    return packBestFit(longest.closerThan(fromTable) ? longest.k : fromTable.k);
}

// The exact per-direction search that the table approximates: every major length plus the naive
// round(127 d). The tests' oracle; 128 candidates per encode.
std::uint64_t bestFitEncodeBySearchUnit(const glm::dvec3& d) {
    const glm::dvec3 ray = glm::abs(d) / std::abs(d[majorAxis(d)]);
    BestFitCandidate best;
    best.k = glm::dvec3(std::nearbyint(d.x * kBestFitComponentMax),
                        std::nearbyint(d.y * kBestFitComponentMax),
                        std::nearbyint(d.z * kBestFitComponentMax));
    best.dot = glm::dot(best.k, d);
    best.length2 = glm::dot(best.k, best.k);
    if (!(best.dot > 0.0)) { // cannot happen for a unit d; keeps the comparison well defined
        best.dot = 0.0;
        best.length2 = 1.0;
    }
    for (int m = 1; m <= kBestFitComponentMax; ++m) {
        const BestFitCandidate c = bestFitCandidate(d, ray, m);
        if (c.closerThan(best))
            best = c;
    }
    return packBestFit(best.k);
}

// --- spherical, spheremap, stereographic ------------------------------------------------------

std::uint64_t sphericalEncode(const glm::dvec3& d, int b) {
    // Polar angle theta in [0, pi] as UNORM over 2^b - 1 steps (both poles exact); azimuth phi
    // periodic over 2^b steps, so no code is wasted on a duplicate seam.
    const double theta = std::atan2(std::hypot(d.x, d.y), d.z); // accurate near the poles
    const double phi = std::atan2(d.y, d.x);
    const double thetaSteps = static_cast<double>(fieldMask(b));
    const std::int64_t phiSteps = std::int64_t{1} << b;
    const auto qTheta = static_cast<std::uint64_t>(std::llround(theta / kPi * thetaSteps));
    std::int64_t qPhi = std::llround(phi / (2.0 * kPi) * static_cast<double>(phiSteps));
    qPhi = ((qPhi % phiSteps) + phiSteps) % phiSteps;
    return pack2(static_cast<std::uint64_t>(qPhi), std::min(qTheta, fieldMask(b)), b);
}

glm::vec3 sphericalDecode(std::uint64_t code, int b) {
    const double phi = static_cast<double>(field(code, 0, b)) * 2.0 * kPi /
                       static_cast<double>(std::uint64_t{1} << b);
    const double theta =
        static_cast<double>(field(code, 1, b)) * kPi / static_cast<double>(fieldMask(b));
    return toUnitFloat(glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                  std::cos(theta)));
}

std::uint64_t spheremapEncode(const glm::dvec3& d, int b) {
    // Pranckevicius' enc = xy / sqrt(8z + 8) + 0.5 is, as SNORM s = 2 enc - 1, the point
    // sin(theta / 2) * azimuth in the unit disc. This form is finite at z = -1 (any rim point).
    double radius = 0.0;
    const glm::dvec2 dir = azimuthDirection(d, radius);
    const glm::dvec2 s = dir * std::sin(0.5 * std::atan2(radius, d.z));
    return pack2(quantizeSnorm(s.x, b), quantizeSnorm(s.y, b), b);
}

glm::vec3 spheremapDecode(std::uint64_t code, int b) {
    glm::dvec2 s(dequantizeSnorm(field(code, 0, b), b), dequantizeSnorm(field(code, 1, b), b));
    double s2 = glm::dot(s, s);
    if (s2 > 1.0) { // square corners outside the disc: pull back to the rim (-Z), no NaN
        s /= std::sqrt(s2);
        s2 = 1.0;
    }
    const glm::dvec2 xy = 2.0 * s * std::sqrt(std::max(0.0, 1.0 - s2));
    return toUnitFloat(glm::dvec3(xy, 1.0 - 2.0 * s2));
}

std::uint64_t stereographicEncode(const glm::dvec3& d, double scale, int b) {
    // a = xy / (1 + z) = tan(theta / 2) * azimuth; the tan form stays finite at -Z (~1.6e16).
    double radius = 0.0;
    const glm::dvec2 dir = azimuthDirection(d, radius);
    glm::dvec2 s = dir * (std::tan(0.5 * std::atan2(radius, d.z)) / scale);
    // Outside the stored square: shrink radially, which keeps the azimuth (per-axis clamping
    // would not).
    const double extent = std::max(std::abs(s.x), std::abs(s.y));
    if (extent > 1.0)
        s /= extent;
    return pack2(quantizeSnorm(s.x, b), quantizeSnorm(s.y, b), b);
}

glm::vec3 stereographicDecode(std::uint64_t code, double scale, int b) {
    const glm::dvec2 a = scale * glm::dvec2(dequantizeSnorm(field(code, 0, b), b),
                                            dequantizeSnorm(field(code, 1, b), b));
    const double a2 = glm::dot(a, a);
    return toUnitFloat(glm::dvec3(2.0 * a, 1.0 - a2) / (1.0 + a2));
}

// --- pixel-view -------------------------------------------------------------------------------

// The thesis' per-pixel view frame, in double. Rows x, y, z are orthonormal and right-handed.
struct PixelViewFrame {
    glm::dvec3 x{1.0, 0.0, 0.0};
    glm::dvec3 y{0.0, 1.0, 0.0};
    glm::dvec3 z{0.0, 0.0, 1.0}; // towards the camera: -normalize(viewRay)
};

PixelViewFrame pixelViewFrame(glm::vec3 viewRayView) {
    PixelViewFrame frame; // the central ray's frame, also the fallback for degenerate rays
    if (!std::isfinite(viewRayView.x) || !std::isfinite(viewRayView.y) ||
        !std::isfinite(viewRayView.z))
        return frame;
    const glm::dvec3 ray(viewRayView);
    const double length = std::sqrt(glm::dot(ray, ray)); // float inputs: no overflow in double
    if (!(length > 0.0))
        return frame;
    const glm::dvec3 z = -ray / length;
    // x = normalize(z.z, 0, -z.x) is undefined for a ray along the view Y axis. The frame is exact
    // for any non-zero horizontal part: z is a unit double vector made from floats, so its squares
    // neither overflow nor vanish (plain sqrt, not the slower hypot).
    const double horizontal = std::sqrt(z.z * z.z + z.x * z.x);
    if (!(horizontal > 0.0))
        return frame;
    frame.z = z;
    frame.x = glm::dvec3(z.z / horizontal, 0.0, -z.x / horizontal);
    frame.y = glm::cross(z, frame.x);
    return frame;
}

std::uint64_t pixelViewEncode(const glm::dvec3& d, glm::vec3 viewRayView, int b) {
    const PixelViewFrame frame = pixelViewFrame(viewRayView);
    glm::dvec2 local(glm::dot(d, frame.x), glm::dot(d, frame.y));
    if (glm::dot(d, frame.z) < 0.0) {
        // Faces away from the ray: invisible to a pinhole camera. Clamp to the silhouette (the
        // nearest direction with local z = 0) instead of mirroring it as xy-z does.
        const double radius = std::hypot(local.x, local.y);
        local = radius > 0.0 ? local / radius : glm::dvec2(1.0, 0.0);
    }
    return pack2(quantizeSnorm(local.x, b), quantizeSnorm(local.y, b), b);
}

glm::vec3 pixelViewDecode(std::uint64_t code, glm::vec3 viewRayView, int b) {
    const glm::dvec2 local(dequantizeSnorm(field(code, 0, b), b),
                           dequantizeSnorm(field(code, 1, b), b));
    // Outside the unit disc (never written) z = 0: the nearest silhouette direction after the
    // final normalisation. Same expression as xy-z, so the central ray gives its bits exactly.
    const double z = std::sqrt(std::max(0.0, 1.0 - local.x * local.x - local.y * local.y));
    const PixelViewFrame frame = pixelViewFrame(viewRayView);
    return toUnitFloat(local.x * frame.x + local.y * frame.y + z * frame.z);
}

} // namespace

const char* normalCodecName(NormalCodecKind kind) {
    return codecInfo(kind).name;
}

std::vector<std::string> normalCodecNames() {
    std::vector<std::string> names;
    for (const CodecInfo& info : codecTable())
        names.emplace_back(info.name);
    return names;
}

std::vector<int> supportedBits(NormalCodecKind kind) {
    return codecInfo(kind).bits;
}

std::vector<NormalCodecSpec> allNormalCodecSpecs() {
    std::vector<NormalCodecSpec> specs;
    for (const CodecInfo& info : codecTable())
        for (int bits : info.bits)
            specs.push_back({info.kind, bits});
    return specs;
}

std::string NormalCodecSpec::text() const {
    return std::string(normalCodecName(kind)) + ":" + std::to_string(bits);
}

NormalCodecSpec NormalCodecSpec::parse(const std::string& text) {
    auto fail = [&](const std::string& why) -> NormalCodecSpec {
        std::string message = "normal codec '" + text + "': " + why +
                              "; expected NAME:BITS (BITS = total bits) with one of:";
        for (const CodecInfo& info : codecTable()) {
            message += std::string(" ") + info.name + ":";
            for (std::size_t i = 0; i < info.bits.size(); ++i)
                message += (i ? "|" : "") + std::to_string(info.bits[i]);
        }
        throw std::invalid_argument(message);
    };
    const std::size_t colon = text.rfind(':');
    if (colon == std::string::npos) {
        // A codec with one bit depth needs no ':BITS' (`--normals float32`).
        for (const CodecInfo& info : codecTable())
            if (text == info.name && info.bits.size() == 1)
                return {info.kind, info.bits.front()};
        return fail("missing ':BITS'");
    }
    const std::string name = text.substr(0, colon);
    const std::string bitsText = text.substr(colon + 1);
    for (const CodecInfo& info : codecTable()) {
        if (name != info.name)
            continue;
        int bits = 0;
        const char* end = bitsText.data() + bitsText.size();
        const auto [ptr, ec] = std::from_chars(bitsText.data(), end, bits);
        if (bitsText.empty() || ec != std::errc() || ptr != end)
            return fail("BITS '" + bitsText + "' is not an integer");
        if (std::find(info.bits.begin(), info.bits.end(), bits) == info.bits.end())
            return fail(std::string(info.name) + " does not support " + bitsText + " bits");
        return {info.kind, bits};
    }
    std::vector<std::string> names;
    for (const CodecInfo& info : codecTable())
        names.push_back(info.name);
    return fail("unknown name '" + name + "'" + scenes::didYouMean(name, names));
}

double normalAngleRadians(glm::vec3 a, glm::vec3 b) {
    const glm::dvec3 da(a), db(b);
    return std::atan2(glm::length(glm::cross(da, db)), glm::dot(da, db));
}

NormalCode encodeNormal(const NormalCodecSpec& spec, glm::vec3 unitNormalView,
                        glm::vec3 viewRayView) {
    const int b = componentBits(spec);
    const glm::dvec3 d = unitOrFallback(unitNormalView);
    NormalCode code;
    switch (spec.kind) {
    case NormalCodecKind::Float32: {
        const glm::vec3 f(d);
        code.low = std::bit_cast<std::uint32_t>(f.x) |
                   (std::uint64_t{std::bit_cast<std::uint32_t>(f.y)} << 32);
        code.high = std::bit_cast<std::uint32_t>(f.z);
        break;
    }
    case NormalCodecKind::Xyz:
        code.low = quantizeSnorm(d.x, b) | (quantizeSnorm(d.y, b) << b) |
                   (quantizeSnorm(d.z, b) << (2 * b));
        break;
    case NormalCodecKind::XyReconstructZ:
        code.low = pack2(quantizeSnorm(d.x, b), quantizeSnorm(d.y, b), b);
        break;
    case NormalCodecKind::Spherical:
        code.low = sphericalEncode(d, b);
        break;
    case NormalCodecKind::Spheremap:
        code.low = spheremapEncode(d, b);
        break;
    case NormalCodecKind::Stereographic:
        code.low = stereographicEncode(d, 1.0, b);
        break;
    case NormalCodecKind::StereographicScaled:
        code.low = stereographicEncode(d, kStereographicScale, b);
        break;
    case NormalCodecKind::PixelView:
        code.low = pixelViewEncode(d, viewRayView, b);
        break;
    case NormalCodecKind::BestFit:
        code.low = bestFitEncode(d);
        break;
    case NormalCodecKind::Octahedral:
        code.low = octahedralEncode(d, b);
        break;
    case NormalCodecKind::OctahedralPrecise: {
        // The reference is the caller's vector when it is a direction at all (the metric ignores
        // length), so "never worse than octahedral" holds exactly against what callers measure.
        const bool usable = std::isfinite(unitNormalView.x) && std::isfinite(unitNormalView.y) &&
                            std::isfinite(unitNormalView.z) && unitNormalView != glm::vec3(0.0f);
        code.low = octahedralPreciseEncode(d, usable ? unitNormalView : glm::vec3(d), b);
        break;
    }
    }
    return code;
}

NormalCode encodeBestFitBySearch(glm::vec3 unitNormalView) {
    return NormalCode{bestFitEncodeBySearchUnit(unitOrFallback(unitNormalView)), 0};
}

glm::vec3 decodeNormal(const NormalCodecSpec& spec, NormalCode code, glm::vec3 viewRayView) {
    const int b = componentBits(spec);
    switch (spec.kind) {
    case NormalCodecKind::Float32: {
        const glm::vec3 f(std::bit_cast<float>(static_cast<std::uint32_t>(code.low)),
                          std::bit_cast<float>(static_cast<std::uint32_t>(code.low >> 32)),
                          std::bit_cast<float>(code.high));
        return toUnitFloat(unitOrFallback(f));
    }
    case NormalCodecKind::Xyz:
        return toUnitFloat(glm::dvec3(dequantizeSnorm(field(code.low, 0, b), b),
                                      dequantizeSnorm(field(code.low, 1, b), b),
                                      dequantizeSnorm(field(code.low, 2, b), b)));
    case NormalCodecKind::XyReconstructZ: {
        const double x = dequantizeSnorm(field(code.low, 0, b), b);
        const double y = dequantizeSnorm(field(code.low, 1, b), b);
        // Outside the unit disc the code is not a unit vector's; z = 0 is the nearest sphere point.
        return toUnitFloat(glm::dvec3(x, y, std::sqrt(std::max(0.0, 1.0 - x * x - y * y))));
    }
    case NormalCodecKind::Spherical:
        return sphericalDecode(code.low, b);
    case NormalCodecKind::Spheremap:
        return spheremapDecode(code.low, b);
    case NormalCodecKind::Stereographic:
        return stereographicDecode(code.low, 1.0, b);
    case NormalCodecKind::StereographicScaled:
        return stereographicDecode(code.low, kStereographicScale, b);
    case NormalCodecKind::PixelView:
        return pixelViewDecode(code.low, viewRayView, b);
    case NormalCodecKind::BestFit:
        // (127,127,127) is the zero vector (never written): toUnitFloat falls back to +Z.
        return toUnitFloat(
            glm::dvec3(static_cast<double>(field(code.low, 0, 8)) - kBestFitComponentMax,
                       static_cast<double>(field(code.low, 1, 8)) - kBestFitComponentMax,
                       static_cast<double>(field(code.low, 2, 8)) - kBestFitComponentMax));
    case NormalCodecKind::Octahedral:
    case NormalCodecKind::OctahedralPrecise:
        return octahedralDecode(code.low, b);
    }
    return kFallbackNormalView;
}

// --- Derived bounds ----------------------------------------------------------------------------
// b = bits per component, N = 2^(b-1) - 1 (SNORM steps per unit: step 1/N, half step 1/(2N)).
// Every bound is a path-length argument: the decoded point is reached from the input's exact
// (unquantised) image by a short straight path in the code domain, and the angle is at most the
// length of that path's image on the sphere. Float output adds kNormalFloatSlackRadians.
//
// xyz: each component moves by <= 1/(2N), so |v - n| <= sqrt(3)/(2N) = e; a vector within e of a
//   unit vector is at most asin(e) away in angle. 8 bits: 0.39 deg.
// xy-z (z >= 0 only) and pixel-view (local z >= 0 only; the same map in a rotated frame):
//   (x, y) moves by <= e = sqrt(2)/(2N) in the unit disc, and the decoder is the inverse
//   orthographic projection. Radially, theta = asin(r) has slope 1/cos(theta), unbounded at the
//   rim: the worst radial step of length e is the last one, pi/2 - asin(1 - e). Tangentially the
//   sphere arc equals the disc arc (sin(theta) = r), and the arc at radius |q| from q to p's
//   azimuth is <= (pi/2) * (2e). Total <= pi/2 - asin(1 - e) + pi e. 8 bits: 6.0 + 2.0 deg; the
//   rim (grazing normals) costs sqrt(2e) rad.
// spherical: theta in UNORM over M = 2^b - 1 steps of pi/M, phi over 2^b steps of 2pi/2^b; move
//   along the meridian (<= pi/(2M)) then along the parallel (sin(theta) * pi/2^b <= pi/2^b).
// spheremap: s = sin(theta/2) * azimuth in the unit disc; in Lambert units rho = 2|s| in [0, 2]
//   a half-cell diagonal is e = 2 * sqrt(2)/(2N) = sqrt(2)/N. theta = 2 asin(rho/2) has slope
//   1/cos(theta/2), unbounded at the rim (-Z), so the worst radial step is
//   pi - 2 asin(1 - e/2); tangentially sphere arc = rho cos(theta/2) dphi <= disc arc <= pi e.
//   Total <= pi - 2 asin(1 - e/2) + pi e: large at 8 bits (~14 deg), only near -Z.
// stereographic (scale S): a = S s, s in [-1,1]^2; the inverse projection is conformal with
//   factor 2/(1 + |a|^2) <= 2, so angle <= 2 * S * sqrt(2)/(2N) = sqrt(2) S / N, valid where no
//   clamping happens: |a| <= S, i.e. z >= (1 - S^2)/(1 + S^2) (0 for S = 1, -0.519 for 1.7777).
//   Beyond that the codec clamps to the square's border: up to ~180 deg at -Z, by design.
// octahedral: p moves by <= e = sqrt(2)/(2N) (half diagonal). The octahedron point
//   (px, py, 1-|px|-|py|) (folded or not, piecewise affine) moves by <= sqrt(e^2 + (|dx|+|dy|)^2)
//   <= sqrt(3) e, and projecting onto the sphere stretches by 1/|o| <= sqrt(3) (the octahedron's
//   face centres are 1/sqrt(3) from the origin). Total <= 3 e = 3 sqrt(2)/(2N). 8 bits: 0.96 deg.
// octahedral-precise: never worse than octahedral per direction, so the same bound.
// best-fit: among the candidates (the table encoder always compares it) is major length 127 with
//   the two minors rounded: error vector
//   <= sqrt(2)/2 against a vector of length >= 127, so angle <= asin((sqrt(2)/2)/127) = 0.32 deg.
// float32: only the float cast, so 0 (+ slack).
double normalErrorBoundRadians(const NormalCodecSpec& spec) {
    const int b = componentBits(spec);
    const double n = static_cast<double>(snormMax(b));
    switch (spec.kind) {
    case NormalCodecKind::Float32:
        return 0.0;
    case NormalCodecKind::Xyz:
        return std::asin(std::sqrt(3.0) / (2.0 * n));
    case NormalCodecKind::XyReconstructZ:
    case NormalCodecKind::PixelView: {
        const double e = std::sqrt(2.0) / (2.0 * n);
        return kPi / 2 - std::asin(1.0 - e) + kPi * e;
    }
    case NormalCodecKind::Spherical:
        return kPi / (2.0 * (std::ldexp(1.0, b) - 1.0)) + kPi / std::ldexp(1.0, b);
    case NormalCodecKind::Spheremap: {
        const double e = std::sqrt(2.0) / n;
        return kPi - 2.0 * std::asin(1.0 - e / 2.0) + kPi * e;
    }
    case NormalCodecKind::Stereographic:
        return std::sqrt(2.0) / n;
    case NormalCodecKind::StereographicScaled:
        return std::sqrt(2.0) * kStereographicScale / n;
    case NormalCodecKind::BestFit:
        return std::asin(std::sqrt(0.5) / kBestFitComponentMax);
    case NormalCodecKind::Octahedral:
    case NormalCodecKind::OctahedralPrecise:
        return 3.0 * std::sqrt(2.0) / (2.0 * n);
    }
    return 0.0;
}

bool inNormalErrorBoundRegion(const NormalCodecSpec& spec, glm::vec3 unitNormalView,
                              glm::vec3 viewRayView) {
    const glm::dvec3 d = unitOrFallback(unitNormalView);
    switch (spec.kind) {
    case NormalCodecKind::XyReconstructZ:
    case NormalCodecKind::Stereographic:
        return d.z >= 0.0;
    case NormalCodecKind::StereographicScaled: {
        const double s2 = kStereographicScale * kStereographicScale;
        return d.z >= (1.0 - s2) / (1.0 + s2);
    }
    case NormalCodecKind::PixelView:
        return glm::dot(d, pixelViewFrame(viewRayView).z) >= 0.0;
    default:
        return true;
    }
}

} // namespace gbuffer
