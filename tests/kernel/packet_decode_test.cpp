// The packet decoder (scalar and every vector target) against the per-pixel oracle
// GBuffer::decode: every covered lane bitwise equal, coverage exactly the G-buffer's, on the
// layouts it supports (derived atrium layout with the material index, the float32 reference
// layout, view-ray reconstruction from standard unorm24 depth, constant albedo and specular,
// the DamagedHelmet's metallic-roughness planes, both models in one scene with the model and
// roughness-metallic from the material index), including each lane's material model,
// with an image size that is not a multiple of 4 so edge packets are exercised. Unsupported
// layouts are refused with a reason.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/PreparedScene.h"
#include "lighting/kernel/PacketDecoder.h"
#include "scenes/SceneLoader.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/kernel/GBufferPlaneCopy.h"
#include "tests/kernel/KernelTestInputs.h"

namespace {

using lighting::kernel::KernelIsa;
using lighting::kernel::PacketDecoder;
using lighting::kernel::ShadingPacket;

constexpr int kWidth = 250; // 250 = 62 * 4 + 2, 142 = 35 * 4 + 2: edge packets on both sides
constexpr int kHeight = 142;

const std::vector<gbuffer::Channel> kBruteReads = {
    gbuffer::Channel::Depth, gbuffer::Channel::Normal, gbuffer::Channel::Albedo,
    gbuffer::Channel::Specular};

scenes::Scene atrium() {
    scenes::SceneRequest request;
    request.lightCount = 4;
    request.seed = 1;
    return scenes::buildProceduralScene("atrium", request);
}

bool same(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// Decodes every packet with every ISA and compares covered lanes with GBuffer::decode; at least
// `minCoverage` of the view must be covered. The metallic-roughness lanes (of the last ISA) go to
// metallicRoughnessLanes when given.
void expectDecodesLikeGBuffer(const lighting::PreparedScene& frame, double minCoverage = 0.5,
                              size_t* metallicRoughnessLanes = nullptr) {
    const gbuffer::GBuffer& gb = *frame.gbuffer;
    const kerneltest::GBufferPlaneCopy copy(gb);
    const PacketDecoder decoder(gb.layout(), frame.view, copy.planes());
    for (const KernelIsa& isa : KernelIsa::available()) {
        int mismatches = 0;
        size_t coveredLanes = 0;
        size_t modelLanes[2] = {}; // Blinn-Phong, metallic-roughness
        for (int y0 = 0; y0 < gb.height(); y0 += 4)
            for (int x0 = 0; x0 < gb.width(); x0 += 4) {
                ShadingPacket packet = kerneltest::poisonedPacket();
                decoder.decode(isa, x0, y0, packet);
                ASSERT_EQ(packet.x0, x0);
                ASSERT_EQ(packet.y0, y0);
                for (int lane = 0; lane < lighting::kernel::kPacketLanes; ++lane) {
                    const int x = x0 + lighting::kernel::laneX(lane);
                    const int y = y0 + lighting::kernel::laneY(lane);
                    const bool inside = x < gb.width() && y < gb.height();
                    const bool covered = inside && gb.covered(size_t(y) * gb.width() + x);
                    ASSERT_EQ(bool(packet.laneMask >> lane & 1u), covered)
                        << isa.name() << " pixel " << x << "," << y;
                    if (!covered) {
                        ASSERT_FALSE(packet.metallicRoughnessMask >> lane & 1u);
                        continue;
                    }
                    ++coveredLanes;
                    const gbuffer::Surface s = gb.decode(x, y);
                    bool equal = same(packet.specularIntensity[lane], s.specularIntensity) &&
                                 same(packet.specularPower[lane], s.specularPower) &&
                                 same(packet.roughness[lane], s.roughness) &&
                                 same(packet.metallic[lane], s.metallic) &&
                                 same(packet.occlusion[lane], s.occlusion);
                    const bool metallicRoughness = packet.metallicRoughnessMask >> lane & 1u;
                    equal = equal && metallicRoughness ==
                                         (s.model == scenes::MaterialModel::MetallicRoughness);
                    modelLanes[metallicRoughness ? 1 : 0]++;
                    for (int k = 0; k < 3; ++k)
                        equal = equal && same(packet.positionView[k][lane], s.positionView[k]) &&
                                same(packet.normalView[k][lane], s.normalView[k]) &&
                                same(packet.albedo[k][lane], s.albedo[k]);
                    if (!equal && ++mismatches <= 5)
                        ADD_FAILURE()
                            << isa.name() << " layout " << gb.layout().name << " pixel " << x << ","
                            << y << ": position " << packet.positionView[0][lane] << ","
                            << packet.positionView[1][lane] << "," << packet.positionView[2][lane]
                            << " vs " << s.positionView.x << "," << s.positionView.y << ","
                            << s.positionView.z;
                }
            }
        EXPECT_EQ(mismatches, 0) << isa.name();
        EXPECT_GT(coveredLanes, size_t(kWidth * kHeight * minCoverage))
            << "the view should be covered";
        if (metallicRoughnessLanes)
            *metallicRoughnessLanes = modelLanes[1];
    }
}

TEST(PacketDecoder, DerivedAtriumLayout) {
    scenes::Scene scene = atrium();
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kBruteReads);
    ASSERT_EQ(layout.albedo, gbuffer::AlbedoEncoding::Material);
    ASSERT_EQ(layout.specular, gbuffer::SpecularEncoding::Material);
    ASSERT_TRUE(PacketDecoder::supports(layout));
    const lighting::PreparedScene frame(std::move(scene), kWidth, kHeight, false, layout);
    expectDecodesLikeGBuffer(frame);
}

TEST(PacketDecoder, ReferenceLayout) {
    const lighting::PreparedScene frame(atrium(), kWidth, kHeight);
    ASSERT_EQ(frame.gbuffer->layout().albedo, gbuffer::AlbedoEncoding::Float32);
    expectDecodesLikeGBuffer(frame);
}

TEST(PacketDecoder, ViewRayFromStandardUnorm24Depth) {
    scenes::Scene scene = atrium();
    gbuffer::LayoutRequest request;
    request.position = gbuffer::PositionMethod::ViewRay;
    request.depth = gbuffer::DepthFormatSpec::parse("unorm24");
    const gbuffer::GBufferLayout layout = gbuffer::makeLayout(scene, kBruteReads, "brute", request);
    ASSERT_EQ(layout.position, gbuffer::PositionMethod::ViewRay);
    const lighting::PreparedScene frame(std::move(scene), kWidth, kHeight, false, layout);
    ASSERT_FALSE(frame.view.reversedZ());
    expectDecodesLikeGBuffer(frame);
}

TEST(PacketDecoder, ViewRayInfiniteFar) {
    scenes::Scene scene = atrium();
    gbuffer::LayoutRequest request;
    request.position = gbuffer::PositionMethod::ViewRay;
    request.depth = gbuffer::DepthFormatSpec::parse("f32-reversed:infinite");
    const gbuffer::GBufferLayout layout = gbuffer::makeLayout(scene, kBruteReads, "brute", request);
    const lighting::PreparedScene frame(std::move(scene), kWidth, kHeight, false, layout);
    ASSERT_TRUE(frame.view.infiniteFar);
    expectDecodesLikeGBuffer(frame);
}

TEST(PacketDecoder, ConstantAlbedoAndSpecular) {
    scenes::Scene scene = atrium();
    gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kBruteReads);
    layout.albedo = gbuffer::AlbedoEncoding::Constant;
    layout.specular = gbuffer::SpecularEncoding::Constant;
    layout.constant = {{0.3f, 0.4f, 0.5f}, 0.25f, 7.0f};
    const lighting::PreparedScene frame(std::move(scene), kWidth, kHeight, false, layout);
    expectDecodesLikeGBuffer(frame);
}

// The material lookup's two paths (a permutation when the table fits in a vector, a gather when
// not) and indices past the table, which GBuffer::decode reads as albedo 0, specular (0, 1).
// The G-buffer pass never writes such indices, so they are planted in a copy of the planes.
TEST(PacketDecoder, MaterialLookupPathsAndIndicesPastTheTable) {
    scenes::Scene scene = atrium();
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kBruteReads);
    const lighting::PreparedScene frame(std::move(scene), 64, 36, false, layout);
    const gbuffer::GBuffer& gb = *frame.gbuffer;
    for (size_t extra : {size_t(0), size_t(20)}) {
        // With 20 more (unused) materials the table fits no vector: every target gathers.
        gbuffer::GBufferLayout table = layout;
        for (size_t i = 0; i < extra; ++i)
            table.materials.push_back({{0.1f * float(i % 10), 0.5f, 0.25f}, 0.5f, float(i + 2)});
        kerneltest::GBufferPlaneCopy copy(gb);
        const uint16_t pastTheTable[3] = {uint16_t(table.materials.size()),
                                          uint16_t(table.materials.size() + 5), 65535};
        for (size_t pixel = 0; pixel < copy.material.size(); pixel += 7)
            copy.material[pixel] = pastTheTable[pixel % 3];
        const PacketDecoder decoder(table, frame.view, copy.planes());
        for (int y0 = 0; y0 < gb.height(); y0 += 4)
            for (int x0 = 0; x0 < gb.width(); x0 += 4) {
                ShadingPacket expected = kerneltest::poisonedPacket();
                decoder.decodeScalar(x0, y0, expected);
                for (const KernelIsa& isa : KernelIsa::available()) {
                    ShadingPacket packet = kerneltest::poisonedPacket();
                    decoder.decode(isa, x0, y0, packet);
                    ASSERT_EQ(packet.laneMask, expected.laneMask);
                    for (int lane = 0; lane < lighting::kernel::kPacketLanes; ++lane) {
                        if (!(packet.laneMask >> lane & 1u))
                            continue;
                        const size_t pixel =
                            size_t(y0 + lighting::kernel::laneY(lane)) * gb.width() +
                            size_t(x0 + lighting::kernel::laneX(lane));
                        const bool past = copy.material[pixel] >= table.materials.size();
                        const gbuffer::Surface s = gb.decode(x0 + lighting::kernel::laneX(lane),
                                                             y0 + lighting::kernel::laneY(lane));
                        for (int k = 0; k < 3; ++k) {
                            EXPECT_TRUE(same(packet.albedo[k][lane], expected.albedo[k][lane]));
                            EXPECT_TRUE(same(packet.albedo[k][lane], past ? 0.0f : s.albedo[k]))
                                << isa.name() << " extra " << extra << " pixel " << pixel;
                        }
                        EXPECT_TRUE(same(packet.specularIntensity[lane],
                                         past ? 0.0f : s.specularIntensity));
                        EXPECT_TRUE(
                            same(packet.specularPower[lane], past ? 1.0f : s.specularPower));
                    }
                }
            }
    }
}

// The DamagedHelmet (metallic-roughness, textured: float32 roughness, metallic and, with an
// ambient light, occlusion planes).
TEST(PacketDecoder, DamagedHelmetMetallicRoughnessPlanes) {
    scenes::SceneRequest request;
    request.lightCount = 4;
    request.seed = 1;
    scenes::Scene scene =
        scenes::loadScene(TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", request);
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kBruteReads);
    ASSERT_EQ(layout.roughnessMetallic, gbuffer::RoughnessMetallicEncoding::Float32);
    ASSERT_EQ(layout.constant.model, scenes::MaterialModel::MetallicRoughness);
    ASSERT_TRUE(PacketDecoder::supports(layout));
    const lighting::PreparedScene frame(std::move(scene), kWidth, kHeight, false, layout);
    // The model covers ~8% of the view; every covered lane is metallic-roughness.
    size_t metallicRoughnessLanes = 0;
    expectDecodesLikeGBuffer(frame, 0.05, &metallicRoughnessLanes);
    EXPECT_GT(metallicRoughnessLanes, 1000u);
}

// Both models in one scene: atrium with every other material made metallic-roughness, so the
// model and roughness-metallic come from the material index.
TEST(PacketDecoder, MixedModelsFromTheMaterialIndex) {
    scenes::Scene scene = atrium();
    for (size_t i = 0; i < scene.materials.size(); i += 2) {
        scene.materials[i].model = scenes::MaterialModel::MetallicRoughness;
        scene.materials[i].roughness = 0.1f + 0.1f * float(i);
        scene.materials[i].metallic = i % 4 == 0 ? 1.0f : 0.25f;
    }
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kBruteReads);
    ASSERT_TRUE(layout.modelPerMaterial);
    ASSERT_EQ(layout.roughnessMetallic, gbuffer::RoughnessMetallicEncoding::Material);
    ASSERT_TRUE(PacketDecoder::supports(layout));
    const lighting::PreparedScene frame(std::move(scene), kWidth, kHeight, false, layout);
    size_t metallicRoughnessLanes = 0;
    expectDecodesLikeGBuffer(frame, 0.5, &metallicRoughnessLanes);
    EXPECT_GT(metallicRoughnessLanes, 1000u);
}

TEST(PacketDecoder, RefusesLayoutsItCannotDecode) {
    scenes::Scene scene = atrium();
    gbuffer::LayoutRequest request;
    request.normals = gbuffer::NormalCodecSpec::parse("octahedral:24");
    const gbuffer::GBufferLayout layout = gbuffer::makeLayout(scene, kBruteReads, "brute", request);
    std::string why;
    EXPECT_FALSE(PacketDecoder::supports(layout, &why));
    EXPECT_NE(why.find("codes"), std::string::npos) << why;
    const gbuffer::GBufferLayout derived = gbuffer::deriveLayout(scene, kBruteReads);
    const lighting::PreparedScene frame(std::move(scene), 64, 36, false, layout);
    const kerneltest::GBufferPlaneCopy copy(*frame.gbuffer);
    EXPECT_THROW(PacketDecoder(layout, frame.view, copy.planes()), std::invalid_argument);
    lighting::kernel::GBufferPlanes missing = copy.planes();
    missing.material = nullptr;
    EXPECT_THROW(PacketDecoder(derived, frame.view, missing), std::invalid_argument);
    gbuffer::GBufferLayout packed = derived;
    packed.roughnessMetallic = gbuffer::RoughnessMetallicEncoding::Unorm8;
    EXPECT_FALSE(PacketDecoder::supports(packed, &why));
    EXPECT_NE(why.find("roughness"), std::string::npos) << why;
}

} // namespace
