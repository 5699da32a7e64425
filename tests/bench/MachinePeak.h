// MachinePeak: this core's clock and FP32 FMA throughput, measured, for the kernel benchmark's
// "fraction of peak" (the kernel's GFLOP/s against what the FMA units can do).
//
// - Clock: a chain of dependent 64-bit integer adds retires one add per cycle on every x86 core
//   since the P6 (latency 1), so adds per second is cycles per second. This is the clock the core
//   actually runs at under load (boost included), which /proc/cpuinfo does not give inside a VM
//   (it reports the TSC's 2096 MHz on the development machine).
// - FMA throughput: 12 independent vfmadd231ps chains (more than latency x pipes = 4 x 2), so
//   FMA instructions per cycle is the number of FMA pipes at that width. AMD documents two FMA
//   pipes (FP0, FP1) for Zen 5 with a native 512-bit datapath on desktop and server parts
//   (Software Optimization Guide for the AMD Zen 5 Microarchitecture, pub. 58455; A. Yee,
//   "Zen5's AVX512 Teardown", numberworld.org, 2024); the measurement checks it on this machine.
// Peak FP32 flops per cycle = lanes x FMA pipes x 2 (a fused multiply-add is two flops).
// Both are timed in the calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID), so time the thread
// spends descheduled on a shared machine does not count; the best of 5 repetitions is kept.
// x86-64 only (inline assembly); each measurement takes ~100 ms.
#pragma once

#include <algorithm>
#include <cstdint>
#include <ctime>

namespace bench {

// CPU time of the calling thread, in seconds: the timer of the single-threaded kernel benchmarks.
inline double threadCpuSeconds() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

inline double measuredClockHz() {
    double best = 0.0;
    for (int repetition = 0; repetition < 5; ++repetition) {
        uint64_t x = 0;
        constexpr int kIterations = 1'000'000;
        const double start = threadCpuSeconds();
        for (int i = 0; i < kIterations; ++i)
            asm volatile(".rept 100\n\taddq $1, %0\n\t.endr" : "+r"(x));
        const double seconds = threadCpuSeconds() - start;
        best = std::max(best, 100.0 * kIterations / seconds);
    }
    return best;
}

// Twelve independent FMA chains on registers 0..11, from the constant registers 12 and 13.
#define BENCH_FMA12(R)                                                                             \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "0\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "1\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "2\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "3\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "4\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "5\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "6\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "7\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "8\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "9\n\t"                                               \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "10\n\t"                                              \
    "vfmadd231ps %%" R "12, %%" R "13, %%" R "11\n\t"
// Zero idioms (no execution port) at the start of every block: the registers hold zeros whatever
// the compiler did with them in between, and each block's chains are 2 FMAs deep.
#define BENCH_ZERO14                                                                               \
    "vpxor %%xmm0, %%xmm0, %%xmm0\n\tvpxor %%xmm1, %%xmm1, %%xmm1\n\t"                             \
    "vpxor %%xmm2, %%xmm2, %%xmm2\n\tvpxor %%xmm3, %%xmm3, %%xmm3\n\t"                             \
    "vpxor %%xmm4, %%xmm4, %%xmm4\n\tvpxor %%xmm5, %%xmm5, %%xmm5\n\t"                             \
    "vpxor %%xmm6, %%xmm6, %%xmm6\n\tvpxor %%xmm7, %%xmm7, %%xmm7\n\t"                             \
    "vpxor %%xmm8, %%xmm8, %%xmm8\n\tvpxor %%xmm9, %%xmm9, %%xmm9\n\t"                             \
    "vpxor %%xmm10, %%xmm10, %%xmm10\n\tvpxor %%xmm11, %%xmm11, %%xmm11\n\t"                       \
    "vpxor %%xmm12, %%xmm12, %%xmm12\n\tvpxor %%xmm13, %%xmm13, %%xmm13\n\t"
#define BENCH_FMA_CLOBBERS                                                                         \
    "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7", "xmm8", "xmm9", "xmm10",       \
        "xmm11", "xmm12", "xmm13"

// FMA instructions per second at `bits` = 256 or 512 (the caller checks the CPU has it).
inline double measuredFmaPerSecond(int bits) {
    double best = 0.0;
    for (int repetition = 0; repetition < 5; ++repetition) {
        constexpr int kIterations = 1'000'000;
        const double start = threadCpuSeconds();
        for (int i = 0; i < kIterations; ++i) {
            if (bits == 512)
                asm volatile(BENCH_ZERO14 BENCH_FMA12("zmm") BENCH_FMA12("zmm")::
                                 : BENCH_FMA_CLOBBERS);
            else
                asm volatile(BENCH_ZERO14 BENCH_FMA12("ymm") BENCH_FMA12("ymm")::
                                 : BENCH_FMA_CLOBBERS);
        }
        const double seconds = threadCpuSeconds() - start;
        best = std::max(best, 24.0 * kIterations / seconds);
    }
    return best;
}

#undef BENCH_FMA12
#undef BENCH_ZERO14
#undef BENCH_FMA_CLOBBERS

} // namespace bench
