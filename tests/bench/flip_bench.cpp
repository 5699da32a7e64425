// ꟻLIP (experiments/compare/Flip.h) of a 1280x720 pair, HDR and LDR, on 1 and 2 threads (a
// tbb::task_arena of that many), wall clock per call. The pair: the atrium (256 lights, seed 1)
// shaded by brute as the reference, and the same frame with deterministic noise of +-4% per
// channel as the test (a noisy render); HDR-ꟻLIP takes its exposures from the reference (the
// `exposures` counter). Counters: the best and median call (ms), the process CPU time per call
// (ms, all threads: on a loaded machine wall time grows while CPU time does not).
//   build/bin/testbed_bench --benchmark_filter=flip --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <vector>

#include <tbb/task_arena.h>

#include "experiments/compare/Flip.h"
#include "lighting/StageRegistry.h"
#include "tests/bench/BenchScenes.h"

namespace {

using experiments::compare::computeFlip;
using experiments::compare::FlipImage;
using experiments::compare::FlipMode;
using experiments::compare::FlipOptions;
using experiments::compare::FlipResult;

struct FlipPair {
    std::vector<float> reference[3], test[3];
    FlipImage referenceView() const {
        return {bench::kWidth, bench::kHeight, reference[0].data(), reference[1].data(),
                reference[2].data()};
    }
    FlipImage testView() const {
        return {bench::kWidth, bench::kHeight, test[0].data(), test[1].data(), test[2].data()};
    }
};

const FlipPair& atriumPair() {
    static const FlipPair pair = [] {
        FlipPair p;
        bench::BenchScene frame("atrium", 256);
        lighting::StageResult result;
        lighting::makeStage("brute")->shade(frame.inputs, result);
        std::uint64_t state = 2026; // SplitMix64: the same noise on every machine
        auto next = [&state] {
            std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
            z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
            z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
            return double((z ^ (z >> 31)) >> 11) / double(1ull << 53);
        };
        for (int c = 0; c < 3; ++c) {
            p.reference[c] = result.radiance[c];
            p.test[c] = result.radiance[c];
            for (float& v : p.test[c])
                v *= float(1.0 + 0.08 * (next() - 0.5));
        }
        return p;
    }();
    return pair;
}

double processCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

void flipAtrium(benchmark::State& state, FlipMode mode, int threads) {
    const FlipPair& pair = atriumPair();
    FlipOptions options;
    options.mode = mode;
    tbb::task_arena arena(threads);
    FlipResult result;
    std::vector<double> wallMs, cpuMs;
    for (auto _ : state) {
        const double cpuStart = processCpuSeconds();
        const auto start = std::chrono::steady_clock::now();
        arena.execute(
            [&] { result = computeFlip(pair.testView(), pair.referenceView(), options); });
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        cpuMs.push_back(1e3 * (processCpuSeconds() - cpuStart));
        wallMs.push_back(1e3 * seconds);
        state.SetIterationTime(seconds);
    }
    std::sort(wallMs.begin(), wallMs.end());
    std::sort(cpuMs.begin(), cpuMs.end());
    state.counters["best_ms"] = wallMs.front();
    state.counters["median_ms"] = wallMs[wallMs.size() / 2];
    state.counters["cpu_median_ms"] = cpuMs[cpuMs.size() / 2];
    state.counters["exposures"] = result.exposureCount;
    state.counters["flip_mean"] = result.mean;
}

BENCHMARK_CAPTURE(flipAtrium, hdr_1thread, FlipMode::Hdr, 1)
    ->UseManualTime()
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(flipAtrium, hdr_2threads, FlipMode::Hdr, 2)
    ->UseManualTime()
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(flipAtrium, ldr_1thread, FlipMode::Ldr, 1)
    ->UseManualTime()
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(flipAtrium, ldr_2threads, FlipMode::Ldr, 2)
    ->UseManualTime()
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond);

} // namespace
