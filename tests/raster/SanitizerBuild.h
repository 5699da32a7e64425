// Whether this test binary is the AddressSanitizer + UBSan build (./run.sh asan, which CI runs),
// and the sampling of exhaustive state sweeps there.
//
// The bitwise sweeps (every depth test x depth write x cull mode x sample count x thread count)
// cost minutes under the sanitizers, which look for memory errors and undefined behaviour: every
// code path those can hide in is reached by a sample of the cases, while the Release suite
// (./run.sh test) keeps every case. A stride coprime with each axis's size keeps every value of
// every axis in the sample.
#pragma once

namespace raster_test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizerBuild = true; // GCC
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitizerBuild = true; // clang
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif

// Whether case `index` (0, 1, ...) of an exhaustive sweep runs: every case in Release, every
// `stride`-th under the sanitizers.
constexpr bool sweepRunsCase(int index, int stride) {
    return !kSanitizerBuild || index % stride == 0;
}

// How many of `cases` cases sweepRunsCase runs.
constexpr int sweptCaseCount(int cases, int stride) {
    return kSanitizerBuild ? (cases + stride - 1) / stride : cases;
}

} // namespace raster_test
