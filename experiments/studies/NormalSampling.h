// NormalSampling: the data sets of the normal-encoding study (NormalStudy.h): counter-based
// random numbers, the sampling of directions (uniform sphere, hemispheres around a view ray,
// random pixel rays), and the data sets built from them: sphere, visible-60, the hard cases and
// the normals of a rendered scene.
//
// Determinism: sample k of a stream is computed from (seed, salt, k) alone, and parallel work is
// split into fixed chunks of kChunkSamples, so every data set is the same for any thread count.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "experiments/studies/NormalStudy.h"

namespace experiments::normal_study {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDegreesPerRadian = 180.0 / kPi;
// Samples per parallel chunk: large enough to amortise scheduling (~1-10 ms of work), small
// enough to balance 10^7 samples over many cores. Fixed, so the merge order is fixed.
inline constexpr std::uint64_t kChunkSamples = std::uint64_t{1} << 15;
// The camera of the visible-60 dataset: the thesis' and the 60 degree vertical field of
// view on a 16:9 image (1280 x 720, the render default).
inline constexpr double kVisibleFovDegrees = 60.0;
inline constexpr double kVisibleAspect = 16.0 / 9.0;
// Salts separating the datasets' random streams.
inline constexpr std::uint64_t kSaltSphere = 1, kSaltVisible = 2, kSaltNegativeZ = 3,
                               kSaltOccupancy = 4, kSaltThroughput = 5, kSaltHard = 6;

std::uint64_t mix64(std::uint64_t z); // SplitMix64's finaliser (Steele et al. 2014)

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

glm::dvec3 uniformSphere(double u1, double u2);
// Orthonormal basis around a unit axis (Duff et al. 2017, "Building an orthonormal basis,
// revisited").
void basisAround(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b);
// Cosine-weighted (projected-area-weighted) direction around `axis`, or uniform on its
// hemisphere.
glm::dvec3 hemisphereAround(const glm::dvec3& axis, double u1, double u2, bool cosineWeighted);
// The view ray (z = -1) through a uniformly random point of the image of a pinhole camera.
glm::dvec3 randomPixelRay(double u1, double u2, double verticalFovDegrees, double aspect);

// fn(chunkIndex, begin, end) for the fixed chunks of [0, count), in parallel.
template <typename Fn> void forEachChunk(std::uint64_t count, Fn&& fn) {
    const std::uint64_t chunks = (count + kChunkSamples - 1) / kChunkSamples;
    tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, chunks, 1),
                      [&](const tbb::blocked_range<std::uint64_t>& range) {
                          for (std::uint64_t c = range.begin(); c != range.end(); ++c)
                              fn(c, c * kChunkSamples, std::min(count, (c + 1) * kChunkSamples));
                      });
}

struct Dataset {
    std::string name;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec3> rays; // empty: every sample is seen along kCentralViewRay
};

Dataset sphereDataset(std::uint64_t count, std::uint64_t seed);
Dataset visibleDataset(std::uint64_t count, std::uint64_t seed);
Dataset hardDataset(); // hardNormalCases()
// The covered pixels of `source` rendered from its first camera at width x height (float32
// G-buffer), with their view rays; `info` gets the scene's figures, `warnings` the loader's.
// The normals are the shading normals the G-buffer stores, after normal mapping. When a used
// material has a normal map, `geometric` receives the same render with the normal maps removed
// ("scene:LABEL:geometric", its figures in geometricInfo), and info.normalMappedFraction the
// share of covered pixels whose normal the maps changed; otherwise geometric stays empty.
Dataset sceneDataset(const std::string& source, const std::string& label, int width, int height,
                     NormalStudyScene& info, std::vector<std::string>& warnings, Dataset& geometric,
                     NormalStudyScene& geometricInfo);
// The .gltf and .glb files below dir, sorted.
std::vector<std::filesystem::path> findModels(const std::filesystem::path& dir);

} // namespace experiments::normal_study
