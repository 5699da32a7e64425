// NormalStatistics: what the normal-encoding study (NormalStudy.h) measures on its data sets:
// the angular error statistics of one codec on one data set (mean, rms, nearest-rank 99.9th
// percentile, max, inside the codec's bound region, on normals facing away from the camera), the
// occupancy of a codec's codes, its single-threaded encode/decode throughput, its equirectangular
// error map, and the fraction of visible orientations with view-space z < 0 at a field of view.
//
// Determinism: per-chunk statistics merged in chunk order (no atomics, no order-dependent float
// sums), so every figure but the throughput is the same for any thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "experiments/studies/NormalSampling.h"
#include "gbuffer/codecs/NormalCodec.h"

namespace experiments::normal_study {

// Occupancy is exhaustive up to 2^24 codes (16.7 M encodes per codec, a few seconds); larger
// codes are sampled (standard error of the fraction <= 0.5 / sqrt(samples) = 0.05 %).
inline constexpr int kOccupancyExhaustiveBits = 24;
inline constexpr int kOccupancyQuickExhaustiveBits = 16;
inline constexpr std::uint64_t kOccupancySamples = std::uint64_t{1} << 20;
inline constexpr std::uint64_t kOccupancyQuickSamples = std::uint64_t{1} << 14;
// Throughput: SoA arrays of this many normals, best of kThroughputRepeats timed loops.
inline constexpr std::size_t kThroughputNormals = std::size_t{1} << 16;
inline constexpr std::size_t kThroughputQuickNormals = std::size_t{1} << 10;
inline constexpr int kThroughputRepeats = 3;

// Errors of one codec on one data set. `errors` is scratch (reused across codecs). The per-codec
// figures (occupancy, throughput) and the hard set's zero-vector text are left for the caller.
NormalStudyRow evaluate(const gbuffer::NormalCodecSpec& spec, const Dataset& data,
                        std::vector<float>& errors);

// What (0, 0, 0) decodes to, as "(x, y, z)" with 9 significant digits.
std::string zeroVectorDecodesTo(const gbuffer::NormalCodecSpec& spec);

struct Occupancy {
    double fraction = 0.0;
    std::uint64_t tested = 0;
};
// Fraction of the 2^bits codes c with encode(decode(c)) == c: the codes that the encoder writes
// for their own direction, i.e. the distinct directions the format can hold.
Occupancy measureOccupancy(const gbuffer::NormalCodecSpec& spec, bool quick, std::uint64_t seed);

struct Throughput {
    double encodePerSecond = 0.0;
    double decodePerSecond = 0.0;
};
// Normals per second on the calling thread, SoA arrays, best of `repeats`.
Throughput measureThroughput(const gbuffer::NormalCodecSpec& spec, std::size_t count, int repeats,
                             std::uint64_t seed);

// The bit depth each codec's error map is drawn at: 16 where supported, else its smallest.
int mapBits(gbuffer::NormalCodecKind kind);
// Row-major, row 0 = latitude +90 (+Z, facing the camera), column 0 = longitude -180 degrees
// (azimuth atan2(y, x)); each cell the max error over sub x sub stratified samples, in degrees.
std::vector<float> errorMap(const gbuffer::NormalCodecSpec& spec, int width, int height, int sub);

NegativeZFraction negativeZFraction(double fovDegrees, double aspect, std::uint64_t count,
                                    std::uint64_t seed);

} // namespace experiments::normal_study
