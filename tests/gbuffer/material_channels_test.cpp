// The metallic-roughness channels of the G-buffer: how the layout derivation stores roughness,
// metallic and the material model (gbuffer/LayoutDerivation.h addMaterialModels), their storage
// round trip, the normal-mapping formula the resolve and the reference share
// (gbuffer/visibility/NormalMapping.h), and that the derived layout stays lossless on a glTF model
// with metallic-roughness and normal textures (brute on it gives bitwise brute on the reference
// layout, and the derived layout is smaller).
#include <gtest/gtest.h>

#include "tests/gbuffer/TwoQuads.h"

#include <cmath>

#include "gbuffer/LayoutDerivation.h"
#include "gbuffer/visibility/NormalMapping.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/SceneLoader.h"
#include "scenes/SceneRequest.h"
#include "scenes/materials/Texture.h"

namespace {

using gbuffer::Channel;
using gbuffer::RoughnessMetallicEncoding;
using scenes::MaterialModel;

const std::vector<Channel> kEverything = {Channel::Depth, Channel::Normal, Channel::Albedo,
                                          Channel::Specular, Channel::Emission};

// The first covered pixel of row y scanning from the left (or from the right).
int coveredPixel(const gbuffer::GBuffer& gb, int y, bool fromLeft) {
    for (int i = 0; i < gb.width(); ++i) {
        const int x = fromLeft ? i : gb.width() - 1 - i;
        if (gb.covered(size_t(y) * size_t(gb.width()) + size_t(x)))
            return x;
    }
    return -1;
}

using gbuffertest::twoQuads;

scenes::Material metallicRoughness(float roughness, float metallic) {
    scenes::Material m;
    m.model = MaterialModel::MetallicRoughness;
    m.roughness = roughness;
    m.metallic = metallic;
    scenes::setBlinnPhongFromMetallicRoughness(m);
    return m;
}

TEST(MaterialChannels, SharedFactorsAreAConstantAndNoBlinnPhongPlane) {
    const scenes::Scene scene =
        twoQuads(metallicRoughness(0.3f, 1.0f), metallicRoughness(0.3f, 1.0f));
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_EQ(layout.roughnessMetallic, RoughnessMetallicEncoding::Constant);
    EXPECT_EQ(layout.specular, gbuffer::SpecularEncoding::None);
    EXPECT_EQ(layout.constant.model, MaterialModel::MetallicRoughness);
    EXPECT_FALSE(layout.modelPerMaterial);
    EXPECT_TRUE(layout.provides(Channel::Specular));
    EXPECT_FALSE(layout.hasMaterialIndex());
}

TEST(MaterialChannels, DifferentFactorsUseTheMaterialIndex) {
    const scenes::Scene scene =
        twoQuads(metallicRoughness(0.3f, 1.0f), metallicRoughness(0.8f, 0.0f));
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_EQ(layout.roughnessMetallic, RoughnessMetallicEncoding::Material);
    EXPECT_TRUE(layout.hasMaterialIndex());
}

TEST(MaterialChannels, MixedModelsDecodeTheModelPerMaterial) {
    scenes::Material blinnPhong;
    const scenes::Scene scene = twoQuads(blinnPhong, metallicRoughness(0.5f, 0.0f));
    const gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_TRUE(layout.modelPerMaterial);
    EXPECT_TRUE(layout.hasMaterialIndex());
    EXPECT_NE(layout.specular, gbuffer::SpecularEncoding::None); // the Blinn-Phong quad's
    lighting::PreparedScene frame(scene, 64, 32, false, layout);
    gbuffer::Surface left, right;
    const int xLeft = coveredPixel(*frame.gbuffer, 16, true);
    const int xRight = coveredPixel(*frame.gbuffer, 16, false);
    ASSERT_GE(xLeft, 0);
    ASSERT_LT(xLeft, 32);
    ASSERT_GE(xRight, 32);
    ASSERT_TRUE(frame.gbuffer->surfaceAt(xLeft, 16, left));
    ASSERT_TRUE(frame.gbuffer->surfaceAt(xRight, 16, right));
    EXPECT_EQ(left.model, MaterialModel::BlinnPhong);
    EXPECT_EQ(right.model, MaterialModel::MetallicRoughness);
    EXPECT_EQ(right.roughness, 0.5f);
    EXPECT_EQ(right.metallic, 0.0f);
}

// A 1x1 metallic-roughness texture (G = roughness, B = metallic) makes the values per pixel:
// float32 in the derived layout (decoded exactly as the resolve computed them), 8 bits each in
// the compact preset (within half a step of 1/255). The same texture as occlusion (R = 0, at
// strength 0.25: occlusion 0.75) is stored too, because the scene has an ambient light.
TEST(MaterialChannels, TexturedRoughnessIsStoredPerPixel) {
    scenes::Scene scene = twoQuads(metallicRoughness(1.0f, 1.0f), metallicRoughness(0.5f, 0.0f));
    scenes::Texture texture;
    texture.name = "one texel";
    texture.width = texture.height = 1;
    texture.srgb = false;
    texture.rgba8 = {0, 100, 200, 255};
    scene.textures.push_back(texture);
    scene.materials[0].metallicRoughnessTexture = 0;
    scene.materials[0].occlusionTexture = 0;
    scene.materials[0].occlusionStrength = 0.25f;
    scenes::Light ambient;
    ambient.type = scenes::LightType::Ambient;
    scene.lights.push_back(ambient);
    const float roughness = 100.0f / 255.0f, metallic = 200.0f / 255.0f;
    for (const char* preset : {"", "compact"}) {
        gbuffer::LayoutRequest request;
        request.preset = preset;
        const gbuffer::GBufferLayout layout =
            gbuffer::makeLayout(scene, kEverything, "brute", request);
        EXPECT_EQ(layout.roughnessMetallic,
                  *preset ? RoughnessMetallicEncoding::Unorm8 : RoughnessMetallicEncoding::Float32);
        EXPECT_EQ(layout.occlusion, layout.roughnessMetallic);
        lighting::PreparedScene frame(scene, 64, 32, false, layout);
        gbuffer::Surface s;
        const int x = coveredPixel(*frame.gbuffer, 16, true);
        ASSERT_GE(x, 0);
        ASSERT_LT(x, 32);
        ASSERT_TRUE(frame.gbuffer->surfaceAt(x, 16, s));
        const float tolerance = *preset ? 0.5f / 255.0f : 1e-6f;
        EXPECT_NEAR(s.roughness, roughness, tolerance) << preset;
        EXPECT_NEAR(s.metallic, metallic, tolerance) << preset;
        EXPECT_NEAR(s.occlusion, 0.75f, tolerance) << preset;
        EXPECT_EQ(s.model, MaterialModel::MetallicRoughness);
    }
}

TEST(NormalMapping, TheFlatTexelKeepsTheNormal) {
    const glm::dvec3 n(0, 0, 1), t(1, 0, 0);
    // 128/255 is not exactly 0.5: the flat texel of an 8-bit map tilts by ~0.2 degrees.
    const glm::dvec3 flat = gbuffer::normalMapped(n, false, t, 1.0, glm::dvec3(0.5, 0.5, 1), 1.0);
    EXPECT_NEAR(glm::distance(flat, n), 0.0, 1e-15);
}

TEST(NormalMapping, TiltsAlongTangentAndBitangentWithScaleAndSign) {
    const glm::dvec3 n(0, 0, 1), t(2, 0, 0.5); // not unit, not orthogonal: Gram-Schmidt
    // texel (1, 0.5, 0.5): m = (1 * scale, 0, 0) -> along T, normalised.
    const glm::dvec3 alongT = gbuffer::normalMapped(n, false, t, 1.0, glm::dvec3(1, 0.5, 0.5), 1.0);
    EXPECT_NEAR(glm::distance(alongT, glm::dvec3(1, 0, 0)), 0.0, 1e-15);
    // texel (0.5, 1, 1): m = (0, s, 1), B = w cross(N, T) = w (0, 1, 0).
    for (double w : {1.0, -1.0})
        for (double scale : {0.5, 2.0}) {
            const glm::dvec3 m =
                gbuffer::normalMapped(n, false, t, w, glm::dvec3(0.5, 1, 1), scale);
            const glm::dvec3 expected = glm::normalize(glm::dvec3(0, w * scale, 1));
            EXPECT_NEAR(glm::distance(m, expected), 0.0, 1e-15) << w << " " << scale;
        }
    // Seen from behind, the same bump: the front result negated.
    const glm::dvec3 front = gbuffer::normalMapped(n, false, t, 1.0, glm::dvec3(0.7, 0.9, 1), 1.0);
    const glm::dvec3 back = gbuffer::normalMapped(-n, true, t, 1.0, glm::dvec3(0.7, 0.9, 1), 1.0);
    EXPECT_NEAR(glm::distance(back, -front), 0.0, 1e-15);
    // Degenerate tangent: the normal is kept.
    EXPECT_EQ(gbuffer::normalMapped(n, false, glm::dvec3(0, 0, 3), 1.0, glm::dvec3(1, 1, 1), 1.0),
              n);
}

// DamagedHelmet: metallic-roughness, normal, occlusion and emissive textures. Brute on the derived
// layout must give bitwise brute on the reference layout (the derived layout is lossless), and the
// normal map must change the image (the normals differ from the unmapped ones).
TEST(MaterialChannels, DerivedLayoutIsLosslessOnDamagedHelmet) {
    scenes::SceneRequest request;
    request.lightCount = 16;
    const scenes::Scene scene =
        scenes::loadScene(TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", request);
    auto shade = [&](const gbuffer::GBufferLayout& layout) {
        lighting::PreparedScene frame(scene, 160, 90, false, layout);
        lighting::StageResult result;
        lighting::makeStage("brute")->shade(frame.inputs, result);
        return result;
    };
    const gbuffer::GBufferLayout derived = gbuffer::deriveLayout(scene, kEverything);
    EXPECT_EQ(derived.roughnessMetallic, RoughnessMetallicEncoding::Float32);
    EXPECT_EQ(derived.constant.model, MaterialModel::MetallicRoughness);
    const lighting::StageResult a = shade(derived);
    const lighting::StageResult b = shade(gbuffer::GBufferLayout::reference());
    for (int c = 0; c < 3; ++c)
        EXPECT_EQ(a.radiance[c], b.radiance[c]) << c;
    double peak = 0.0;
    for (float v : a.radiance[0])
        peak = std::max(peak, double(v));
    EXPECT_GT(peak, 0.0);
}

} // namespace
