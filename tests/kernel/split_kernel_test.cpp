// The kernel's split form (lighting/kernel/SplitLightKernel.h), what light-prepass and inferred
// shade with: its scalar path against splitLighting (lighting/brdf/SplitLighting.h, the per-pixel
// code the stages ran before) bitwise, and every compiled vector target against the scalar path
// on random packets of both material models: diffuse sums and every metallic-roughness sum
// bitwise, the Blinn-Phong specular sum within the pow bound, counters identical (and equal to
// shadePacket's for the same packet and list), inactive lanes untouched, a list split over calls
// bitwise the whole list.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "lighting/brdf/SplitLighting.h"
#include "lighting/kernel/LightKernel.h"
#include "lighting/kernel/SplitLightKernel.h"
#include "tests/kernel/KernelTestInputs.h"

namespace {

using namespace kerneltest;
using lighting::kernel::kAllLanes;
using lighting::kernel::KernelIsa;
using lighting::kernel::KernelLights;
using lighting::kernel::PacketAccumulator;
using lighting::kernel::SplitPacketAccumulator;

// Blinn-Phong specular, vector vs scalar: the sums differ only through pow, whose relative error
// is about (|y ln x| + 4) float roundings (vector_pow_test). In the radiance the diffuse term
// dilutes it to a few ulps (light_kernel_test); the specular sum alone shows it whole where a lane
// receives only narrow lobes far from their peak (|y ln x| up to ~100, lobe ~e^-100). So: at most
// kMaxUlps, or at most kPowRelative of the value (vector_pow_test's measured worst is 8.7e-6).
constexpr int64_t kMaxUlps = 16;
constexpr double kPowRelative = 2e-5;

enum class Models { BlinnPhong, MetallicRoughness, Mixed };

using Case = PacketCase;

// 64 lights, 48 of them near the block.
Case randomCase(RandomScene& random, Models models) {
    return randomPacketCase(random, int(models), 64, 48);
}

SplitPacketAccumulator shadeSplit(const KernelIsa& isa, const Case& c, uint32_t laneMask,
                                  const KernelLights& lights) {
    SplitPacketAccumulator sums;
    sums.clear();
    lighting::kernel::shadePacketSplit(isa, c.packet, laneMask, lights, c.indices, sums);
    return sums;
}

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

bool bitwiseEqual(const SplitPacketAccumulator& a, const SplitPacketAccumulator& b) {
    return std::memcmp(a.diffuse, b.diffuse, sizeof a.diffuse) == 0 &&
           std::memcmp(a.specular, b.specular, sizeof a.specular) == 0 &&
           std::memcmp(a.specularEdge, b.specularEdge, sizeof a.specularEdge) == 0 &&
           std::memcmp(a.lightsEvaluated, b.lightsEvaluated, sizeof a.lightsEvaluated) == 0;
}

// The scalar path is splitLighting lane by lane, bitwise; lanes outside the packet stay 0.
TEST(SplitKernel, ScalarPathIsSplitLighting) {
    RandomScene random(1202);
    int lanesChecked = 0;
    for (int caseIndex = 0; caseIndex < 600; ++caseIndex) {
        const Case c = randomCase(random, Models(caseIndex % 3));
        const KernelLights lights(c.lights);
        const SplitPacketAccumulator sums = shadeSplit(KernelIsa::scalar(), c, kAllLanes, lights);
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            const bool active = c.packet.laneMask >> lane & 1u;
            const lighting::SplitLighting expected =
                active ? lighting::splitLighting(pointOf(c.surfaces[lane]), c.lights, c.indices)
                       : lighting::SplitLighting{};
            for (int k = 0; k < 3; ++k) {
                EXPECT_TRUE(sameBits(sums.diffuse[k][lane], expected.diffuse[k]))
                    << "case " << caseIndex << " lane " << lane;
                EXPECT_TRUE(sameBits(sums.specular[k][lane], expected.specular[k]))
                    << "case " << caseIndex << " lane " << lane;
                EXPECT_TRUE(sameBits(sums.specularEdge[k][lane], expected.specularEdge[k]))
                    << "case " << caseIndex << " lane " << lane;
            }
            EXPECT_EQ(sums.lightsEvaluated[lane], active ? uint32_t(c.indices.size()) : 0u);
            lanesChecked += active ? 1 : 0;
        }
    }
    EXPECT_GT(lanesChecked, 7000);
}

class SplitKernelTest : public ::testing::TestWithParam<KernelIsa> {};

TEST_P(SplitKernelTest, RandomPacketsMatchScalarPath) {
    const KernelIsa isa = GetParam();
    RandomScene random(20261202);
    int64_t worstSpecularUlps = 0;
    double worstSpecularRelative = 0;
    uint64_t blinnPhongLanes = 0, metallicRoughnessLanes = 0, specularDiffering = 0, shaded = 0;
    for (int caseIndex = 0; caseIndex < 3000; ++caseIndex) {
        const Case c = randomCase(random, Models(caseIndex % 3));
        const KernelLights lights(c.lights);
        const SplitPacketAccumulator vector = shadeSplit(isa, c, kAllLanes, lights);
        const SplitPacketAccumulator scalar = shadeSplit(KernelIsa::scalar(), c, kAllLanes, lights);
        const std::string where = isa.name() + " case " + std::to_string(caseIndex);
        // Counters: the scalar path's, and shadePacket's for the same packet and list (one
        // evaluation per light, whatever the output form).
        PacketAccumulator radiance;
        radiance.clear();
        lighting::kernel::shadePacket(isa, c.packet, kAllLanes, lights, c.indices, radiance, false);
        for (const SplitPacketAccumulator* other : {&scalar}) {
            EXPECT_EQ(vector.lightsSkippedAtRange, other->lightsSkippedAtRange) << where;
            EXPECT_EQ(vector.lightsSkippedAtConeOrFacing, other->lightsSkippedAtConeOrFacing)
                << where;
            EXPECT_EQ(vector.lightsShaded, other->lightsShaded) << where;
        }
        EXPECT_EQ(vector.lightsSkippedAtRange, radiance.lightsSkippedAtRange) << where;
        EXPECT_EQ(vector.lightsSkippedAtConeOrFacing, radiance.lightsSkippedAtConeOrFacing)
            << where;
        EXPECT_EQ(vector.lightsShaded, radiance.lightsShaded) << where;
        shaded += vector.lightsShaded;
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            EXPECT_EQ(vector.lightsEvaluated[lane], scalar.lightsEvaluated[lane]) << where;
            const bool active = c.packet.laneMask >> lane & 1u;
            const bool metallicRoughness = c.surfaces[lane].metallicRoughness;
            if (active)
                ++(metallicRoughness ? metallicRoughnessLanes : blinnPhongLanes);
            for (int k = 0; k < 3; ++k) {
                const std::string at = where + " lane " + std::to_string(lane);
                ASSERT_TRUE(std::isfinite(vector.diffuse[k][lane])) << at;
                ASSERT_TRUE(std::isfinite(vector.specular[k][lane])) << at;
                EXPECT_TRUE(sameBits(vector.diffuse[k][lane], scalar.diffuse[k][lane]))
                    << at << ": " << vector.diffuse[k][lane] << " vs " << scalar.diffuse[k][lane];
                EXPECT_TRUE(sameBits(vector.specularEdge[k][lane], scalar.specularEdge[k][lane]))
                    << at;
                const float v = vector.specular[k][lane], s = scalar.specular[k][lane];
                if (!active || metallicRoughness) {
                    // Inactive lanes untouched (0 after clear); metallic-roughness: no pow.
                    EXPECT_TRUE(sameBits(v, s)) << at << ": " << v << " vs " << s;
                    continue;
                }
                EXPECT_EQ(vector.specularEdge[k][lane], 0.0f) << at;
                const int64_t ulps = ulpDistance(v, s);
                const double relative = s != 0.0f ? std::abs(double(v) - double(s)) / s : 0.0;
                worstSpecularUlps = std::max(worstSpecularUlps, ulps);
                worstSpecularRelative = std::max(worstSpecularRelative, relative);
                specularDiffering += ulps > 0 ? 1 : 0;
                EXPECT_TRUE(ulps <= kMaxUlps || relative <= kPowRelative)
                    << at << ": " << v << " vs " << s << " (" << ulps << " ulps)";
            }
        }
    }
    std::printf("[ %s ] split vs scalar: diffuse and metallic-roughness bitwise (%llu "
                "metallic-roughness lanes); Blinn-Phong specular worst %lld ulps, relative %.3g, "
                "%llu of %llu channel sums differ; lights shaded %llu\n",
                isa.name().c_str(), (unsigned long long)metallicRoughnessLanes,
                (long long)worstSpecularUlps, worstSpecularRelative,
                (unsigned long long)specularDiffering, (unsigned long long)(3 * blinnPhongLanes),
                (unsigned long long)shaded);
    EXPECT_GT(blinnPhongLanes, 10000u);
    EXPECT_GT(metallicRoughnessLanes, 10000u);
    EXPECT_GT(shaded, 0u);
}

// The kernel only adds: a list split over two calls, or the lanes over two calls with disjoint
// masks, gives the whole call's sums bitwise (the stages call once per tile group of a packet).
TEST_P(SplitKernelTest, SplitListsAndLaneSubsets) {
    const KernelIsa isa = GetParam();
    RandomScene random(99);
    for (int caseIndex = 0; caseIndex < 300; ++caseIndex) {
        const Case c = randomCase(random, Models(caseIndex % 3));
        const KernelLights lights(c.lights);
        const SplitPacketAccumulator whole = shadeSplit(isa, c, kAllLanes, lights);
        const size_t half = c.indices.size() / 2;
        const std::vector<uint32_t> first(c.indices.begin(), c.indices.begin() + long(half));
        const std::vector<uint32_t> second(c.indices.begin() + long(half), c.indices.end());
        SplitPacketAccumulator split;
        split.clear();
        lighting::kernel::shadePacketSplit(isa, c.packet, kAllLanes, lights, first, split);
        lighting::kernel::shadePacketSplit(isa, c.packet, kAllLanes, lights, second, split);
        EXPECT_TRUE(bitwiseEqual(whole, split)) << isa.name() << " case " << caseIndex;
        const uint32_t lanes = uint32_t(random.engine()()) & kAllLanes;
        SplitPacketAccumulator subsets;
        subsets.clear();
        lighting::kernel::shadePacketSplit(isa, c.packet, lanes, lights, c.indices, subsets);
        lighting::kernel::shadePacketSplit(isa, c.packet, ~lanes & kAllLanes, lights, c.indices,
                                           subsets);
        EXPECT_TRUE(bitwiseEqual(whole, subsets)) << isa.name() << " case " << caseIndex;
    }
}

std::string isaName(const ::testing::TestParamInfo<KernelIsa>& info) {
    return info.param.name();
}

INSTANTIATE_TEST_SUITE_P(EveryTarget, SplitKernelTest, ::testing::ValuesIn(vectorIsas()), isaName);

} // namespace
