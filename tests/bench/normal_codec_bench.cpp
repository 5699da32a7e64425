// Encode and decode throughput of every normal codec x bits (gbuffer/codecs/NormalCodec.h), one
// thread, structure-of-arrays loops over 1M normals as a G-buffer pass would see them: front-facing
// normals for random pixels of a 60 degree FOV 16:9 camera, each with its view ray (only
// pixel-view reads it). items_per_second = normals per second per core.
//   build/bin/testbed_bench --benchmark_filter='normal(Encode|Decode)'
// Benchmarks are named by spec, e.g. normalEncode/octahedral-precise:24.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "gbuffer/codecs/NormalCodec.h"

namespace {

constexpr std::size_t kNormalCount = std::size_t{1} << 20;

struct NormalArrays {
    std::vector<float> x, y, z, rayX, rayY, rayZ;
};

// Deterministic inputs (SplitMix64), built once: rays through uniform pixels, normals uniform on
// the hemisphere facing each ray.
const NormalArrays& inputs() {
    static const NormalArrays arrays = [] {
        NormalArrays a;
        std::uint64_t state = 2024;
        auto uniform = [&state] {
            std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
            z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
            z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
            return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
        };
        const double tanHalf = std::tan(std::numbers::pi / 6.0), aspect = 16.0 / 9.0;
        for (std::size_t i = 0; i < kNormalCount; ++i) {
            const glm::dvec3 ray((2.0 * uniform() - 1.0) * tanHalf * aspect,
                                 (2.0 * uniform() - 1.0) * tanHalf, -1.0);
            const double z = 1.0 - 2.0 * uniform(), phi = 2.0 * std::numbers::pi * uniform();
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
            glm::dvec3 n(r * std::cos(phi), r * std::sin(phi), z);
            if (glm::dot(n, ray) > 0.0)
                n = -n;
            a.x.push_back(float(n.x)), a.y.push_back(float(n.y)), a.z.push_back(float(n.z));
            a.rayX.push_back(float(ray.x)), a.rayY.push_back(float(ray.y)),
                a.rayZ.push_back(float(ray.z));
        }
        return a;
    }();
    return arrays;
}

void normalEncode(benchmark::State& state, gbuffer::NormalCodecSpec spec) {
    const NormalArrays& in = inputs();
    std::vector<std::uint64_t> low(kNormalCount);
    std::vector<std::uint32_t> high(kNormalCount);
    for (auto _ : state) {
        for (std::size_t i = 0; i < kNormalCount; ++i) {
            const gbuffer::NormalCode code = gbuffer::encodeNormal(
                spec, {in.x[i], in.y[i], in.z[i]}, {in.rayX[i], in.rayY[i], in.rayZ[i]});
            low[i] = code.low;
            high[i] = code.high;
        }
        benchmark::DoNotOptimize(low.data());
        benchmark::DoNotOptimize(high.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kNormalCount));
}

void normalDecode(benchmark::State& state, gbuffer::NormalCodecSpec spec) {
    const NormalArrays& in = inputs();
    std::vector<std::uint64_t> low(kNormalCount);
    std::vector<std::uint32_t> high(kNormalCount);
    for (std::size_t i = 0; i < kNormalCount; ++i) {
        const gbuffer::NormalCode code = gbuffer::encodeNormal(
            spec, {in.x[i], in.y[i], in.z[i]}, {in.rayX[i], in.rayY[i], in.rayZ[i]});
        low[i] = code.low;
        high[i] = code.high;
    }
    std::vector<float> x(kNormalCount), y(kNormalCount), z(kNormalCount);
    for (auto _ : state) {
        for (std::size_t i = 0; i < kNormalCount; ++i) {
            const glm::vec3 n = gbuffer::decodeNormal(spec, {low[i], high[i]},
                                                      {in.rayX[i], in.rayY[i], in.rayZ[i]});
            x[i] = n.x, y[i] = n.y, z[i] = n.z;
        }
        benchmark::DoNotOptimize(x.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::DoNotOptimize(z.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kNormalCount));
}

// One benchmark per spec, registered at start-up so new codecs appear without edits here.
const bool kRegistered = [] {
    for (const gbuffer::NormalCodecSpec& spec : gbuffer::allNormalCodecSpecs()) {
        benchmark::RegisterBenchmark(("normalEncode/" + spec.text()).c_str(), normalEncode, spec)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("normalDecode/" + spec.text()).c_str(), normalDecode, spec)
            ->Unit(benchmark::kMillisecond);
    }
    return true;
}();

} // namespace
