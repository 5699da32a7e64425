// Which sanitizer this translation unit is compiled with (gcc defines __SANITIZE_*__, clang
// answers __has_feature): the few places whose behaviour must differ under one (JobProcess.cpp,
// the tests that measure memory or signals) ask here instead of spelling the macros out.
#pragma once

#if defined(__has_feature)
#define TESTBED_HAS_FEATURE(name) __has_feature(name)
#else
#define TESTBED_HAS_FEATURE(name) 0
#endif

namespace experiments {

#if defined(__SANITIZE_ADDRESS__) || TESTBED_HAS_FEATURE(address_sanitizer)
inline constexpr bool kAddressSanitizerBuild = true;
#else
inline constexpr bool kAddressSanitizerBuild = false;
#endif

#if defined(__SANITIZE_THREAD__) || TESTBED_HAS_FEATURE(thread_sanitizer)
inline constexpr bool kThreadSanitizerBuild = true;
#else
inline constexpr bool kThreadSanitizerBuild = false;
#endif

} // namespace experiments
