// The shading kernel's vector paths (every compiled instruction set this CPU runs) against its
// scalar path (lighting/brdf/Brdf.h's evaluateLight lane by lane) and the double-precision formula,
// for both material models (Blinn-Phong, metallic-roughness) and packets that mix them:
// random packets and lights, hand-built edge cases with known outcomes, lane independence, the
// early-out rule (a contributing light is never skipped, counters equal to the scalar path's),
// split lists and lane subsets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "lighting/kernel/LightKernel.h"
#include "lighting/kernel/VectorTargets.h"
#include "tests/kernel/KernelTestInputs.h"

namespace {

using namespace kerneltest;
using lighting::kernel::kAllLanes;
using lighting::kernel::KernelIsa;
using lighting::kernel::KernelLights;
using lighting::kernel::PacketAccumulator;
using lighting::kernel::shadePacket;

// Vector vs scalar radiance, per lane and channel: the paths differ only in pow (std::pow against
// exp(y log x) through Highway), whose relative error is about (|y log x| + 4) float roundings
// (vector_pow_test); where |y log x| is large the lobe is e^-|y log x| small beside the diffuse
// term, so the sum moves by a few ulps. Measured worst: 5 ulps (random cases), 2 (atrium frame).
constexpr int64_t kMaxUlps = 16;

PacketAccumulator shade(const KernelIsa& isa, const ShadingPacket& packet, uint32_t laneMask,
                        const KernelLights& lights, const std::vector<uint32_t>& indices) {
    PacketAccumulator accumulator;
    accumulator.clear();
    shadePacket(isa, packet, laneMask, lights, indices, accumulator);
    return accumulator;
}

void expectSameCounts(const PacketAccumulator& vector, const PacketAccumulator& scalar,
                      const std::string& where) {
    EXPECT_EQ(vector.lightsSkippedAtRange, scalar.lightsSkippedAtRange) << where;
    EXPECT_EQ(vector.lightsSkippedAtConeOrFacing, scalar.lightsSkippedAtConeOrFacing) << where;
    EXPECT_EQ(vector.lightsShaded, scalar.lightsShaded) << where;
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        EXPECT_EQ(vector.lightsEvaluated[lane], scalar.lightsEvaluated[lane]) << where << lane;
        EXPECT_EQ(vector.lightsContributing[lane], scalar.lightsContributing[lane])
            << where << " lane " << lane;
    }
}

bool bitwiseEqual(const PacketAccumulator& a, const PacketAccumulator& b) {
    return std::memcmp(a.radiance, b.radiance, sizeof a.radiance) == 0 &&
           std::memcmp(a.lightsContributing, b.lightsContributing, sizeof a.lightsContributing) ==
               0 &&
           std::memcmp(a.lightsEvaluated, b.lightsEvaluated, sizeof a.lightsEvaluated) == 0;
}

class LightKernelTest : public ::testing::TestWithParam<KernelIsa> {};

// Which material models the lanes of a random packet use.
enum class CaseModels { BlinnPhong, MetallicRoughness, Mixed };

CaseModels modelsOfCase(int caseIndex) {
    return CaseModels(caseIndex % 3);
}

// One random packet: lanes around a common point (coherent, like a 4x4 block of a surface) or
// scattered, some lanes background; lights near the packet and far from it; a random ascending
// subset of them as the list.
struct RandomCase {
    ShadingPacket packet = poisonedPacket();
    Surface surfaces[kPacketLanes];
    std::vector<LightInView<float>> lights;
    std::vector<uint32_t> indices;
};

RandomCase randomCase(RandomScene& random, CaseModels models = CaseModels::BlinnPhong) {
    RandomCase c;
    const bool coherent = random.chance(0.5f);
    const Surface centre = random.surface();
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        Surface s = random.surface();
        if (coherent) {
            s.position = centre.position + glm::vec3(random.uniform(-0.05f, 0.05f),
                                                     random.uniform(-0.05f, 0.05f),
                                                     random.uniform(-0.05f, 0.05f));
            s.normal = glm::normalize(centre.normal + 0.1f * random.unitVector());
        }
        if (models == CaseModels::MetallicRoughness ||
            (models == CaseModels::Mixed && random.chance(0.5f)))
            random.makeMetallicRoughness(s);
        c.surfaces[lane] = s;
        if (!random.chance(0.15f))
            setLane(c.packet, lane, s);
    }
    for (int i = 0; i < 48; ++i)
        c.lights.push_back(random.lightNear(centre.position));
    for (int i = 0; i < 16; ++i)
        c.lights.push_back(random.lightNear(random.surface().position));
    for (uint32_t i = 0; i < c.lights.size(); ++i)
        if (random.chance(0.7f))
            c.indices.push_back(i);
    return c;
}

TEST_P(LightKernelTest, RandomPacketsMatchScalarPath) {
    const KernelIsa isa = GetParam();
    RandomScene random(20261202);
    int64_t worstUlps = 0;
    double vectorError2 = 0, scalarError2 = 0, reference2 = 0;
    uint64_t shaded = 0, skippedAtRange = 0, skippedLater = 0, contributing = 0;
    for (int caseIndex = 0; caseIndex < 3000; ++caseIndex) {
        const RandomCase c = randomCase(random);
        const KernelLights lights(c.lights);
        const PacketAccumulator vector = shade(isa, c.packet, kAllLanes, lights, c.indices);
        const PacketAccumulator scalar =
            shade(KernelIsa::scalar(), c.packet, kAllLanes, lights, c.indices);
        const std::string where = "case " + std::to_string(caseIndex);
        expectSameCounts(vector, scalar, where);
        shaded += vector.lightsShaded;
        skippedAtRange += vector.lightsSkippedAtRange;
        skippedLater += vector.lightsSkippedAtConeOrFacing;
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            if (!(c.packet.laneMask >> lane & 1u)) {
                for (int k = 0; k < 3; ++k)
                    EXPECT_EQ(vector.radiance[k][lane], 0.0f) << where << " background lane";
                EXPECT_EQ(vector.lightsEvaluated[lane], 0u);
                continue;
            }
            contributing += vector.lightsContributing[lane];
            const glm::dvec3 reference = referenceSum(c.surfaces[lane], c.lights, c.indices);
            for (int k = 0; k < 3; ++k) {
                const float v = vector.radiance[k][lane], s = scalar.radiance[k][lane];
                ASSERT_TRUE(std::isfinite(v)) << where << " lane " << lane;
                const int64_t ulps = ulpDistance(v, s);
                worstUlps = std::max(worstUlps, ulps);
                EXPECT_LE(ulps, kMaxUlps) << where << " lane " << lane << ": " << v << " vs " << s;
                vectorError2 += (v - reference[k]) * (v - reference[k]);
                scalarError2 += (s - reference[k]) * (s - reference[k]);
                reference2 += reference[k] * reference[k];
            }
        }
    }
    const double vectorRelativeRmse = std::sqrt(vectorError2 / reference2);
    const double scalarRelativeRmse = std::sqrt(scalarError2 / reference2);
    std::printf("[ %s ] vector vs scalar: worst %lld ulps; relative RMSE vs double: vector %.3g, "
                "scalar %.3g; lights shaded %llu, skipped at range %llu, at cone/n.l %llu; "
                "contributing lane-lights %llu\n",
                isa.name().c_str(), (long long)worstUlps, vectorRelativeRmse, scalarRelativeRmse,
                (unsigned long long)shaded, (unsigned long long)skippedAtRange,
                (unsigned long long)skippedLater, (unsigned long long)contributing);
    // Against double the float formula itself is the error (n.h rounded to float, raised to powers
    // up to 8192, moves the lobe by up to 8192 ulps relative); the vector path adds nothing
    // measurable to it.
    EXPECT_LE(vectorRelativeRmse, scalarRelativeRmse * 1.01 + 1e-9);
    // Every exit is exercised by the random cases.
    EXPECT_GT(shaded, 0u);
    EXPECT_GT(skippedAtRange, 0u);
    EXPECT_GT(skippedLater, 0u);
}

// The metallic-roughness model has no pow: its vector radiance is the scalar path's bitwise
// (MetallicRoughness.h's float operations in its order, IEEE division and square root, nothing
// fused), on packets of metallic-roughness lanes and on packets that mix both models (whose
// Blinn-Phong lanes keep the pow bound above). Counts as the scalar path's.
TEST_P(LightKernelTest, MetallicRoughnessMatchesScalarPathBitwise) {
    const KernelIsa isa = GetParam();
    RandomScene random(20261203);
    int64_t worstMetallicRoughness = 0, worstBlinnPhong = 0;
    double vectorError2 = 0, scalarError2 = 0, reference2 = 0;
    uint64_t metallicRoughnessLanes = 0, shaded = 0;
    for (int caseIndex = 0; caseIndex < 2000; ++caseIndex) {
        const CaseModels models =
            caseIndex % 2 == 0 ? CaseModels::MetallicRoughness : CaseModels::Mixed;
        const RandomCase c = randomCase(random, models);
        const KernelLights lights(c.lights);
        const PacketAccumulator vector = shade(isa, c.packet, kAllLanes, lights, c.indices);
        const PacketAccumulator scalar =
            shade(KernelIsa::scalar(), c.packet, kAllLanes, lights, c.indices);
        const std::string where = "case " + std::to_string(caseIndex);
        expectSameCounts(vector, scalar, where);
        shaded += vector.lightsShaded;
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            if (!(c.packet.laneMask >> lane & 1u))
                continue;
            const bool metallicRoughness = c.surfaces[lane].metallicRoughness;
            metallicRoughnessLanes += metallicRoughness ? 1 : 0;
            const glm::dvec3 reference = referenceSum(c.surfaces[lane], c.lights, c.indices);
            for (int k = 0; k < 3; ++k) {
                const float v = vector.radiance[k][lane], s = scalar.radiance[k][lane];
                ASSERT_TRUE(std::isfinite(v)) << where << " lane " << lane;
                const int64_t ulps = ulpDistance(v, s);
                (metallicRoughness ? worstMetallicRoughness : worstBlinnPhong) =
                    std::max(metallicRoughness ? worstMetallicRoughness : worstBlinnPhong, ulps);
                if (metallicRoughness) {
                    EXPECT_EQ(std::memcmp(&v, &s, sizeof v), 0)
                        << where << " lane " << lane << ": " << v << " vs " << s;
                    vectorError2 += (v - reference[k]) * (v - reference[k]);
                    scalarError2 += (s - reference[k]) * (s - reference[k]);
                    reference2 += reference[k] * reference[k];
                } else {
                    EXPECT_LE(ulps, kMaxUlps) << where << " lane " << lane;
                }
            }
        }
    }
    std::printf("[ %s ] metallic-roughness vs scalar: worst %lld ulps on %llu metallic-roughness "
                "lanes (Blinn-Phong lanes of mixed packets: %lld); relative RMSE vs double: "
                "vector %.3g, scalar %.3g; lights shaded %llu\n",
                isa.name().c_str(), (long long)worstMetallicRoughness,
                (unsigned long long)metallicRoughnessLanes, (long long)worstBlinnPhong,
                std::sqrt(vectorError2 / reference2), std::sqrt(scalarError2 / reference2),
                (unsigned long long)shaded);
    EXPECT_GT(metallicRoughnessLanes, 10000u);
    EXPECT_GT(shaded, 0u);
}

// Each light alone: when the scalar path finds it contributing at any lane, the packet must not
// have skipped it; when the vector path skipped it, no lane of the scalar path may see it.
TEST_P(LightKernelTest, ContributingLightIsNeverSkipped) {
    const KernelIsa isa = GetParam();
    RandomScene random(7);
    int contributingLights = 0;
    for (int caseIndex = 0; caseIndex < 300; ++caseIndex) {
        const RandomCase c = randomCase(random, modelsOfCase(caseIndex));
        const KernelLights lights(c.lights);
        for (uint32_t index = 0; index < c.lights.size(); ++index) {
            const std::vector<uint32_t> one{index};
            const PacketAccumulator vector = shade(isa, c.packet, kAllLanes, lights, one);
            const PacketAccumulator scalar =
                shade(KernelIsa::scalar(), c.packet, kAllLanes, lights, one);
            const uint32_t anyScalar = std::accumulate(std::begin(scalar.lightsContributing),
                                                       std::end(scalar.lightsContributing), 0u);
            if (c.packet.laneMask == 0)
                continue;
            if (anyScalar > 0) {
                ++contributingLights;
                EXPECT_EQ(vector.lightsShaded, 1u) << "case " << caseIndex << " light " << index;
            }
            if (vector.lightsShaded == 0) {
                EXPECT_EQ(anyScalar, 0u);
            }
        }
    }
    EXPECT_GT(contributingLights, 1000);
}

// Hand-built edges, each with the outcome the formula dictates (not just agreement).
TEST_P(LightKernelTest, HardCases) {
    const KernelIsa isa = GetParam();
    Surface floor; // at (0, 0, -5), normal +Y
    floor.normal = {0.0f, 1.0f, 0.0f};
    auto pointLight = [](glm::vec3 position, float range) {
        LightInView<float> light;
        light.type = LightType::Point;
        light.positionView = position;
        light.radiance = glm::vec3(1.0f);
        light.rangeMetres = range;
        return light;
    };
    struct Case {
        const char* name;
        LightInView<float> light;
        bool contributes;
        int exit; // 0 shaded, 1 skipped at range, 2 skipped at cone or n.l
    };
    std::vector<Case> cases;
    // distance 3 exactly (offset (0, 3, 0)): at the range nothing, just inside something.
    cases.push_back({"at range", pointLight({0, 3, -5}, 3.0f), false, 1});
    cases.push_back({"inside range", pointLight({0, 3, -5}, std::nextafter(3.0f, 4.0f)), true, 0});
    cases.push_back({"beyond range", pointLight({0, 3, -5}, 2.0f), false, 1});
    // In the tangent plane: n.l = 0 exactly.
    cases.push_back({"n.l = 0", pointLight({2, 0, -5}, 10.0f), false, 2});
    cases.push_back({"below the surface", pointLight({0, -1, -5}, 10.0f), false, 2});
    // On the surface: no direction, taken as overhead (n.l = 1).
    cases.push_back({"zero distance", pointLight({0, 0, -5}, 1.0f), true, 0});
    {
        // Spot above, pointing straight down: the point is on the axis.
        LightInView<float> spot = pointLight({0, 2, -5}, 10.0f);
        spot.type = LightType::Spot;
        spot.directionView = {0, -1, 0};
        spot.spotInnerCos = 0.95f;
        spot.spotOuterCos = 0.9f;
        cases.push_back({"spot on axis", spot, true, 0});
        // Cone edge: cos(angle) to the point exactly equals the outer cosine -> rejected.
        spot.spotOuterCos = 1.0f;
        spot.spotInnerCos = 1.0f;
        cases.push_back({"spot outer edge", spot, false, 2});
        // Inner == outer (zero-width edge): full intensity inside.
        spot.spotOuterCos = 0.5f;
        spot.spotInnerCos = 0.5f;
        cases.push_back({"spot zero-width edge", spot, true, 0});
        spot.directionView = {0, 1, 0}; // pointing away
        cases.push_back({"spot pointing away", spot, false, 2});
    }
    {
        LightInView<float> sun;
        sun.type = LightType::Directional;
        sun.radiance = glm::vec3(2.0f);
        sun.directionView = {0, -1, 0};
        cases.push_back({"sun from above", sun, true, 0});
        sun.directionView = {0, 1, 0};
        cases.push_back({"sun from below", sun, false, 2});
        sun.directionView = {1, 0, 0};
        cases.push_back({"sun grazing", sun, false, 2});
        LightInView<float> ambient;
        ambient.type = LightType::Ambient;
        ambient.radiance = glm::vec3(0.1f);
        cases.push_back({"ambient", ambient, true, 0});
        ambient.radiance = glm::vec3(0.0f);
        cases.push_back({"black ambient", ambient, false, 0});
    }
    for (const Case& c : cases) {
        for (float power : {0.0f, 1.0f, 8192.0f}) {
            ShadingPacket packet = poisonedPacket();
            Surface s = floor;
            s.specularPower = power;
            setLane(packet, 5, s);
            const std::vector<lighting::LightInView<float>> one{c.light};
            const KernelLights lights(one);
            const std::vector<uint32_t> list{0};
            PacketAccumulator vector;
            vector.clear();
            vector.radiance[0][6] = -0.0f; // an inactive lane's value must survive untouched
            shadePacket(isa, packet, kAllLanes, lights, list, vector);
            const PacketAccumulator scalar =
                shade(KernelIsa::scalar(), packet, kAllLanes, lights, list);
            const std::string where = std::string(c.name) + " power " + std::to_string(power);
            EXPECT_EQ(vector.lightsContributing[5], c.contributes ? 1u : 0u) << where;
            EXPECT_EQ(vector.lightsShaded, c.exit == 0 ? 1u : 0u) << where;
            EXPECT_EQ(vector.lightsSkippedAtRange, c.exit == 1 ? 1u : 0u) << where;
            EXPECT_EQ(vector.lightsSkippedAtConeOrFacing, c.exit == 2 ? 1u : 0u) << where;
            expectSameCounts(vector, scalar, where);
            for (int k = 0; k < 3; ++k) {
                EXPECT_LE(ulpDistance(vector.radiance[k][5], scalar.radiance[k][5]), kMaxUlps)
                    << where;
                EXPECT_EQ(c.contributes, vector.radiance[k][5] != 0.0f) << where;
            }
            EXPECT_TRUE(std::signbit(vector.radiance[0][6])) << where;
            for (int lane = 0; lane < kPacketLanes; ++lane)
                if (lane != 5) {
                    EXPECT_EQ(vector.lightsEvaluated[lane], 0u) << where;
                }
        }
    }
}

// An analytic value, independent of lighting/brdf/Brdf.h: a sun straight above a floor seen along
// +Z (l = +Y, v = +Z, so h = (0, 1, 1) / sqrt 2 and n.h = 1 / sqrt 2), radiance 2:
// 2 * (albedo / pi + intensity (power + 8) / (8 pi) * (1 / sqrt 2)^power).
TEST_P(LightKernelTest, ClosedFormSun) {
    const KernelIsa isa = GetParam();
    for (float power : {1.0f, 16.0f, 100.0f}) {
        Surface floor;
        floor.position = {0.0f, 0.0f, -5.0f};
        floor.normal = {0.0f, 1.0f, 0.0f};
        floor.albedo = glm::vec3(0.5f);
        floor.specularIntensity = 0.25f;
        floor.specularPower = power;
        ShadingPacket packet = poisonedPacket();
        setLane(packet, 9, floor);
        LightInView<float> sun;
        sun.type = LightType::Directional;
        sun.directionView = {0.0f, -1.0f, 0.0f};
        sun.radiance = glm::vec3(2.0f);
        const std::vector<lighting::LightInView<float>> sunOnly{sun};
        const KernelLights lights(sunOnly);
        const PacketAccumulator result = shade(isa, packet, kAllLanes, lights, {0});
        const double pi = 3.14159265358979323846;
        const double expected = 2.0 * (0.5 / pi + 0.25 * (double(power) + 8.0) / (8.0 * pi) *
                                                      std::pow(std::sqrt(0.5), double(power)));
        EXPECT_NEAR(result.radiance[0][9], expected, 1e-6 * expected) << "power " << power;
    }
}

// A pixel's sum depends on its own surface and the list only: the same surface in different
// lanes, with different neighbours (some background with NaN data), gives bitwise the same sum.
TEST_P(LightKernelTest, LaneIndependence) {
    const KernelIsa isa = GetParam();
    RandomScene random(99);
    for (int caseIndex = 0; caseIndex < 200; ++caseIndex) {
        const RandomCase base = randomCase(random, modelsOfCase(caseIndex));
        const KernelLights lights(base.lights);
        const Surface probe = base.surfaces[0];
        float expected[3] = {};
        for (int variant = 0; variant < 4; ++variant) {
            ShadingPacket packet = poisonedPacket();
            const int probeLane = (caseIndex * 7 + variant * 5) % kPacketLanes;
            for (int lane = 0; lane < kPacketLanes; ++lane) {
                if (lane == probeLane)
                    setLane(packet, lane, probe);
                else if (variant > 0 && random.chance(0.7f))
                    setLane(packet, lane, variant == 3 ? random.surface() : base.surfaces[lane]);
            }
            const PacketAccumulator result = shade(isa, packet, kAllLanes, lights, base.indices);
            for (int k = 0; k < 3; ++k) {
                if (variant == 0)
                    expected[k] = result.radiance[k][probeLane];
                else
                    EXPECT_EQ(std::memcmp(&expected[k], &result.radiance[k][probeLane], 4), 0)
                        << "case " << caseIndex << " variant " << variant;
            }
        }
    }
}

// Splitting a list over calls, or shading disjoint lane subsets in separate calls, gives bitwise
// the result of one call.
TEST_P(LightKernelTest, SplitListsAndLaneSubsets) {
    const KernelIsa isa = GetParam();
    RandomScene random(5);
    for (int caseIndex = 0; caseIndex < 200; ++caseIndex) {
        const RandomCase c = randomCase(random, modelsOfCase(caseIndex));
        const KernelLights lights(c.lights);
        const PacketAccumulator whole = shade(isa, c.packet, kAllLanes, lights, c.indices);

        PacketAccumulator split;
        split.clear();
        const size_t cut = c.indices.size() * size_t(caseIndex % 5) / 4;
        const std::vector<uint32_t> first(c.indices.begin(), c.indices.begin() + long(cut));
        const std::vector<uint32_t> second(c.indices.begin() + long(cut), c.indices.end());
        shadePacket(isa, c.packet, kAllLanes, lights, first, split);
        shadePacket(isa, c.packet, kAllLanes, lights, second, split);
        EXPECT_TRUE(bitwiseEqual(whole, split)) << "case " << caseIndex << " cut " << cut;

        PacketAccumulator subsets;
        subsets.clear();
        const uint32_t lanes = uint32_t(random.engine()()) & kAllLanes;
        shadePacket(isa, c.packet, lanes, lights, c.indices, subsets);
        shadePacket(isa, c.packet, ~lanes & kAllLanes, lights, c.indices, subsets);
        EXPECT_TRUE(bitwiseEqual(whole, subsets)) << "case " << caseIndex;
    }
}

// Per-light lane masks (the `ideal` stage's union lists): one call equals, lane by lane and
// bitwise, shading each lane alone with its own sub-list (radiance, evaluated, contributing), on
// every vector target and on the scalar path.
TEST_P(LightKernelTest, PerLightLaneMasksShadeEachLaneItsOwnSubList) {
    RandomScene random(13);
    for (const KernelIsa& isa : {GetParam(), KernelIsa::scalar()})
        for (int caseIndex = 0; caseIndex < 200; ++caseIndex) {
            const RandomCase c = randomCase(random, modelsOfCase(caseIndex));
            const KernelLights lights(c.lights);
            std::vector<uint16_t> masks(c.indices.size());
            for (uint16_t& mask : masks)
                mask = caseIndex % 4 == 0 ? uint16_t(kAllLanes) : uint16_t(random.engine()());
            const uint32_t laneMask =
                caseIndex % 3 == 0 ? kAllLanes : uint32_t(random.engine()()) & kAllLanes;
            PacketAccumulator masked;
            masked.clear();
            shadePacket(isa, c.packet, laneMask, lights, c.indices, masks, masked);
            PacketAccumulator perLane;
            perLane.clear();
            for (int lane = 0; lane < kPacketLanes; ++lane) {
                if (!(laneMask >> lane & 1u))
                    continue;
                std::vector<uint32_t> own;
                for (size_t i = 0; i < c.indices.size(); ++i)
                    if (masks[i] >> lane & 1u)
                        own.push_back(c.indices[i]);
                shadePacket(isa, c.packet, 1u << lane, lights, own, perLane);
            }
            EXPECT_TRUE(bitwiseEqual(masked, perLane)) << isa.name() << " case " << caseIndex;
        }
}

std::string isaName(const ::testing::TestParamInfo<KernelIsa>& info) {
    return info.param.name();
}

INSTANTIATE_TEST_SUITE_P(EveryTarget, LightKernelTest, ::testing::ValuesIn(vectorIsas()), isaName);

// Targets that run the same operations agree bitwise: AVX2 with AVX-512 (both fuse Highway's
// MulAdd inside Exp and Log), SSSE3 with SSE4 (neither does).
TEST(LightKernel, TargetsWithTheSameFusionAgreeBitwise) {
    const std::vector<KernelIsa> isas = vectorIsas();
    auto find = [&](const std::string& name) -> const KernelIsa* {
        for (const KernelIsa& isa : isas)
            if (isa.name() == name)
                return &isa;
        return nullptr;
    };
    int pairs = 0;
    for (auto [a, b] : {std::pair{"avx2", "avx3"}, std::pair{"ssse3", "sse4"}}) {
        const KernelIsa* first = find(a);
        const KernelIsa* second = find(b);
        if (!first || !second)
            continue;
        ++pairs;
        RandomScene random(11);
        for (int caseIndex = 0; caseIndex < 500; ++caseIndex) {
            const RandomCase c = randomCase(random);
            const KernelLights lights(c.lights);
            EXPECT_TRUE(bitwiseEqual(shade(*first, c.packet, kAllLanes, lights, c.indices),
                                     shade(*second, c.packet, kAllLanes, lights, c.indices)))
                << a << " vs " << b << " case " << caseIndex;
        }
    }
    RecordProperty("pairs", pairs);
    // Across the two groups (fused and unfused MulAdd inside Exp and Log) the radiance differs by
    // a few ulps, within the bound both keep to the scalar path.
    const KernelIsa* fused = find("avx2");
    const KernelIsa* unfused = find("sse4");
    if (fused && unfused) {
        RandomScene random(11);
        int64_t worst = 0;
        for (int caseIndex = 0; caseIndex < 500; ++caseIndex) {
            const RandomCase c = randomCase(random);
            const KernelLights lights(c.lights);
            const PacketAccumulator a = shade(*fused, c.packet, kAllLanes, lights, c.indices);
            const PacketAccumulator b = shade(*unfused, c.packet, kAllLanes, lights, c.indices);
            for (int k = 0; k < 3; ++k)
                for (int lane = 0; lane < kPacketLanes; ++lane)
                    worst = std::max(worst, ulpDistance(a.radiance[k][lane], b.radiance[k][lane]));
        }
        std::printf("avx2 vs sse4: worst %lld ulps\n", (long long)worst);
        EXPECT_LE(worst, kMaxUlps);
    }
}

} // namespace
