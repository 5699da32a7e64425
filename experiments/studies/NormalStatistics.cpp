#include "experiments/studies/NormalStatistics.h"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace experiments::normal_study {

namespace {

using gbuffer::NormalCode;
using gbuffer::NormalCodecKind;
using gbuffer::NormalCodecSpec;
using Clock = std::chrono::steady_clock;

bool finite3(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Sums and maxima of the errors of one chunk of samples (radians).
struct ChunkStats {
    std::uint64_t samples = 0, nanInf = 0, region = 0, negative = 0;
    std::int64_t worse = 0;
    double sum = 0.0, sumSquares = 0.0, max = 0.0, regionMax = 0.0, negativeSum = 0.0,
           negativeMax = 0.0;

    void merge(const ChunkStats& s) {
        samples += s.samples;
        nanInf += s.nanInf;
        region += s.region;
        negative += s.negative;
        worse += s.worse;
        sum += s.sum;
        sumSquares += s.sumSquares;
        max = std::max(max, s.max);
        regionMax = std::max(regionMax, s.regionMax);
        negativeSum += s.negativeSum;
        negativeMax = std::max(negativeMax, s.negativeMax);
    }
};

// Samples [begin, end) of `data` through `spec`; each sample's error goes to errors[i] (-1 when
// the input has no direction).
ChunkStats evaluateChunk(const NormalCodecSpec& spec, const Dataset& data, std::uint64_t begin,
                         std::uint64_t end, std::vector<float>& errors) {
    const bool precise = spec.kind == NormalCodecKind::OctahedralPrecise;
    const NormalCodecSpec plain{NormalCodecKind::Octahedral, spec.bits};
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
    return s;
}

// Nearest-rank 99.9th percentile of the errors of the samples with a direction (reorders them).
double p999(std::vector<float>& errors, std::uint64_t samples) {
    auto last = std::remove_if(errors.begin(), errors.end(), [](float e) { return e < 0.0f; });
    const std::size_t rank =
        static_cast<std::size_t>(std::ceil(0.999 * static_cast<double>(samples))) - 1;
    std::nth_element(errors.begin(), errors.begin() + rank, last);
    return static_cast<double>(errors[rank]);
}

// The row of the merged statistics, in degrees.
NormalStudyRow rowOf(const NormalCodecSpec& spec, const Dataset& data, const ChunkStats& total,
                     std::vector<float>& errors) {
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
        row.p999Degrees = p999(errors, total.samples) * kDegreesPerRadian;
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
    if (spec.kind == NormalCodecKind::OctahedralPrecise)
        row.worseThanOctahedral = total.worse;
    return row;
}

} // namespace

NormalStudyRow evaluate(const NormalCodecSpec& spec, const Dataset& data,
                        std::vector<float>& errors) {
    const std::uint64_t count = data.normals.size();
    errors.assign(count, -1.0f); // -1: no direction (not counted in the percentile)
    std::vector<ChunkStats> stats((count + kChunkSamples - 1) / kChunkSamples);
    forEachChunk(count, [&](std::uint64_t chunk, std::uint64_t begin, std::uint64_t end) {
        stats[chunk] = evaluateChunk(spec, data, begin, end, errors);
    });
    ChunkStats total;
    for (const ChunkStats& s : stats) // fixed order: deterministic sums
        total.merge(s);
    return rowOf(spec, data, total, errors);
}

std::string zeroVectorDecodesTo(const NormalCodecSpec& spec) {
    const glm::vec3 v = gbuffer::decodeNormal(spec, gbuffer::encodeNormal(spec, glm::vec3(0.0f)));
    std::ostringstream text;
    text << std::setprecision(9) << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return text.str();
}

NormalCode codeFromBits(const NormalCodecSpec& spec, std::uint64_t low, std::uint64_t high) {
    if (spec.bits >= 64)
        return {low, spec.bits > 64 ? static_cast<std::uint32_t>(high) : 0u};
    return {low & ((std::uint64_t{1} << spec.bits) - 1), 0u};
}

Occupancy measureOccupancy(const NormalCodecSpec& spec, bool quick, std::uint64_t seed) {
    const bool exhaustive =
        spec.bits <= (quick ? kOccupancyQuickExhaustiveBits : kOccupancyExhaustiveBits);
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

Throughput measureThroughput(const NormalCodecSpec& spec, std::size_t count, int repeats,
                             std::uint64_t seed) {
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
    return {static_cast<double>(count) / std::max(bestEncode, 1e-9),
            static_cast<double>(count) / std::max(bestDecode, 1e-9)};
}

int mapBits(NormalCodecKind kind) {
    const std::vector<int> bits = gbuffer::supportedBits(kind);
    return std::find(bits.begin(), bits.end(), 16) != bits.end() ? 16 : bits.front();
}

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

} // namespace experiments::normal_study
