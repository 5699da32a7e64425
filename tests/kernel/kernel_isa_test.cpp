// Run-time selection of the shading kernel: the scalar path and every compiled Highway target this
// CPU supports are listed, "auto" picks the widest, names round-trip, unknown names are errors.
#include <gtest/gtest.h>

#include <stdexcept>

#include "lighting/kernel/KernelIsa.h"
#include "lighting/kernel/VectorTargets.h"

namespace {

using lighting::kernel::KernelIsa;

TEST(KernelIsa, ListsScalarThenTargetsNarrowestToWidest) {
    const std::vector<KernelIsa> isas = KernelIsa::available();
    ASSERT_GE(isas.size(), 2u) << "at least one vector target on any x86-64-v2 machine";
    EXPECT_TRUE(isas.front().isScalar());
    EXPECT_EQ(isas.front().vectorLanes(), 1);
    for (size_t i = 1; i < isas.size(); ++i) {
        EXPECT_FALSE(isas[i].isScalar());
        EXPECT_LE(isas[i - 1].vectorLanes(), isas[i].vectorLanes());
        EXPECT_EQ(16 % isas[i].vectorLanes(), 0);
    }
    std::string names;
    for (const KernelIsa& isa : isas)
        names += isa.name() + " ";
    std::printf("kernel targets on this machine: %s; auto = %s (%d lanes)\n", names.c_str(),
                KernelIsa::best().name().c_str(), KernelIsa::best().vectorLanes());
    RecordProperty("auto", KernelIsa::best().name());
}

TEST(KernelIsa, AutoIsTheWidest) {
    const std::vector<KernelIsa> isas = KernelIsa::available();
    EXPECT_EQ(KernelIsa::best(), isas.back());
    EXPECT_EQ(KernelIsa::byName("auto"), KernelIsa::best());
    EXPECT_EQ(KernelIsa::byName("AUTO"), KernelIsa::best());
}

TEST(KernelIsa, NamesRoundTrip) {
    for (const KernelIsa& isa : KernelIsa::available()) {
        EXPECT_EQ(KernelIsa::byName(isa.name()), isa);
        if (!isa.isScalar()) {
            EXPECT_EQ(isa.vector()->vectorLanes, isa.vectorLanes());
        }
    }
    EXPECT_TRUE(KernelIsa::byName("Scalar").isScalar());
}

TEST(KernelIsa, UnknownNameListsTheValidOnes) {
    try {
        KernelIsa::byName("avx1024");
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("avx1024"), std::string::npos) << message;
        EXPECT_NE(message.find("scalar"), std::string::npos) << message;
        EXPECT_NE(message.find("auto"), std::string::npos) << message;
        EXPECT_NE(message.find(KernelIsa::best().name()), std::string::npos) << message;
    }
}

#if defined(__x86_64__)
// The targets the project promises on x86: SSE4, AVX2 and AVX-512 are compiled in; which run
// depends on the CPU, so only check what this one reports.
TEST(KernelIsa, X86TargetsFollowTheCpu) {
    __builtin_cpu_init();
    auto has = [](const std::string& name) {
        for (const KernelIsa& isa : KernelIsa::available())
            if (isa.name() == name)
                return true;
        return false;
    };
    EXPECT_EQ(has("sse4"), bool(__builtin_cpu_supports("sse4.2")) &&
                               bool(__builtin_cpu_supports("aes")) &&
                               bool(__builtin_cpu_supports("pclmul")));
    EXPECT_EQ(has("avx2"),
              bool(__builtin_cpu_supports("avx2")) && bool(__builtin_cpu_supports("fma")));
    EXPECT_EQ(has("avx3"), bool(__builtin_cpu_supports("avx512f")) &&
                               bool(__builtin_cpu_supports("avx512bw")) &&
                               bool(__builtin_cpu_supports("avx512dq")) &&
                               bool(__builtin_cpu_supports("avx512vl")));
}
#endif

} // namespace
