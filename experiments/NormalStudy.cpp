// NormalStudy implementation; see NormalStudy.h for what is measured and gbuffer/README.md for
// the definitions. Parallel work is always "fixed chunks, per-chunk results, merged in chunk
// order" (no atomics, no order-dependent float sums), so results do not depend on threads.
#include "experiments/NormalStudy.h"
#include "experiments/BuildCommit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "experiments/AtomicFile.h"
#include "experiments/PlotScript.h"
#include "gbuffer/DepthFormat.h"
#include "gbuffer/NormalCodec.h"
#include "lighting/PreparedScene.h"
#include "scenes/ProceduralScenes.h"
#include "scenes/SceneLoader.h"

#ifndef TESTBED_SOURCE_DIR
#define TESTBED_SOURCE_DIR "."
#endif

namespace experiments {

namespace {

using gbuffer::NormalCode;
using gbuffer::NormalCodecKind;
using gbuffer::NormalCodecSpec;
using Clock = std::chrono::steady_clock;

constexpr double kPi = std::numbers::pi;
constexpr double kDegreesPerRadian = 180.0 / kPi;
// Samples per parallel chunk: large enough to amortise scheduling (~1-10 ms of work), small
// enough to balance 10^7 samples over many cores. Fixed, so the merge order is fixed.
constexpr std::uint64_t kChunkSamples = std::uint64_t{1} << 15;
// The camera of the visible-60 dataset: the thesis' and the 60 degree vertical field of
// view on a 16:9 image (1280 x 720, the render default).
constexpr double kVisibleFovDegrees = 60.0;
constexpr double kVisibleAspect = 16.0 / 9.0;
// Occupancy is exhaustive up to 2^24 codes (16.7 M encodes per codec, a few seconds); larger
// codes are sampled (standard error of the fraction <= 0.5 / sqrt(samples) = 0.05 %).
constexpr int kOccupancyExhaustiveBits = 24;
constexpr std::uint64_t kOccupancySamples = std::uint64_t{1} << 20;
constexpr std::uint64_t kOccupancyQuickSamples = std::uint64_t{1} << 14;
// Throughput: SoA arrays of this many normals, best of kThroughputRepeats timed loops.
constexpr std::size_t kThroughputNormals = std::size_t{1} << 16;
constexpr std::size_t kThroughputQuickNormals = std::size_t{1} << 10;
constexpr int kThroughputRepeats = 3;
// Error maps: equirectangular grid, each cell the max over sub x sub stratified samples.
constexpr int kMapWidth = 720, kMapHeight = 360, kMapSub = 4; // 0.5 degree cells
constexpr int kQuickMapWidth = 90, kQuickMapHeight = 45, kQuickMapSub = 2;
constexpr int kQuickSceneWidth = 160, kQuickSceneHeight = 90;
// Salts separating the datasets' random streams.
constexpr std::uint64_t kSaltSphere = 1, kSaltVisible = 2, kSaltNegativeZ = 3, kSaltOccupancy = 4,
                        kSaltThroughput = 5, kSaltHard = 6;

// --- counter-based random numbers --------------------------------------------------------------

std::uint64_t mix64(std::uint64_t z) { // SplitMix64's finaliser (Steele et al. 2014)
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// Value k of a SplitMix64 sequence, computable for any k independently: what makes parallel
// generation identical to sequential generation.
struct CounterRng {
    std::uint64_t base;
    CounterRng(std::uint64_t seed, std::uint64_t salt)
        : base(mix64(seed ^ (salt * 0xD1B54A32D192ED03ull))) {}
    std::uint64_t bits(std::uint64_t k) const {
        return mix64(base + (k + 1) * 0x9E3779B97F4A7C15ull);
    }
    double uniform(std::uint64_t k) const { return static_cast<double>(bits(k) >> 11) * 0x1.0p-53; }
};

glm::dvec3 uniformSphere(double u1, double u2) {
    const double z = 1.0 - 2.0 * u1;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * kPi * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// Orthonormal basis around a unit axis (Duff et al. 2017, "Building an orthonormal basis,
// revisited").
void basisAround(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

// Cosine-weighted (projected-area-weighted) direction around `axis`, or uniform on its
// hemisphere.
glm::dvec3 hemisphereAround(const glm::dvec3& axis, double u1, double u2, bool cosineWeighted) {
    const double cosTheta = cosineWeighted ? std::sqrt(1.0 - u1) : 1.0 - u1;
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const double phi = 2.0 * kPi * u2;
    glm::dvec3 t, b;
    basisAround(axis, t, b);
    return sinTheta * std::cos(phi) * t + sinTheta * std::sin(phi) * b + cosTheta * axis;
}

// The view ray (z = -1) through a uniformly random point of the image of a pinhole camera.
glm::dvec3 randomPixelRay(double u1, double u2, double verticalFovDegrees, double aspect) {
    const double tanHalf = std::tan(0.5 * verticalFovDegrees / kDegreesPerRadian);
    return {(2.0 * u1 - 1.0) * tanHalf * aspect, (2.0 * u2 - 1.0) * tanHalf, -1.0};
}

// --- datasets ----------------------------------------------------------------------------------

struct Dataset {
    std::string name;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec3> rays; // empty: every sample is seen along kCentralViewRay
};

template <typename Fn>
void forEachChunk(std::uint64_t count, Fn&& fn) { // fn(chunkIndex, begin, end)
    const std::uint64_t chunks = (count + kChunkSamples - 1) / kChunkSamples;
    tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, chunks, 1),
                      [&](const tbb::blocked_range<std::uint64_t>& range) {
                          for (std::uint64_t c = range.begin(); c != range.end(); ++c)
                              fn(c, c * kChunkSamples, std::min(count, (c + 1) * kChunkSamples));
                      });
}

Dataset sphereDataset(std::uint64_t count, std::uint64_t seed) {
    Dataset data{"sphere", std::vector<glm::vec3>(count), {}};
    const CounterRng rng(seed, kSaltSphere);
    forEachChunk(count, [&](std::uint64_t, std::uint64_t begin, std::uint64_t end) {
        for (std::uint64_t i = begin; i < end; ++i)
            data.normals[i] = glm::vec3(uniformSphere(rng.uniform(2 * i), rng.uniform(2 * i + 1)));
    });
    return data;
}

Dataset visibleDataset(std::uint64_t count, std::uint64_t seed) {
    Dataset data{"visible-60", std::vector<glm::vec3>(count), std::vector<glm::vec3>(count)};
    const CounterRng rng(seed, kSaltVisible);
    forEachChunk(count, [&](std::uint64_t, std::uint64_t begin, std::uint64_t end) {
        for (std::uint64_t i = begin; i < end; ++i) {
            const glm::dvec3 ray = randomPixelRay(rng.uniform(4 * i), rng.uniform(4 * i + 1),
                                                  kVisibleFovDegrees, kVisibleAspect);
            data.rays[i] = glm::vec3(ray);
            data.normals[i] = glm::vec3(hemisphereAround(
                -glm::normalize(ray), rng.uniform(4 * i + 2), rng.uniform(4 * i + 3), true));
        }
    });
    return data;
}

// --- hard cases --------------------------------------------------------------------------------

glm::vec3 unitFloat(double x, double y, double z) {
    const double l = std::sqrt(x * x + y * y + z * z);
    return glm::vec3(x / l, y / l, z / l);
}

} // namespace

std::vector<HardNormalCase> hardNormalCases() {
    const glm::vec3 central = gbuffer::kCentralViewRay;
    std::vector<HardNormalCase> cases;
    auto add = [&](glm::vec3 n, const char* group, glm::vec3 ray) {
        cases.push_back({n, ray, group});
    };
    const float sub = std::numeric_limits<float>::denorm_min();
    const float big = std::numeric_limits<float>::max();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();

    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f}) {
            glm::vec3 n(0.0f);
            n[axis] = sign;
            add(n, "axes", central);
        }
    // -Z: the spheremap and stereographic singularity (and the worst back face of xy-z); +-Z: the
    // spherical poles. Exactly there, signed zeros, and 1e-8..1e-2 rad away at 8 azimuths.
    for (float sign : {1.0f, -1.0f}) {
        const char* group = sign < 0 ? "minus-z" : "plus-z-pole";
        add({-0.0f, -0.0f, sign}, group, central);
        add({0.0f, -0.0f, sign}, group, central);
        for (double eps : {1e-8, 1e-6, 1e-4, 1e-3, 1e-2})
            for (int k = 0; k < 8; ++k) {
                const double phi = k * kPi / 4.0;
                add(unitFloat(std::sin(eps) * std::cos(phi), std::sin(eps) * std::sin(phi),
                              sign * std::cos(eps)),
                    group, central);
            }
    }
    // Octahedral folds and the square's edges: |x| + |y| = 1 with z = 0 and z = +-1e-7.
    for (double t : {0.0, 1e-7, 0.25, 0.5, 0.75, 1.0 - 1e-7, 1.0})
        for (double sx : {1.0, -1.0})
            for (double sy : {1.0, -1.0})
                for (double z : {0.0, 1e-7, -1e-7})
                    add(unitFloat(sx * t, sy * (1.0 - t), z), "octahedral-edge", central);
    // One zero component (the fold lines and the axes' great circles), every 15 degrees.
    for (int k = 0; k < 24; ++k) {
        const double a = k * kPi / 12.0, c = std::cos(a), s = std::sin(a);
        add(unitFloat(c, 0.0, s), "one-zero-component", central);
        add(unitFloat(0.0, c, s), "one-zero-component", central);
        add(unitFloat(c, s, 0.0), "one-zero-component", central);
    }
    // Back-facing view-space normals, z slightly negative (visible off-centre under perspective).
    for (double z : {-1e-3, -3e-3, -1e-2, -3e-2, -0.1})
        for (int k = 0; k < 8; ++k) {
            const double phi = (k + 0.5) * kPi / 4.0, r = std::sqrt(1.0 - z * z);
            add(unitFloat(r * std::cos(phi), r * std::sin(phi), z), "back-facing", central);
        }
    // Not-quite-unit lengths 1 +- 1e-3.
    const CounterRng rng(1, kSaltHard);
    for (int k = 0; k < 16; ++k) {
        const glm::dvec3 d = uniformSphere(rng.uniform(2 * k), rng.uniform(2 * k + 1));
        add(glm::vec3(d * (1.0 + 1e-3)), "near-unit", central);
        add(glm::vec3(d * (1.0 - 1e-3)), "near-unit", central);
    }
    // Subnormal, tiny and huge components (directions still defined).
    for (glm::vec3 n : {glm::vec3(sub, 0, 0), glm::vec3(0, sub, 0), glm::vec3(0, 0, sub),
                        glm::vec3(0, 0, -sub), glm::vec3(sub, sub, sub), glm::vec3(-sub, sub, -sub),
                        glm::vec3(1e-40f, -1e-40f, 1e-40f), glm::vec3(1e-30f, 2e-30f, -3e-30f)})
        add(n, "subnormal", central);
    for (glm::vec3 n :
         {glm::vec3(big, big, big), glm::vec3(-big, 0, big), glm::vec3(1e38f, -1e38f, -1e38f)})
        add(n, "huge", central);
    // No direction at all.
    for (glm::vec3 n : {glm::vec3(0, 0, 0), glm::vec3(-0.0f, -0.0f, -0.0f), glm::vec3(0, -0.0f, 0)})
        add(n, "zero", central);
    for (glm::vec3 n : {glm::vec3(nan, 0, 1), glm::vec3(0, nan, 0), glm::vec3(nan, nan, nan),
                        glm::vec3(inf, 0, 0), glm::vec3(-inf, inf, 0), glm::vec3(0, 0, -inf),
                        glm::vec3(inf, inf, inf), glm::vec3(nan, inf, -inf)})
        add(n, "non-finite", central);
    // pixel-view: off-axis rays (corners and edges of a 90 degree 16:9 camera, a nearly horizontal
    // and a nearly vertical ray) with a normal facing the ray, grazing it and slightly behind it;
    // degenerate rays (zero, NaN/Inf, along view Y) that must fall back to the central ray.
    const double t = std::tan(kPi / 4.0), a = 16.0 / 9.0;
    for (glm::dvec3 ray :
         {glm::dvec3(t * a, t, -1), glm::dvec3(-t * a, t, -1), glm::dvec3(0, -t, -1),
          glm::dvec3(t * a, 0, -1), glm::dvec3(1, 0, -1e-3), glm::dvec3(0, 1, -1e-3)}) {
        const glm::dvec3 towards = -glm::normalize(ray);
        glm::dvec3 u, v;
        basisAround(towards, u, v);
        for (double z : {1.0, 0.5, 1e-3, 0.0, -1e-3, -0.1}) {
            const double r = std::sqrt(1.0 - z * z);
            add(glm::vec3(z * towards + r * u), "off-axis-ray", glm::vec3(ray));
            add(glm::vec3(z * towards - r * v), "off-axis-ray", glm::vec3(ray));
        }
    }
    for (glm::vec3 ray : {glm::vec3(0, 0, 0), glm::vec3(nan, 0, -1), glm::vec3(0, inf, -1),
                          glm::vec3(0, 1, 0), glm::vec3(0, -1e-30f, 0)})
        for (glm::vec3 n :
             {glm::vec3(0, 0, 1), unitFloat(0.6, 0.0, 0.8), unitFloat(0.3, -0.4, -0.1)})
            add(n, "degenerate-ray", ray);
    return cases;
}

namespace {

Dataset hardDataset() {
    Dataset data{"hard", {}, {}};
    for (const HardNormalCase& c : hardNormalCases()) {
        data.normals.push_back(c.normalView);
        data.rays.push_back(c.viewRayView);
    }
    return data;
}

// --- evaluation ----------------------------------------------------------------------------------

bool finite3(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

struct ChunkStats {
    std::uint64_t samples = 0, nanInf = 0, region = 0, negative = 0;
    std::int64_t worse = 0;
    double sum = 0.0, sumSquares = 0.0, max = 0.0, regionMax = 0.0, negativeSum = 0.0,
           negativeMax = 0.0;
};

std::string vecText(glm::vec3 v) {
    std::ostringstream text;
    text << std::setprecision(9) << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return text.str();
}

// Errors of one codec on one dataset. `errors` is scratch (reused across codecs).
NormalStudyRow evaluate(const NormalCodecSpec& spec, const Dataset& data,
                        std::vector<float>& errors) {
    const std::uint64_t count = data.normals.size();
    errors.assign(count, -1.0f); // -1: no direction (not counted in the percentile)
    const std::uint64_t chunks = (count + kChunkSamples - 1) / kChunkSamples;
    std::vector<ChunkStats> stats(chunks);
    const bool precise = spec.kind == NormalCodecKind::OctahedralPrecise;
    const NormalCodecSpec plain{NormalCodecKind::Octahedral, spec.bits};
    forEachChunk(count, [&](std::uint64_t chunk, std::uint64_t begin, std::uint64_t end) {
        ChunkStats s;
        for (std::uint64_t i = begin; i < end; ++i) {
            const glm::vec3 n = data.normals[i];
            const glm::vec3 ray = data.rays.empty() ? gbuffer::kCentralViewRay : data.rays[i];
            const glm::vec3 decoded =
                gbuffer::decodeNormal(spec, gbuffer::encodeNormal(spec, n, ray), ray);
            const bool finiteOut = finite3(decoded);
            s.nanInf += finiteOut ? 0 : 1;
            if (!finite3(n) || n == glm::vec3(0.0f))
                continue; // no direction to compare with
            const double error = finiteOut ? gbuffer::normalAngleRadians(n, decoded) : kPi;
            errors[i] = static_cast<float>(error);
            ++s.samples;
            s.sum += error;
            s.sumSquares += error * error;
            s.max = std::max(s.max, error);
            if (gbuffer::inNormalErrorBoundRegion(spec, n, ray)) {
                ++s.region;
                s.regionMax = std::max(s.regionMax, error);
            }
            if (n.z < 0.0f) {
                ++s.negative;
                s.negativeSum += error;
                s.negativeMax = std::max(s.negativeMax, error);
            }
            if (precise) {
                const glm::vec3 p = gbuffer::decodeNormal(plain, gbuffer::encodeNormal(plain, n));
                s.worse += error > gbuffer::normalAngleRadians(n, p) ? 1 : 0;
            }
        }
        stats[chunk] = s;
    });
    ChunkStats total;
    for (const ChunkStats& s : stats) { // fixed order: deterministic sums
        total.samples += s.samples;
        total.nanInf += s.nanInf;
        total.region += s.region;
        total.negative += s.negative;
        total.worse += s.worse;
        total.sum += s.sum;
        total.sumSquares += s.sumSquares;
        total.max = std::max(total.max, s.max);
        total.regionMax = std::max(total.regionMax, s.regionMax);
        total.negativeSum += s.negativeSum;
        total.negativeMax = std::max(total.negativeMax, s.negativeMax);
    }
    NormalStudyRow row;
    row.codec = spec.text();
    row.name = gbuffer::normalCodecName(spec.kind);
    row.bits = spec.bits;
    row.dataset = data.name;
    row.samples = total.samples;
    row.nanInfOutputs = total.nanInf;
    if (total.samples > 0) {
        const double n = static_cast<double>(total.samples);
        row.meanDegrees = total.sum / n * kDegreesPerRadian;
        row.rmsDegrees = std::sqrt(total.sumSquares / n) * kDegreesPerRadian;
        row.maxDegrees = total.max * kDegreesPerRadian;
        // Nearest-rank 99.9th percentile over the samples with a direction.
        auto last = std::remove_if(errors.begin(), errors.end(), [](float e) { return e < 0.0f; });
        const std::size_t rank = static_cast<std::size_t>(std::ceil(0.999 * n)) - 1;
        std::nth_element(errors.begin(), errors.begin() + rank, last);
        row.p999Degrees = static_cast<double>(errors[rank]) * kDegreesPerRadian;
    }
    row.boundDegrees =
        (gbuffer::normalErrorBoundRadians(spec) + gbuffer::kNormalFloatSlackRadians) *
        kDegreesPerRadian;
    row.boundRegionSamples = total.region;
    row.maxInBoundRegionDegrees = total.regionMax * kDegreesPerRadian;
    row.negativeZSamples = total.negative;
    if (total.negative > 0) {
        row.meanNegativeZDegrees =
            total.negativeSum / static_cast<double>(total.negative) * kDegreesPerRadian;
        row.maxNegativeZDegrees = total.negativeMax * kDegreesPerRadian;
    }
    if (precise)
        row.worseThanOctahedral = total.worse;
    return row;
}

// --- occupancy, throughput, maps -----------------------------------------------------------------

struct Occupancy {
    double fraction = 0.0;
    std::uint64_t tested = 0;
};

NormalCode codeFromBits(const NormalCodecSpec& spec, std::uint64_t low, std::uint64_t high) {
    if (spec.bits >= 64)
        return {low, spec.bits > 64 ? static_cast<std::uint32_t>(high) : 0u};
    return {low & ((std::uint64_t{1} << spec.bits) - 1), 0u};
}

// Fraction of the 2^bits codes c with encode(decode(c)) == c: the codes that the encoder writes
// for their own direction, i.e. the distinct directions the format can hold.
Occupancy measureOccupancy(const NormalCodecSpec& spec, bool quick, std::uint64_t seed) {
    const bool exhaustive = spec.bits <= (quick ? 16 : kOccupancyExhaustiveBits);
    const std::uint64_t count = exhaustive ? std::uint64_t{1} << spec.bits
                                           : (quick ? kOccupancyQuickSamples : kOccupancySamples);
    const CounterRng rng(seed, kSaltOccupancy);
    std::vector<std::uint64_t> fixedPerChunk((count + kChunkSamples - 1) / kChunkSamples, 0);
    forEachChunk(count, [&](std::uint64_t chunk, std::uint64_t begin, std::uint64_t end) {
        std::uint64_t fixed = 0;
        for (std::uint64_t i = begin; i < end; ++i) {
            const NormalCode code = exhaustive
                                        ? codeFromBits(spec, i, 0)
                                        : codeFromBits(spec, rng.bits(2 * i), rng.bits(2 * i + 1));
            fixed += gbuffer::encodeNormal(spec, gbuffer::decodeNormal(spec, code)) == code ? 1 : 0;
        }
        fixedPerChunk[chunk] = fixed;
    });
    std::uint64_t fixed = 0;
    for (std::uint64_t f : fixedPerChunk)
        fixed += f;
    return {static_cast<double>(fixed) / static_cast<double>(count), count};
}

// Normals per second on the calling thread, SoA arrays, best of kThroughputRepeats.
void measureThroughput(const NormalCodecSpec& spec, std::size_t count, int repeats,
                       std::uint64_t seed, double& encodePerSecond, double& decodePerSecond) {
    std::vector<float> nx(count), ny(count), nz(count), rx(count), ry(count), rz(count);
    std::vector<float> ox(count), oy(count), oz(count);
    std::vector<std::uint64_t> low(count);
    std::vector<std::uint32_t> high(count);
    const CounterRng rng(seed, kSaltThroughput);
    for (std::size_t i = 0; i < count; ++i) {
        const glm::dvec3 ray = randomPixelRay(rng.uniform(4 * i), rng.uniform(4 * i + 1),
                                              kVisibleFovDegrees, kVisibleAspect);
        const glm::dvec3 n = hemisphereAround(-glm::normalize(ray), rng.uniform(4 * i + 2),
                                              rng.uniform(4 * i + 3), true);
        nx[i] = float(n.x), ny[i] = float(n.y), nz[i] = float(n.z);
        rx[i] = float(ray.x), ry[i] = float(ray.y), rz[i] = float(ray.z);
    }
    double bestEncode = std::numeric_limits<double>::infinity(), bestDecode = bestEncode;
    for (int r = 0; r < repeats; ++r) {
        auto start = Clock::now();
        for (std::size_t i = 0; i < count; ++i) {
            const NormalCode code =
                gbuffer::encodeNormal(spec, {nx[i], ny[i], nz[i]}, {rx[i], ry[i], rz[i]});
            low[i] = code.low;
            high[i] = code.high;
        }
        bestEncode =
            std::min(bestEncode, std::chrono::duration<double>(Clock::now() - start).count());
        start = Clock::now();
        for (std::size_t i = 0; i < count; ++i) {
            const glm::vec3 n =
                gbuffer::decodeNormal(spec, {low[i], high[i]}, {rx[i], ry[i], rz[i]});
            ox[i] = n.x, oy[i] = n.y, oz[i] = n.z;
        }
        bestDecode =
            std::min(bestDecode, std::chrono::duration<double>(Clock::now() - start).count());
    }
    // The outputs are read once so the loops cannot be dropped.
    volatile float sink = ox[count / 2] + oy[count / 3] + oz[count - 1];
    (void)sink;
    encodePerSecond = static_cast<double>(count) / std::max(bestEncode, 1e-9);
    decodePerSecond = static_cast<double>(count) / std::max(bestDecode, 1e-9);
}

int mapBits(NormalCodecKind kind) { // the depth each codec's error map is drawn at
    const std::vector<int> bits = gbuffer::supportedBits(kind);
    return std::find(bits.begin(), bits.end(), 16) != bits.end() ? 16 : bits.front();
}

// Row-major, row 0 = latitude +90 (+Z, facing the camera), column 0 = longitude -180 degrees
// (azimuth atan2(y, x)); each cell the max error over sub x sub stratified samples, in degrees.
std::vector<float> errorMap(const NormalCodecSpec& spec, int width, int height, int sub) {
    std::vector<float> map(std::size_t(width) * height);
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            double worst = 0.0;
            for (int sy = 0; sy < sub; ++sy)
                for (int sx = 0; sx < sub; ++sx) {
                    const double lon = -kPi + 2.0 * kPi * (x + (sx + 0.5) / sub) / width;
                    const double lat = 0.5 * kPi - kPi * (y + (sy + 0.5) / sub) / height;
                    const glm::vec3 n(glm::dvec3(std::cos(lat) * std::cos(lon),
                                                 std::cos(lat) * std::sin(lon), std::sin(lat)));
                    const glm::vec3 decoded =
                        gbuffer::decodeNormal(spec, gbuffer::encodeNormal(spec, n));
                    worst = std::max(
                        worst, finite3(decoded) ? gbuffer::normalAngleRadians(n, decoded) : kPi);
                }
            map[std::size_t(y) * width + x] = static_cast<float>(worst * kDegreesPerRadian);
        }
    });
    return map;
}

// --- visible negative-z fractions
// ------------------------------------------------------------------

NegativeZFraction negativeZFraction(double fovDegrees, double aspect, std::uint64_t count,
                                    std::uint64_t seed) {
    const CounterRng rng(seed, kSaltNegativeZ);
    std::vector<std::pair<std::uint64_t, std::uint64_t>> perChunk((count + kChunkSamples - 1) /
                                                                  kChunkSamples);
    forEachChunk(count, [&](std::uint64_t chunk, std::uint64_t begin, std::uint64_t end) {
        std::uint64_t uniform = 0, weighted = 0;
        for (std::uint64_t i = begin; i < end; ++i) {
            const glm::dvec3 towards = -glm::normalize(
                randomPixelRay(rng.uniform(6 * i), rng.uniform(6 * i + 1), fovDegrees, aspect));
            uniform +=
                hemisphereAround(towards, rng.uniform(6 * i + 2), rng.uniform(6 * i + 3), false).z <
                0.0;
            weighted +=
                hemisphereAround(towards, rng.uniform(6 * i + 4), rng.uniform(6 * i + 5), true).z <
                0.0;
        }
        perChunk[chunk] = {uniform, weighted};
    });
    std::uint64_t uniform = 0, weighted = 0;
    for (const auto& [u, w] : perChunk)
        uniform += u, weighted += w;
    NegativeZFraction result{fovDegrees, aspect, double(uniform) / double(count),
                             double(weighted) / double(count)};
    // Closed forms per ray, a = angle between the ray and -Z: the front-facing hemisphere (pole
    // -ray) and the half space z < 0 meet in a lune of dihedral angle a, area 2a of the
    // hemisphere's 2 pi (uniform: a / pi); projected onto the disc around -ray, that lune covers
    // (pi / 2)(1 - cos a) of the disc's pi (area-weighted: (1 - cos a) / 2).
    constexpr int kGrid = 1024;
    double uniformSum = 0.0, weightedSum = 0.0;
    for (int y = 0; y < kGrid; ++y)
        for (int x = 0; x < kGrid; ++x) {
            const glm::dvec3 ray =
                randomPixelRay((x + 0.5) / kGrid, (y + 0.5) / kGrid, fovDegrees, aspect);
            const double cosA = 1.0 / glm::length(ray); // ray.z = -1
            uniformSum += std::acos(cosA) / kPi;
            weightedSum += 0.5 * (1.0 - cosA);
        }
    result.uniformExact = uniformSum / (double(kGrid) * kGrid);
    result.areaWeightedExact = weightedSum / (double(kGrid) * kGrid);
    return result;
}

// --- scenes --------------------------------------------------------------------------------------

Dataset sceneDataset(const std::string& source, const std::string& label, int width, int height,
                     NormalStudyScene& info, std::vector<std::string>& warnings) {
    scenes::SceneRequest request; // no generated lights: only the geometry matters here
    scenes::Scene scene = scenes::loadScene(source, request);
    for (const std::string& warning : scene.warnings)
        warnings.push_back(label + ": " + warning);
    lighting::PreparedScene prepared(std::move(scene), width, height);
    const gbuffer::GBuffer& gb = *prepared.gbuffer;
    const gbuffer::CameraView& view = prepared.view;
    Dataset data{"scene:" + label, {}, {}};
    std::uint64_t negative = 0, backFacing = 0;
    for (int y = 0; y < gb.height(); ++y)
        for (int x = 0; x < gb.width(); ++x) {
            if (!gb.covered(std::size_t(y) * gb.width() + x))
                continue;
            const glm::vec3 n = gb.decode(x, y).normalView;
            const glm::vec3 ray = gbuffer::viewRayOfNdc(view, view.ndcOfPixel(x, y));
            data.normals.push_back(n);
            data.rays.push_back(ray);
            negative += n.z < 0.0f;
            backFacing += glm::dot(n, ray) > 0.0f;
        }
    info.dataset = data.name;
    info.source = source;
    info.width = width;
    info.height = height;
    info.coveredPixels = data.normals.size();
    const double covered = std::max<double>(1.0, double(data.normals.size()));
    info.negativeZFraction = double(negative) / covered;
    info.backFacingFraction = double(backFacing) / covered;
    return data;
}

std::vector<std::filesystem::path> findModels(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> models;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
        const std::string ext = entry.path().extension().string();
        if (entry.is_regular_file() && (ext == ".gltf" || ext == ".glb"))
            models.push_back(entry.path());
    }
    std::sort(models.begin(), models.end());
    return models;
}

// --- outputs -------------------------------------------------------------------------------------

nlohmann::json rowJson(const NormalStudyRow& r) {
    return {{"codec", r.codec},
            {"name", r.name},
            {"bits", r.bits},
            {"dataset", r.dataset},
            {"samples", r.samples},
            {"nan_inf_outputs", r.nanInfOutputs},
            {"mean_deg", r.meanDegrees},
            {"rms_deg", r.rmsDegrees},
            {"p999_deg", r.p999Degrees},
            {"max_deg", r.maxDegrees},
            {"bound_deg", r.boundDegrees},
            {"bound_region_samples", r.boundRegionSamples},
            {"max_in_bound_region_deg", r.maxInBoundRegionDegrees},
            {"within_bound", r.withinBound()},
            {"negative_z_samples", r.negativeZSamples},
            {"mean_negative_z_deg", r.meanNegativeZDegrees},
            {"max_negative_z_deg", r.maxNegativeZDegrees},
            {"worse_than_octahedral", r.worseThanOctahedral},
            {"zero_vector_decodes_to", r.zeroVectorDecodesTo},
            {"occupancy", r.occupancy},
            {"occupancy_codes_tested", r.occupancyCodesTested},
            {"encode_per_s_1thread_study", r.encodePerSecond},
            {"decode_per_s_1thread_study", r.decodePerSecond}};
}

std::string csvText(const std::vector<NormalStudyRow>& rows) {
    std::ostringstream csv;
    csv << std::setprecision(9);
    csv << "codec,name,bits,dataset,samples,nan_inf_outputs,mean_deg,rms_deg,p999_deg,max_deg,"
           "bound_deg,bound_region_samples,max_in_bound_region_deg,within_bound,negative_z_samples,"
           "mean_negative_z_deg,max_negative_z_deg,worse_than_octahedral,zero_vector_decodes_to,"
           "occupancy,occupancy_codes_tested,encode_per_s_1thread_study,decode_per_s_1thread_"
           "study\n";
    for (const NormalStudyRow& r : rows)
        csv << r.codec << "," << r.name << "," << r.bits << "," << r.dataset << "," << r.samples
            << "," << r.nanInfOutputs << "," << r.meanDegrees << "," << r.rmsDegrees << ","
            << r.p999Degrees << "," << r.maxDegrees << "," << r.boundDegrees << ","
            << r.boundRegionSamples << "," << r.maxInBoundRegionDegrees << ","
            << (r.withinBound() ? "true" : "false") << "," << r.negativeZSamples << ","
            << r.meanNegativeZDegrees << "," << r.maxNegativeZDegrees << ","
            << r.worseThanOctahedral << ",\"" << r.zeroVectorDecodesTo << "\"," << r.occupancy
            << "," << r.occupancyCodesTested << "," << r.encodePerSecond << "," << r.decodePerSecond
            << "\n";
    return csv.str();
}

void writeFloats(const std::filesystem::path& path, const std::vector<float>& values) {
    writeFileAtomically(path, [&](const std::filesystem::path& temp) {
        std::ofstream file(temp, std::ios::binary);
        file.write(reinterpret_cast<const char*>(values.data()),
                   static_cast<std::streamsize>(values.size() * sizeof(float)));
        if (!file)
            throw std::runtime_error("cannot write " + temp.string());
    });
}

} // namespace

NormalStudyResult runNormalStudy(const NormalStudyOptions& options,
                                 const std::function<void(const std::string&)>& progress) {
    auto step = [&](const std::string& what) {
        if (progress)
            progress(what);
    };
    // Validate everything before any work.
    if (options.out.empty())
        throw std::invalid_argument("--out: an output folder is required");
    const std::uint64_t directions = options.directions.value_or(
        options.quick ? kNormalStudyQuickDirections : kNormalStudyDirections);
    if (directions < 1000 || directions > 1'000'000'000)
        throw std::invalid_argument("--directions " + std::to_string(directions) +
                                    ": expected 1000 .. 1000000000");
    if (options.threads < 0 || options.threads > 1024)
        throw std::invalid_argument("--threads " + std::to_string(options.threads) +
                                    ": expected 0 .. 1024");
    const int sceneWidth = options.quick ? kQuickSceneWidth : options.sceneWidth;
    const int sceneHeight = options.quick ? kQuickSceneHeight : options.sceneHeight;
    if (sceneWidth < 1 || sceneHeight < 1 || sceneWidth > 8192 || sceneHeight > 8192)
        throw std::invalid_argument("--width/--height " + std::to_string(sceneWidth) + "x" +
                                    std::to_string(sceneHeight) + ": expected 1 .. 8192 each");
    for (const std::string& scene : options.scenes)
        if (!scenes::isProceduralScene(scene) && !std::filesystem::is_regular_file(scene)) {
            std::string names;
            for (const std::string& name : scenes::proceduralSceneNames())
                names += " " + name;
            throw std::invalid_argument("--scene '" + scene + "': not a built-in scene (" +
                                        names.substr(1) + ") and no such file");
        }
    std::string plotsScript = options.plotsScript.empty() ? std::string(TESTBED_SOURCE_DIR) +
                                                                "/experiments/plots/normals.py"
                                                          : options.plotsScript;
    if (options.plots && !std::filesystem::is_regular_file(plotsScript))
        throw std::invalid_argument("--plots-script '" + plotsScript + "': no such file");
    ensureWritableDirectory(options.out);
    std::filesystem::create_directories(options.out / "maps");

    NormalStudyResult result;
    const int threads = options.threads > 0 ? options.threads
                                            : std::max(1, int(std::thread::hardware_concurrency()));
    nlohmann::json timings = nlohmann::json::object();
    auto timed = [&](const std::string& name, auto&& fn) {
        const auto start = Clock::now();
        fn();
        timings[name] = std::chrono::duration<double>(Clock::now() - start).count();
    };
    const std::vector<NormalCodecSpec> specs = gbuffer::allNormalCodecSpecs();
    std::vector<std::string> modelSources;
    std::filesystem::path modelsDir;
    if (options.modelsDir || !options.quick) {
        modelsDir = options.modelsDir.value_or(kNormalStudyModelsDir);
        if (std::filesystem::is_directory(modelsDir)) {
            for (const std::filesystem::path& model : findModels(modelsDir))
                modelSources.push_back(model.string());
        } else {
            result.warnings.push_back("models folder " + modelsDir.string() +
                                      " not found: no glTF models studied");
        }
    }

    std::vector<std::vector<NormalStudyRow>> rowsBySpec(specs.size());
    std::vector<nlohmann::json> maps;
    tbb::task_arena arena(threads);
    arena.execute([&] {
        std::vector<float> errors;
        auto addDataset = [&](const Dataset& data) {
            for (std::size_t s = 0; s < specs.size(); ++s)
                rowsBySpec[s].push_back(evaluate(specs[s], data, errors));
        };
        timed("sphere", [&] {
            step("sphere: " + std::to_string(directions) + " uniform directions x " +
                 std::to_string(specs.size()) + " codecs");
            addDataset(sphereDataset(directions, options.seed));
        });
        timed("visible-60", [&] {
            step("visible-60: " + std::to_string(directions) + " front-facing normals");
            addDataset(visibleDataset(directions, options.seed));
        });
        timed("scenes", [&] {
            std::vector<std::pair<std::string, std::string>> sources; // source, label
            for (const std::string& s : options.scenes)
                sources.emplace_back(
                    s, scenes::isProceduralScene(s) ? s : std::filesystem::path(s).stem().string());
            for (const std::string& s : modelSources)
                sources.emplace_back(s, std::filesystem::path(s).stem().string());
            for (const auto& [source, label] : sources) {
                step("scene " + label + " at " + std::to_string(sceneWidth) + "x" +
                     std::to_string(sceneHeight));
                NormalStudyScene info;
                const Dataset data =
                    sceneDataset(source, label, sceneWidth, sceneHeight, info, result.warnings);
                result.scenes.push_back(info);
                addDataset(data);
            }
        });
        timed("hard", [&] {
            step("hard cases");
            const Dataset hard = hardDataset();
            for (std::size_t s = 0; s < specs.size(); ++s) {
                NormalStudyRow row = evaluate(specs[s], hard, errors);
                row.zeroVectorDecodesTo = vecText(gbuffer::decodeNormal(
                    specs[s], gbuffer::encodeNormal(specs[s], glm::vec3(0.0f))));
                rowsBySpec[s].push_back(row);
            }
        });
        timed("negative_z_fractions", [&] {
            step("negative view-space z fractions at 45/60/90 degrees");
            for (double fov : {45.0, 60.0, 90.0})
                for (double aspect : {16.0 / 9.0, 1.0})
                    result.negativeZ.push_back(
                        negativeZFraction(fov, aspect, directions, options.seed));
        });
        timed("occupancy", [&] {
            step("occupancy (encode(decode(code)) == code)");
            for (std::size_t s = 0; s < specs.size(); ++s) {
                const Occupancy occupancy = measureOccupancy(specs[s], options.quick, options.seed);
                for (NormalStudyRow& row : rowsBySpec[s]) {
                    row.occupancy = occupancy.fraction;
                    row.occupancyCodesTested = occupancy.tested;
                }
            }
        });
        timed("maps", [&] {
            step("error maps");
            const int w = options.quick ? kQuickMapWidth : kMapWidth;
            const int h = options.quick ? kQuickMapHeight : kMapHeight;
            const int sub = options.quick ? kQuickMapSub : kMapSub;
            for (const NormalCodecSpec& spec : specs) {
                if (spec.bits != mapBits(spec.kind))
                    continue;
                const std::string stem = std::string(gbuffer::normalCodecName(spec.kind)) + "-" +
                                         std::to_string(spec.bits);
                const std::vector<float> grid = errorMap(spec, w, h, sub);
                writeFloats(options.out / "maps" / (stem + ".f32"), grid);
                maps.push_back({{"codec", spec.text()},
                                {"name", gbuffer::normalCodecName(spec.kind)},
                                {"bits", spec.bits},
                                {"data", "maps/" + stem + ".f32"},
                                {"png", "maps/" + stem + ".png"},
                                {"width", w},
                                {"height", h},
                                {"samples_per_cell", sub * sub},
                                {"max_deg", *std::max_element(grid.begin(), grid.end())}});
            }
        });
    });
    // Throughput last, on this thread alone, with no parallel work running.
    timed("throughput", [&] {
        step("single-threaded encode/decode throughput (wall clock of this run)");
        const std::size_t count = options.quick ? kThroughputQuickNormals : kThroughputNormals;
        const int repeats = options.quick ? 1 : kThroughputRepeats;
        for (std::size_t s = 0; s < specs.size(); ++s) {
            double encode = 0.0, decode = 0.0;
            measureThroughput(specs[s], count, repeats, options.seed, encode, decode);
            for (NormalStudyRow& row : rowsBySpec[s]) {
                row.encodePerSecond = encode;
                row.decodePerSecond = decode;
            }
        }
    });
    for (const std::vector<NormalStudyRow>& rows : rowsBySpec)
        result.rows.insert(result.rows.end(), rows.begin(), rows.end());

    nlohmann::json& json = result.json;
    json["study"] = "normals";
    json["commit"] = kBuildCommit;
    json["hardware_threads"] = std::thread::hardware_concurrency();
    json["config"] = {
        {"directions", directions},
        {"seed", options.seed},
        {"scenes", options.scenes},
        {"models_dir", modelsDir.string()},
        {"models", modelSources},
        {"scene_width", sceneWidth},
        {"scene_height", sceneHeight},
        {"threads", threads},
        {"quick", options.quick},
        {"visible_fov_deg", kVisibleFovDegrees},
        {"visible_aspect", kVisibleAspect},
        {"throughput_normals", options.quick ? kThroughputQuickNormals : kThroughputNormals},
        {"occupancy_exhaustive_max_bits", options.quick ? 16 : kOccupancyExhaustiveBits}};
    json["datasets"] = {
        {"sphere", "directions uniform on the sphere, central view ray"},
        {"visible-60",
         "front-facing normals weighted by projected area (cosine around -ray) for a "
         "uniformly random pixel of a 60 deg vertical FOV 16:9 camera; pixel-view gets the ray"},
        {"scene:NAME",
         "view-space normals of the covered pixels of a render of NAME (first camera), with "
         "each pixel's view ray"},
        {"hard",
         "hardNormalCases(): axes, -Z and poles, octahedral edges, one zero component, back "
         "faces, near-unit, subnormal, huge, zero and non-finite inputs, off-axis and degenerate "
         "rays"}};
    json["rows"] = nlohmann::json::array();
    for (const NormalStudyRow& row : result.rows)
        json["rows"].push_back(rowJson(row));
    json["scenes"] = nlohmann::json::array();
    for (const NormalStudyScene& scene : result.scenes)
        json["scenes"].push_back({{"dataset", scene.dataset},
                                  {"source", scene.source},
                                  {"width", scene.width},
                                  {"height", scene.height},
                                  {"covered_pixels", scene.coveredPixels},
                                  {"negative_z_fraction", scene.negativeZFraction},
                                  {"back_facing_fraction", scene.backFacingFraction}});
    json["negative_z_fractions"] = nlohmann::json::array();
    for (const NegativeZFraction& f : result.negativeZ)
        json["negative_z_fractions"].push_back({{"vertical_fov_deg", f.verticalFovDegrees},
                                                {"aspect", f.aspect},
                                                {"uniform_fraction", f.uniformFraction},
                                                {"area_weighted_fraction", f.areaWeightedFraction},
                                                {"uniform_exact", f.uniformExact},
                                                {"area_weighted_exact", f.areaWeightedExact},
                                                {"samples", directions}});
    json["maps"] = maps;
    json["hard_case_count"] = hardNormalCases().size();
    json["warnings"] = result.warnings;
    json["timings_s"] = timings;

    step("writing normals.csv, normals.json");
    writeTextAtomically(options.out / "normals.csv", csvText(result.rows));
    writeTextAtomically(options.out / "normals.json", json.dump(2) + "\n");

    if (options.plots) {
        step("plots (matplotlib)");
        const std::string python = findPythonWithMatplotlib(options.python);
        if (python.empty())
            throw std::runtime_error(
                "plots: no python3 with matplotlib found (" +
                (options.python.empty() ? std::string("tried python3 and /usr/bin/python3")
                                        : "tried --python " + options.python) +
                "); install Debian's python3-matplotlib or pass --python, or --no-plots to skip. " +
                "normals.csv and normals.json were written to " + options.out.string());
        const int status = runProcess({python, plotsScript, "--out", options.out.string()});
        if (status != 0)
            throw std::runtime_error("plots: " + python + " " + plotsScript + " --out " +
                                     options.out.string() + " failed with exit status " +
                                     std::to_string(status) +
                                     "; normals.csv and normals.json were written");
    }
    return result;
}

namespace {

void printSummary(const NormalStudyResult& result, std::ostream& out) {
    auto find = [&](const std::string& codec, const std::string& dataset) -> const NormalStudyRow* {
        for (const NormalStudyRow& row : result.rows)
            if (row.codec == codec && row.dataset == dataset)
                return &row;
        return nullptr;
    };
    out << "angular error in degrees; sphere = uniform directions, visible-60 = normals a 60 deg "
           "FOV "
           "camera sees\n";
    char line[400];
    std::snprintf(line, sizeof line,
                  "%-24s | %9s %9s %9s | %9s %9s | %9s %5s | %8s | %7s %7s | %s\n", "codec", "mean",
                  "p99.9", "max", "vis.mean", "vis.max", "bound", "ok", "occupied", "enc M/s",
                  "dec M/s", "hard: NaN, max finite");
    out << line;
    std::vector<std::string> seen;
    for (const NormalStudyRow& row : result.rows) {
        if (std::find(seen.begin(), seen.end(), row.codec) != seen.end())
            continue;
        seen.push_back(row.codec);
        const NormalStudyRow* sphere = find(row.codec, "sphere");
        const NormalStudyRow* visible = find(row.codec, "visible-60");
        const NormalStudyRow* hard = find(row.codec, "hard");
        if (!sphere || !visible || !hard)
            continue;
        // "ok": the measured max inside the bound region is within the derived bound on sphere
        // and visible-60.
        const bool ok = sphere->withinBound() && visible->withinBound();
        std::snprintf(line, sizeof line,
                      "%-24s | %9.5f %9.5f %9.5f | %9.5f %9.5f | %9.5f %5s | %7.3f%% | %7.1f %7.1f "
                      "| %llu, %.3g\n",
                      row.codec.c_str(), sphere->meanDegrees, sphere->p999Degrees,
                      sphere->maxDegrees, visible->meanDegrees, visible->maxDegrees,
                      sphere->boundDegrees, ok ? "yes" : "NO", 100.0 * sphere->occupancy,
                      sphere->encodePerSecond * 1e-6, sphere->decodePerSecond * 1e-6,
                      static_cast<unsigned long long>(hard->nanInfOutputs), hard->maxDegrees);
        out << line;
    }
    out << "(bound = derived max error incl. float slack, checked inside each codec's bound "
           "region; "
           "enc/dec M/s = one thread, wall clock of this run)\n\n";
    out << "rendered scenes: visible normals with view-space z < 0 and what xy-z does there\n";
    for (const NormalStudyScene& scene : result.scenes) {
        std::snprintf(line, sizeof line, "  %-22s %8llu px  z<0: %6.3f%%  back-facing: %6.3f%%",
                      scene.dataset.c_str(), static_cast<unsigned long long>(scene.coveredPixels),
                      100.0 * scene.negativeZFraction, 100.0 * scene.backFacingFraction);
        out << line;
        for (const char* codec : {"xy-z:32", "pixel-view:32"})
            if (const NormalStudyRow* row = find(codec, scene.dataset)) {
                std::snprintf(line, sizeof line, "  %s on z<0: mean %.3f max %.3f deg", codec,
                              row->meanNegativeZDegrees, row->maxNegativeZDegrees);
                out << line;
            }
        out << "\n";
    }
    out << "\nfraction of visible surface orientations with view-space z < 0 (random pixel, "
           "front-facing orientation)\n";
    for (const NegativeZFraction& f : result.negativeZ) {
        std::snprintf(
            line, sizeof line,
            "  vertical FOV %4.0f deg, aspect %5.3f: area-weighted %6.3f%% (exact %6.3f%%), "
            "uniform %6.3f%% (exact %6.3f%%)\n",
            f.verticalFovDegrees, f.aspect, 100.0 * f.areaWeightedFraction,
            100.0 * f.areaWeightedExact, 100.0 * f.uniformFraction, 100.0 * f.uniformExact);
        out << line;
    }
}

} // namespace

int runNormalStudyCommand(const NormalStudyOptions& options) {
    const auto start = Clock::now();
    auto progress = [&](const std::string& what) {
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        std::cerr << "[" << std::fixed << std::setprecision(1) << seconds << " s] " << what << "\n";
    };
    try {
        const NormalStudyResult result = runNormalStudy(options, progress);
        for (const std::string& warning : result.warnings)
            std::cerr << "testbed normals: warning: " << warning << "\n";
        printSummary(result, std::cout);
        std::cout << "outputs in " << std::filesystem::absolute(options.out).string() << "\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "testbed normals: error: " << e.what() << "\n";
        return 1;
    }
}

} // namespace experiments
