// Shadows in the shading kernel (lighting/shadows/ShadowLookup.h through KernelLights): a light's
// radiance at a lane is multiplied by the lookup's visibility there, on the scalar path and on
// every compiled vector target, in the radiance and the split (light pre-pass) forms alike.
// Checked with an analytic lookup (every other light casts; visibility a smooth function of the
// position with whole regions at exactly 0 and 1):
// - scalar path = evaluateLight x visibility lane by lane, bitwise; counts are the unshadowed ones;
// - vector = scalar (the radiance bound of light_kernel_test: pow; split: diffuse bitwise);
// - visibility 0 everywhere = the list without the casting lights, bitwise (a shadowed light adds
//   exactly +0);
// - the lookup is asked only where a light passes its range, cone and facing tests, and the same
//   number of times on every path.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>

#include "lighting/brdf/SplitLighting.h"
#include "lighting/kernel/LightKernel.h"
#include "lighting/kernel/SplitLightKernel.h"
#include "lighting/shadows/LightReaches.h"
#include "lighting/shadows/ShadowLookup.h"
#include "tests/kernel/KernelTestInputs.h"

namespace {

using namespace kerneltest;
using lighting::kernel::kAllLanes;
using lighting::kernel::KernelIsa;
using lighting::kernel::KernelLights;
using lighting::kernel::PacketAccumulator;
using lighting::kernel::SplitPacketAccumulator;
using lighting::shadows::kNoShadow;

constexpr int64_t kMaxUlps = 16;      // light_kernel_test's bound (pow in the Blinn-Phong lobe)
constexpr double kPowRelative = 2e-5; // split_kernel_test's bound for the specular sum alone

// Even lights cast (shadow = index + 100, to tell shadows from lights), odd ones do not; ambient
// lights never do, whatever the lookup says (KernelLights drops their shadow). The
// visibility is a clamped stripe pattern over the position, shifted per shadow and tilted by the
// normal: 0 and 1 on whole regions, fractions between.
class StripeShadows : public lighting::shadows::ShadowLookup {
public:
    explicit StripeShadows(float constant = -1.0f) : mConstant(constant) {}
    uint32_t shadowOf(size_t light) const override {
        return light % 2 == 0 ? uint32_t(light) + 100u : kNoShadow;
    }
    float visibility(uint32_t shadow, const glm::vec3& p, const glm::vec3& n) const override {
        mCalls.fetch_add(1, std::memory_order_relaxed);
        if (mConstant >= 0.0f)
            return mConstant;
        const float phase = 3.0f * p.x - 2.0f * p.y + p.z + 0.5f * n.y + 0.37f * float(shadow);
        return std::clamp(1.5f * std::sin(phase) + 0.5f, 0.0f, 1.0f);
    }
    uint64_t calls() const { return mCalls.load(); }
    void resetCalls() { mCalls = 0; }

private:
    float mConstant;
    mutable std::atomic<uint64_t> mCalls{0};
};

using Case = PacketCase;

Case randomCase(RandomScene& random, int models) {
    return randomPacketCase(random, models, 48, 36);
}

PacketAccumulator shade(const KernelIsa& isa, const Case& c, const KernelLights& lights,
                        const std::vector<uint32_t>& indices) {
    PacketAccumulator accumulator;
    accumulator.clear();
    lighting::kernel::shadePacket(isa, c.packet, kAllLanes, lights, indices, accumulator);
    return accumulator;
}

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(ShadowKernel, ScalarPathIsEvaluateLightTimesVisibility) {
    RandomScene random(2912);
    StripeShadows shadows;
    int partial = 0, dark = 0, lanes = 0;
    for (int caseIndex = 0; caseIndex < 400; ++caseIndex) {
        const Case c = randomCase(random, caseIndex % 3);
        const KernelLights lit(c.lights), shadowed(c.lights, &shadows);
        const PacketAccumulator plain = shade(KernelIsa::scalar(), c, lit, c.indices);
        const PacketAccumulator sums = shade(KernelIsa::scalar(), c, shadowed, c.indices);
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            const std::string where =
                "case " + std::to_string(caseIndex) + " lane " + std::to_string(lane);
            // Shadows change the image, never the counts (the oracle ignores occlusion).
            EXPECT_EQ(sums.lightsContributing[lane], plain.lightsContributing[lane]) << where;
            EXPECT_EQ(sums.lightsEvaluated[lane], plain.lightsEvaluated[lane]) << where;
            if (!(c.packet.laneMask >> lane & 1u))
                continue;
            ++lanes;
            const gbuffer::Surface point = pointOf(c.surfaces[lane]);
            const glm::vec3 toViewer = glm::normalize(-point.positionView);
            glm::vec3 expected(0.0f);
            for (uint32_t index : c.indices) {
                const glm::vec3 radiance =
                    lighting::evaluateLight(point, toViewer, c.lights[index]);
                float v = 1.0f;
                if (shadowed.shadowOf(index) != kNoShadow && lighting::contributes(radiance)) {
                    v = shadows.visibility(shadowed.shadowOf(index), point.positionView,
                                           point.normalView);
                    partial += v > 0.0f && v < 1.0f ? 1 : 0;
                    dark += v == 0.0f ? 1 : 0;
                }
                expected += radiance * v;
            }
            for (int k = 0; k < 3; ++k)
                EXPECT_TRUE(sameBits(sums.radiance[k][lane], expected[k]))
                    << where << ": " << sums.radiance[k][lane] << " vs " << expected[k];
        }
    }
    EXPECT_GT(lanes, 4000);
    EXPECT_GT(partial, 1000); // the pattern exercises fractions and full shadow
    EXPECT_GT(dark, 1000);
}

class ShadowKernelTest : public ::testing::TestWithParam<KernelIsa> {};

TEST_P(ShadowKernelTest, VectorMatchesScalarPath) {
    const KernelIsa isa = GetParam();
    RandomScene random(291229);
    StripeShadows shadows;
    int64_t worstUlps = 0;
    for (int caseIndex = 0; caseIndex < 1500; ++caseIndex) {
        const Case c = randomCase(random, caseIndex % 3);
        const KernelLights lights(c.lights, &shadows);
        shadows.resetCalls();
        const PacketAccumulator vector = shade(isa, c, lights, c.indices);
        const uint64_t vectorCalls = shadows.calls();
        shadows.resetCalls();
        const PacketAccumulator scalar = shade(KernelIsa::scalar(), c, lights, c.indices);
        const std::string where = isa.name() + " case " + std::to_string(caseIndex);
        // The same lanes ask the lookup: those passing range, cone and facing.
        EXPECT_EQ(vectorCalls, shadows.calls()) << where;
        EXPECT_EQ(vector.lightsShaded, scalar.lightsShaded) << where;
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            EXPECT_EQ(vector.lightsContributing[lane], scalar.lightsContributing[lane]) << where;
            for (int k = 0; k < 3; ++k) {
                const float v = vector.radiance[k][lane], s = scalar.radiance[k][lane];
                ASSERT_TRUE(std::isfinite(v)) << where;
                const int64_t ulps = ulpDistance(v, s);
                worstUlps = std::max(worstUlps, ulps);
                EXPECT_LE(ulps, kMaxUlps) << where << " lane " << lane << ": " << v << " vs " << s;
            }
        }
    }
    std::printf("[ %s ] shadowed vector vs scalar: worst %lld ulps\n", isa.name().c_str(),
                (long long)worstUlps);
}

// A light in full shadow adds exactly +0: the image is the list without the casting lights.
TEST_P(ShadowKernelTest, FullShadowIsTheListWithoutTheCasters) {
    const KernelIsa isa = GetParam();
    RandomScene random(7);
    const StripeShadows black(0.0f);
    for (int caseIndex = 0; caseIndex < 300; ++caseIndex) {
        const Case c = randomCase(random, caseIndex % 3);
        const KernelLights shadowed(c.lights, &black), lit(c.lights);
        std::vector<uint32_t> nonCasting; // ambient lights never cast (KernelLights)
        for (uint32_t index : c.indices)
            if (shadowed.shadowOf(index) == kNoShadow)
                nonCasting.push_back(index);
        for (const KernelIsa& path : {isa, KernelIsa::scalar()}) {
            const PacketAccumulator all = shade(path, c, shadowed, c.indices);
            const PacketAccumulator without = shade(path, c, lit, nonCasting);
            EXPECT_EQ(std::memcmp(all.radiance, without.radiance, sizeof all.radiance), 0)
                << path.name() << " case " << caseIndex;
        }
    }
}

// The split form (light pre-pass, inferred): scalar = addSplitLight with the factor, vector =
// scalar (diffuse and every metallic-roughness term bitwise, Blinn-Phong specular within pow).
TEST_P(ShadowKernelTest, SplitFormAppliesTheSameFactor) {
    const KernelIsa isa = GetParam();
    RandomScene random(4242);
    StripeShadows shadows;
    for (int caseIndex = 0; caseIndex < 600; ++caseIndex) {
        const Case c = randomCase(random, caseIndex % 3);
        const KernelLights lights(c.lights, &shadows);
        SplitPacketAccumulator vector, scalar;
        vector.clear();
        scalar.clear();
        lighting::kernel::shadePacketSplit(isa, c.packet, kAllLanes, lights, c.indices, vector);
        lighting::kernel::shadePacketSplit(KernelIsa::scalar(), c.packet, kAllLanes, lights,
                                           c.indices, scalar);
        const std::string where = isa.name() + " case " + std::to_string(caseIndex);
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            if (!(c.packet.laneMask >> lane & 1u))
                continue;
            // The scalar path against addSplitLight with the factor, light by light.
            const gbuffer::Surface point = pointOf(c.surfaces[lane]);
            const lighting::SplitPoints points(point);
            const glm::vec3 toViewer = glm::normalize(-point.positionView);
            lighting::SplitLighting expected;
            for (uint32_t index : c.indices) {
                const float v = lights.shadowOf(index) != kNoShadow &&
                                        lighting::shadows::lightReaches(point, c.lights[index])
                                    ? shadows.visibility(lights.shadowOf(index), point.positionView,
                                                         point.normalView)
                                    : 1.0f;
                lighting::addSplitLight(point, points, toViewer, c.lights[index], expected, v);
            }
            const bool metallicRoughness = c.surfaces[lane].metallicRoughness;
            for (int k = 0; k < 3; ++k) {
                EXPECT_TRUE(sameBits(scalar.diffuse[k][lane], expected.diffuse[k])) << where;
                EXPECT_TRUE(sameBits(scalar.specular[k][lane], expected.specular[k])) << where;
                EXPECT_TRUE(sameBits(vector.diffuse[k][lane], scalar.diffuse[k][lane])) << where;
                EXPECT_TRUE(sameBits(vector.specularEdge[k][lane], scalar.specularEdge[k][lane]))
                    << where;
                const float v = vector.specular[k][lane], s = scalar.specular[k][lane];
                if (metallicRoughness) {
                    EXPECT_TRUE(sameBits(v, s)) << where;
                } else {
                    const double relative =
                        s != 0.0f ? std::abs(double(v) - double(s)) / double(s) : 0.0;
                    EXPECT_TRUE(ulpDistance(v, s) <= kMaxUlps || relative <= kPowRelative)
                        << where << ": " << v << " vs " << s;
                }
            }
        }
    }
}

std::string isaName(const ::testing::TestParamInfo<KernelIsa>& info) {
    return info.param.name();
}

INSTANTIATE_TEST_SUITE_P(EveryTarget, ShadowKernelTest, ::testing::ValuesIn(vectorIsas()), isaName);

} // namespace
