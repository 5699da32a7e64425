// G-buffer layouts: derivation from the scene's materials and the stage's needs (each rule of
// gbuffer/LayoutDerivation.h), presets' sizes, the encodings' storage round trip, and the claim
// that the derived layout is lossless (brute on it gives bitwise the image of brute on reference).
#include <gtest/gtest.h>

#include "tests/gbuffer/TwoQuads.h"

#include <cstring>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/SceneRequest.h"
#include "scenes/materials/Texture.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

using gbuffer::AlbedoEncoding;
using gbuffer::Channel;
using gbuffer::SpecularEncoding;

const std::vector<Channel> kEverything = {Channel::Depth, Channel::Normal, Channel::Albedo,
                                          Channel::Specular};

using gbuffertest::twoQuads;

scenes::Material material(glm::vec3 albedo, float intensity, float power) {
    scenes::Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    m.specularIntensity = intensity;
    m.specularPower = power;
    return m;
}

TEST(LayoutDerivation, SharedSpecularStoresNoSpecularPlane) {
    const scenes::Scene scene =
        twoQuads(material({1, 0, 0}, 0.5f, 20.0f), material({0, 1, 0}, 0.5f, 20.0f));
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_EQ(layout.specular, SpecularEncoding::Constant);
    for (const gbuffer::PlaneDesc& plane : layout.planes())
        EXPECT_NE(plane.channel, "specular") << plane.name;
    EXPECT_NE(layout.explain().find("every used material has specular intensity"),
              std::string::npos)
        << layout.explain();
}

TEST(LayoutDerivation, OneColourPerMaterialStoresAMaterialIndexInsteadOfAlbedo) {
    const scenes::Scene scene =
        twoQuads(material({1, 0, 0}, 0.5f, 20.0f), material({0, 1, 0}, 0.2f, 60.0f));
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_EQ(layout.albedo, AlbedoEncoding::Material);
    EXPECT_EQ(layout.specular, SpecularEncoding::Material);
    int materialPlanes = 0;
    for (const gbuffer::PlaneDesc& plane : layout.planes()) {
        EXPECT_NE(plane.channel, "albedo") << plane.name;
        materialPlanes += plane.channel == "material";
    }
    EXPECT_EQ(materialPlanes, 1);
    // depth 32 + normal 96 + material index 8 bits
    EXPECT_DOUBLE_EQ(layout.bytesPerPixel(), (32 + 96 + 8) / 8.0);
}

TEST(LayoutDerivation, OneColourForTheWholeSceneIsAConstant) {
    const scenes::Scene scene = twoQuads(material({0.3f, 0.3f, 0.3f}, 0.5f, 20.0f),
                                         material({0.3f, 0.3f, 0.3f}, 0.2f, 60.0f));
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_EQ(layout.albedo, AlbedoEncoding::Constant);
    EXPECT_EQ(layout.specular, SpecularEncoding::Material);
}

TEST(LayoutDerivation, TexturedMaterialsStoreAlbedoPerPixel) {
    scenes::Scene scene =
        twoQuads(material({1, 1, 1}, 0.5f, 20.0f), material({0, 1, 0}, 0.5f, 20.0f));
    scenes::Texture texture;
    texture.name = "one texel";
    texture.width = texture.height = 1;
    texture.rgba8 = {128, 64, 255, 255};
    scene.textures.push_back(texture);
    scene.materials[0].baseColorTexture = 0;
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_EQ(layout.albedo, AlbedoEncoding::Float32);
    EXPECT_NE(layout.explain().find("textured"), std::string::npos);
}

TEST(LayoutDerivation, AStageGetsOnlyTheChannelsItReads) {
    const scenes::Scene scene = scenes::buildProceduralScene("spheres", {});
    for (const lighting::StageInfo& info : lighting::stageInfos()) {
        const auto stage = lighting::makeStage(info.name);
        const std::vector<Channel> reads = stage->requirements().channels;
        const gbuffer::GBufferLayout layout = gbuffer::makeLayout(scene, reads, info.name, {});
        for (Channel channel : {Channel::Normal, Channel::Albedo, Channel::Specular}) {
            const bool read = std::find(reads.begin(), reads.end(), channel) != reads.end();
            EXPECT_EQ(layout.provides(channel), read)
                << info.name << " " << gbuffer::channelName(channel);
        }
    }
    // Forward shading reads no G-buffer channel: depth (coverage) alone, 4 bytes.
    const gbuffer::GBufferLayout forward = gbuffer::makeLayout(
        scene, lighting::makeStage("forward")->requirements().channels, "forward", {});
    EXPECT_DOUBLE_EQ(forward.bytesPerPixel(), 4.0);
    EXPECT_NE(forward.explain().find("does not read normals"), std::string::npos)
        << forward.explain();
}

TEST(LayoutDerivation, AnOverrideOfAnUnreadChannelIsReportedNotStored) {
    const scenes::Scene scene = scenes::buildProceduralScene("spheres", {});
    gbuffer::LayoutRequest request;
    request.normals = gbuffer::NormalCodecSpec::parse("octahedral:16");
    const gbuffer::GBufferLayout layout =
        gbuffer::makeLayout(scene, {Channel::Depth}, "forward", request);
    EXPECT_FALSE(layout.provides(Channel::Normal));
    ASSERT_FALSE(layout.notes.empty());
    EXPECT_NE(layout.notes.back().find("does not read normals"), std::string::npos);
}

TEST(LayoutPresets, HistoricalSizesMatchTheThesis) {
    const scenes::Scene scene = scenes::buildProceduralScene("spheres", {});
    // Thesis chapter 4: RGBA8 + RGBA16F + D24S8 = 128 bits.
    EXPECT_DOUBLE_EQ(gbuffer::presetLayout("thesis", scene).bytesPerPixel(), 16.0);
    // Killzone 2 and BF3: 4 x RGBA8 + D24S8 = 160 bits.
    EXPECT_DOUBLE_EQ(gbuffer::presetLayout("killzone2", scene).bytesPerPixel(), 20.0);
    EXPECT_DOUBLE_EQ(gbuffer::presetLayout("bf3", scene).bytesPerPixel(), 20.0);
    // S.T.A.L.K.E.R. 160 and Clear Sky 96 bits, each + 8 bits of specular intensity (noted).
    EXPECT_DOUBLE_EQ(gbuffer::presetLayout("stalker", scene).bytesPerPixel(), 21.0);
    EXPECT_DOUBLE_EQ(gbuffer::presetLayout("clear-sky", scene).bytesPerPixel(), 13.0);
    EXPECT_FALSE(gbuffer::presetLayout("clear-sky", scene).notes.empty());
    EXPECT_THROW(gbuffer::presetLayout("gbuffer-of-doom", scene), std::invalid_argument);
}

// UE4's deferred base pass (4.18): D32S8 + GBufferA (RGB10A2) + GBufferB (RGBA8) + GBufferC
// (RGBA8) = 136 bits, whichever material model the scene uses: what a channel does not carry for
// this scene is counted as unmodelled, never dropped from the budget.
TEST(LayoutPresets, Ue4IsD32S8PlusThreeTargets) {
    const scenes::Scene blinnPhong = scenes::buildProceduralScene("spheres", {});
    const gbuffer::GBufferLayout layout = gbuffer::presetLayout("ue4", blinnPhong);
    EXPECT_DOUBLE_EQ(layout.bytesPerPixel(), 17.0);
    EXPECT_EQ(layout.normals.text(), "xyz:30");
    EXPECT_EQ(layout.normalSpace, gbuffer::NormalSpace::World);
    EXPECT_EQ(layout.albedo, gbuffer::AlbedoEncoding::Rgb8Srgb);
    EXPECT_NE(layout.explain().find("GBufferA"), std::string::npos) << layout.explain();

    scenes::Scene metallic = blinnPhong;
    for (scenes::Material& m : metallic.materials) {
        m.model = scenes::MaterialModel::MetallicRoughness;
        m.metallicRoughnessTexture = -1;
    }
    metallic.materials[0].roughness = 0.25f; // two values: stored, not a constant
    const gbuffer::GBufferLayout pbr = gbuffer::presetLayout("ue4", metallic);
    EXPECT_DOUBLE_EQ(pbr.bytesPerPixel(), 17.0);
    EXPECT_EQ(pbr.specular, gbuffer::SpecularEncoding::None);
}

// Brute on the derived layout must be bitwise brute on the reference layout: derivation only
// removes what is constant or redundant, never precision.
TEST(LayoutDerivation, DerivedLayoutIsLossless) {
    auto shade = [](const gbuffer::GBufferLayout* layout) {
        scenes::SceneRequest request;
        request.lightCount = 48;
        scenes::Scene scene = scenes::buildProceduralScene("atrium", request);
        const gbuffer::GBufferLayout used = layout ? gbuffer::deriveLayout(scene, kEverything)
                                                   : gbuffer::GBufferLayout::reference();
        lighting::PreparedScene frame(std::move(scene), 160, 90, false, used);
        lighting::StageResult result;
        lighting::makeStage("brute")->shade(frame.inputs, result);
        return std::make_pair(result, frame.gbuffer->layout().bytesPerPixel());
    };
    const gbuffer::GBufferLayout marker;
    const auto [derived, derivedBytes] = shade(&marker);
    const auto [reference, referenceBytes] = shade(nullptr);
    EXPECT_LT(derivedBytes, referenceBytes);
    for (int c = 0; c < 3; ++c)
        EXPECT_EQ(std::memcmp(derived.radiance[c].data(), reference.radiance[c].data(),
                              derived.radiance[c].size() * sizeof(float)),
                  0)
            << c;
}

// Every encoding the G-buffer stores decodes to within its format's step of the lossless value,
// and coverage never changes.
TEST(GBufferStorage, LossyEncodingsDecodeCloseToTheLosslessSurface) {
    scenes::SceneRequest sceneRequest;
    const scenes::Scene scene = scenes::buildProceduralScene("atrium", sceneRequest);
    lighting::PreparedScene lossless(scenes::Scene(scene), 160, 90, false,
                                     gbuffer::deriveLayout(scene, kEverything));
    for (const char* preset :
         {"thesis", "killzone2", "bf3", "stalker", "clear-sky", "compact", "ue4"}) {
        const gbuffer::GBufferLayout layout = gbuffer::presetLayout(preset, scene);
        lighting::PreparedScene lossy(scenes::Scene(scene), 160, 90, false, layout);
        const gbuffer::GBuffer& a = *lossless.gbuffer;
        const gbuffer::GBuffer& b = *lossy.gbuffer;
        size_t coverageDiffers = 0, covered = 0, compared = 0;
        double worstAlbedo = 0, worstIntensity = 0, worstPowerRatio = 0, worstNormalDot = 1;
        for (int y = 0; y < a.height(); ++y)
            for (int x = 0; x < a.width(); ++x) {
                const size_t pixel = size_t(y) * a.width() + x;
                if (a.covered(pixel) != b.covered(pixel)) {
                    ++coverageDiffers;
                    continue;
                }
                if (!a.covered(pixel))
                    continue;
                const gbuffer::Surface sa = a.decode(x, y), sb = b.decode(x, y);
                ++covered;
                // A different surface may win the depth test where depths nearly tie.
                if (glm::length(sa.positionView - sb.positionView) > 0.01f * -sa.positionView.z)
                    continue;
                ++compared;
                worstAlbedo = std::max(worstAlbedo, double(glm::length(sa.albedo - sb.albedo)));
                worstIntensity = std::max(
                    worstIntensity, double(std::abs(sa.specularIntensity - sb.specularIntensity)));
                worstPowerRatio = std::max(
                    worstPowerRatio, double(std::abs(sb.specularPower / sa.specularPower - 1)));
                if (sa.normalView.z >
                    0.05f) // xy-z cannot hold back-facing normals: measured elsewhere
                    worstNormalDot =
                        std::min(worstNormalDot, double(glm::dot(sa.normalView, sb.normalView)));
            }
        EXPECT_EQ(coverageDiffers, 0u) << preset;
        EXPECT_GT(compared, covered * 9 / 10) << preset;
        EXPECT_LT(worstAlbedo, 0.01) << preset;                // RGB8 sRGB: < 1/255 in sRGB space
        EXPECT_LT(worstIntensity, 0.5 / 255 + 1e-6) << preset; // unorm8
        EXPECT_LT(worstPowerRatio, 0.03) << preset; // log8 over 2^13: 2^(13/510) - 1 = 1.8%
        EXPECT_GT(worstNormalDot, std::cos(glm::radians(1.5))) << preset;
    }
}

} // namespace

namespace {

// World-space codes decode back to the same view-space normals (within the codec's error), and
// the hemisphere codecs refuse world space.
TEST(GBufferStorage, WorldSpaceNormalsDecodeToViewSpace) {
    const scenes::Scene scene = scenes::buildProceduralScene("atrium", {});
    lighting::PreparedScene lossless(scenes::Scene(scene), 160, 90, false,
                                     gbuffer::deriveLayout(scene, kEverything));
    gbuffer::LayoutRequest request;
    request.normals = gbuffer::NormalCodecSpec::parse("octahedral:24");
    request.normalSpace = gbuffer::NormalSpace::World;
    const gbuffer::GBufferLayout world = gbuffer::makeLayout(scene, kEverything, "brute", request);
    lighting::PreparedScene encoded(scenes::Scene(scene), 160, 90, false, world);
    double worst = 0.0;
    for (int y = 0; y < 90; ++y)
        for (int x = 0; x < 160; ++x) {
            if (!lossless.gbuffer->covered(size_t(y) * 160 + x))
                continue;
            worst = std::max(worst,
                             gbuffer::normalAngleRadians(lossless.gbuffer->decode(x, y).normalView,
                                                         encoded.gbuffer->decode(x, y).normalView));
        }
    EXPECT_LT(glm::degrees(worst), 0.1); // octahedral 2x12 bits: max ~0.06 degrees
    request.normals = gbuffer::NormalCodecSpec::parse("xy-z:16");
    EXPECT_THROW(gbuffer::makeLayout(scene, kEverything, "brute", request), std::invalid_argument);
}

} // namespace
