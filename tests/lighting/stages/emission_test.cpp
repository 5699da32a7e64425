// Emission (glTF emissiveFactor x KHR_materials_emissive_strength x emissiveTexture): added once
// per pixel, after the light sum, by every registered stage and the reference, never per light;
// light counts unaffected. Checked in closed form on two quads facing the camera: the left one
// Blinn-Phong with an untextured emission, the right one metallic-roughness with a 1x1 sRGB
// emissive texture, under three lights that all reach both quads (a per-light emission would be
// counted three times). Without any light the image is exactly the emission. A blended (BLEND)
// pane that emits, over an emitting wall: its emission is composited with its lit colour by
// "over" in every stage's blended pass and the reference's composite
// (lighting/passes/BlendedPass.h).
#include <gtest/gtest.h>

#include "tests/gbuffer/TwoQuads.h"
#include "tests/lighting/StageTestName.h"

#include <cmath>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/materials/Texture.h"

namespace {

// The texel the emissive texture holds (sRGB), and its linear value computed here from the sRGB
// transfer function, independently of Texture::sample.
constexpr uint8_t kTexel[3] = {128, 64, 255};
float linearOfSrgb8(uint8_t value) {
    const double c = value / 255.0;
    return float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

const glm::vec3 kLeftFactor(0.5f, 0.25f, 1.0f);
constexpr float kLeftStrength = 3.0f;
const glm::vec3 kRightFactor(1.0f, 0.5f, 0.25f);
constexpr float kRightStrength = 2.0f;

// lightCount point lights in a rising row at depth z, of growing intensity.
void addLightRow(scenes::Scene& scene, int lightCount, float z) {
    for (int i = 0; i < lightCount; ++i) {
        scenes::Light light;
        light.type = scenes::LightType::Point;
        light.positionWorld = glm::vec3(-1.0f + float(i), 0.3f * float(i), z);
        light.color = glm::vec3(1.0f, 0.9f, 0.8f);
        light.intensity = float(i + 1);
        light.rangeMetres = 20.0f;
        scene.lights.push_back(light);
    }
}

scenes::Scene emissiveQuads(bool emissive, int lightCount) {
    scenes::Material left, right;
    left.baseColorFactor = glm::vec4(0.6f, 0.5f, 0.4f, 1.0f);
    right.model = scenes::MaterialModel::MetallicRoughness;
    right.baseColorFactor = glm::vec4(0.8f, 0.7f, 0.2f, 1.0f);
    right.roughness = 0.4f;
    right.metallic = 0.5f;
    scenes::setBlinnPhongFromMetallicRoughness(right);
    if (emissive) {
        left.emissiveFactor = kLeftFactor;
        left.emissiveStrength = kLeftStrength;
        right.emissiveFactor = kRightFactor;
        right.emissiveStrength = kRightStrength;
    }
    scenes::Scene scene = gbuffertest::twoQuads(left, right);
    scenes::Texture texture;
    texture.name = "one emissive texel";
    texture.width = texture.height = 1;
    texture.srgb = true;
    texture.rgba8 = {kTexel[0], kTexel[1], kTexel[2], 255};
    scene.textures.push_back(texture);
    if (emissive)
        scene.materials[1].emissiveTexture = 0;
    addLightRow(scene, lightCount, -2.5f);
    scenes::validate(scene);
    return scene;
}

// The closed form: what a covered pixel of each quad emits.
glm::vec3 expectedEmission(bool leftQuad) {
    if (leftQuad)
        return kLeftFactor * kLeftStrength;
    return kRightFactor * kRightStrength *
           glm::vec3(linearOfSrgb8(kTexel[0]), linearOfSrgb8(kTexel[1]), linearOfSrgb8(kTexel[2]));
}

lighting::StageResult shade(const scenes::Scene& scene, const std::string& stageName) {
    const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(stageName);
    const gbuffer::GBufferLayout layout =
        gbuffer::makeLayout(scene, stage->requirements().channels, stageName, {});
    lighting::PreparedScene frame(scene, 64, 32, stage->requirements().exactSurface, layout);
    lighting::StageResult result;
    stage->shade(frame.inputs, result);
    return result;
}

std::vector<std::string> everyStage() {
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        names.push_back(info.name);
    return names;
}

class EmissionPerStage : public ::testing::TestWithParam<std::string> {};

// Lit: the emissive scene's image is the non-emissive scene's plus the closed-form emission, at
// every pixel the non-emissive image covers, for three lights; counts are the same.
TEST_P(EmissionPerStage, AddedOncePerPixelAfterTheLights) {
    const std::string stageName = GetParam();
    const lighting::StageResult lit = shade(emissiveQuads(false, 3), stageName);
    const lighting::StageResult glowing = shade(emissiveQuads(true, 3), stageName);
    const lighting::StageResult dark = shade(emissiveQuads(true, 0), stageName);
    int covered = 0, failures = 0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 64; ++x) {
            const size_t pixel = size_t(y) * 64 + size_t(x);
            EXPECT_EQ(glowing.lightsEvaluated[pixel], lit.lightsEvaluated[pixel]);
            const bool background = dark.radiance[0][pixel] == 0.0f &&
                                    dark.radiance[1][pixel] == 0.0f &&
                                    dark.radiance[2][pixel] == 0.0f;
            if (background)
                continue;
            ++covered;
            const glm::vec3 emission = expectedEmission(x < 32);
            for (int c = 0; c < 3; ++c) {
                // No light: the emission (up to the texture's float sRGB table and bilinear
                // weights, a few ulps; a per-light emission would be off by 200% here).
                const float tolerance = 1e-5f * emission[c];
                if (!(std::abs(dark.radiance[c][pixel] - emission[c]) <= tolerance) &&
                    failures++ < 5)
                    ADD_FAILURE() << stageName << " unlit pixel (" << x << ", " << y << ") channel "
                                  << c << ": " << dark.radiance[c][pixel] << ", emission "
                                  << emission[c];
                const float expected = lit.radiance[c][pixel] + emission[c];
                if (!(std::abs(glowing.radiance[c][pixel] - expected) <= 1e-5f * expected) &&
                    failures++ < 5)
                    ADD_FAILURE() << stageName << " lit pixel (" << x << ", " << y << ") channel "
                                  << c << ": " << glowing.radiance[c][pixel] << ", expected "
                                  << expected << " (lights " << lit.radiance[c][pixel]
                                  << " + emission " << emission[c] << ")";
            }
        }
    EXPECT_GT(covered, 64 * 32 / 8) << stageName; // the quads cover 420 of 2048 pixels
    EXPECT_EQ(failures, 0) << stageName;
}

INSTANTIATE_TEST_SUITE_P(EveryStage, EmissionPerStage, ::testing::ValuesIn(everyStage()),
                         stagecheck::stageTestName);

// A blended pane that emits, over an emitting opaque wall: the pane's emission joins its lit
// colour before "over" (glTF's BLEND composites the surface's whole output; BlendedPass.h,
// "Emission"), so a pane pixel gains alpha x pane emission + (1 - alpha) x wall emission.
const glm::vec3 kWallEmission(0.2f, 0.1f, 0.05f);
const glm::vec3 kPaneFactor(1.0f, 0.5f, 0.2f);
constexpr float kPaneStrength = 1.5f;
constexpr float kPaneAlpha = 0.375f; // a few ulps of rounding at most: 3/8 is exact

scenes::Scene emissivePane(bool emissive, int lightCount) {
    scenes::Scene scene;
    scene.name = "emissive-pane";
    scenes::Material wall, pane;
    wall.baseColorFactor = glm::vec4(0.6f, 0.5f, 0.4f, 1.0f);
    pane.model = scenes::MaterialModel::MetallicRoughness;
    pane.baseColorFactor = glm::vec4(0.3f, 0.7f, 0.5f, kPaneAlpha);
    pane.roughness = 0.3f;
    pane.metallic = 0.2f;
    pane.alphaMode = scenes::AlphaMode::Blend;
    scenes::setBlinnPhongFromMetallicRoughness(pane);
    if (emissive) {
        wall.emissiveFactor = kWallEmission;
        pane.emissiveFactor = kPaneFactor;
        pane.emissiveStrength = kPaneStrength;
    }
    scene.materials = {wall, pane};
    // The wall fills the view at 4 m; the pane covers the middle at 3 m.
    const float half[2][2] = {{12.0f, 8.0f}, {0.8f, 0.5f}};
    const float z[2] = {-4.0f, -3.0f};
    for (int i = 0; i < 2; ++i) {
        scenes::Mesh mesh;
        const float hx = half[i][0], hy = half[i][1];
        mesh.positions = {{-hx, -hy, z[i]}, {hx, -hy, z[i]}, {hx, hy, z[i]}, {-hx, hy, z[i]}};
        mesh.normals.assign(4, glm::vec3(0, 0, 1));
        mesh.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
        mesh.indices = {0, 1, 2, 0, 2, 3};
        mesh.material = uint32_t(i);
        scene.meshes.push_back(mesh);
        scene.instances.push_back({uint32_t(i), glm::mat4(1.0f)});
    }
    scenes::Camera camera;
    camera.forwardWorld = {0, 0, -1};
    scene.cameras.push_back(camera);
    addLightRow(scene, lightCount, -2.0f);
    scenes::validate(scene);
    return scene;
}

// Every stage, the reference included: unlit, a pane pixel is exactly the closed form above and
// a wall pixel the wall's emission; lit, the emissive scene's image is the non-emissive one's
// plus the same closed form (emission changes no light count). A pane that emitted outside the
// composite (alpha x emission missing, or added after "over") is off by a factor 1/alpha = 2.7.
TEST_P(EmissionPerStage, BlendedPaneEmitsWithinTheComposite) {
    const std::string stageName = GetParam();
    const lighting::StageResult lit = shade(emissivePane(false, 3), stageName);
    const lighting::StageResult glowing = shade(emissivePane(true, 3), stageName);
    const lighting::StageResult dark = shade(emissivePane(true, 0), stageName);
    const glm::vec3 paneEmission = kPaneFactor * kPaneStrength;
    const glm::vec3 overWall = kPaneAlpha * paneEmission + (1.0f - kPaneAlpha) * kWallEmission;
    int panePixels = 0, failures = 0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 64; ++x) {
            const size_t pixel = size_t(y) * 64 + size_t(x);
            EXPECT_EQ(glowing.lightsEvaluated[pixel], lit.lightsEvaluated[pixel]);
            // The pane is the only thing that makes the unlit image differ from the wall.
            const bool pane =
                std::abs(dark.radiance[0][pixel] - kWallEmission[0]) > 1e-3f * kWallEmission[0];
            const glm::vec3 expected = pane ? overWall : kWallEmission;
            panePixels += pane ? 1 : 0;
            for (int c = 0; c < 3; ++c) {
                const float tolerance = 1e-5f * expected[c];
                if (!(std::abs(dark.radiance[c][pixel] - expected[c]) <= tolerance) &&
                    failures++ < 5)
                    ADD_FAILURE() << stageName << " unlit pixel (" << x << ", " << y << ") channel "
                                  << c << ": " << dark.radiance[c][pixel] << ", expected "
                                  << expected[c] << (pane ? " (pane over wall)" : " (wall)");
                const float sum = lit.radiance[c][pixel] + expected[c];
                if (!(std::abs(glowing.radiance[c][pixel] - sum) <= 1e-5f * sum) && failures++ < 5)
                    ADD_FAILURE() << stageName << " lit pixel (" << x << ", " << y << ") channel "
                                  << c << ": " << glowing.radiance[c][pixel] << ", expected " << sum
                                  << " (lights " << lit.radiance[c][pixel] << " + emission "
                                  << expected[c] << ")";
            }
        }
    EXPECT_GT(panePixels, 20) << stageName;
    EXPECT_LT(panePixels, 64 * 32 / 2) << stageName;
    EXPECT_EQ(failures, 0) << stageName;
}

// Blended surfaces never reach the G-buffer: a pane's emission alone makes no emission plane.
TEST(EmissionLayout, NoPlaneForABlendedMaterialsEmission) {
    scenes::Scene scene = emissivePane(true, 1);
    scene.materials[0].emissiveFactor = glm::vec3(0.0f);
    EXPECT_EQ(
        gbuffer::deriveLayout(scene, lighting::StageRequirements::wholeSurface().channels).emission,
        gbuffer::EmissionEncoding::None);
}

const std::vector<gbuffer::Channel> kWholeSurface =
    lighting::StageRequirements::wholeSurface().channels;

TEST(EmissionLayout, NoPlaneWhenNoMaterialEmits) {
    const gbuffer::GBufferLayout layout =
        gbuffer::deriveLayout(emissiveQuads(false, 1), kWholeSurface);
    EXPECT_EQ(layout.emission, gbuffer::EmissionEncoding::None);
    for (const gbuffer::PlaneDesc& plane : layout.planes())
        EXPECT_NE(plane.channel, "emission") << plane.name;
    EXPECT_TRUE(layout.provides(gbuffer::Channel::Emission));
    EXPECT_NE(layout.explain().find("no used material emits"), std::string::npos)
        << layout.explain();
}

TEST(EmissionLayout, TexturedEmissionIsAPlaneUntexturedTheMaterialIndex) {
    scenes::Scene scene = emissiveQuads(true, 1);
    gbuffer::GBufferLayout layout = gbuffer::deriveLayout(scene, kWholeSurface);
    EXPECT_EQ(layout.emission, gbuffer::EmissionEncoding::Float32);
    int planes = 0;
    for (const gbuffer::PlaneDesc& plane : layout.planes())
        planes += plane.channel == "emission" ? 1 : 0;
    EXPECT_EQ(planes, 3);
    EXPECT_NE(layout.explain().find("emissive texture"), std::string::npos) << layout.explain();

    scene.materials[1].emissiveTexture = -1;
    layout = gbuffer::deriveLayout(scene, kWholeSurface);
    EXPECT_EQ(layout.emission, gbuffer::EmissionEncoding::Material);
    EXPECT_TRUE(layout.hasMaterialIndex());
    EXPECT_EQ(layout.materials[0].emission, kLeftFactor * kLeftStrength);

    // A stage that does not read the channel (forward shading adds its own surfaces' emission)
    // gets no plane.
    layout = gbuffer::deriveLayout(scene, {gbuffer::Channel::Depth});
    EXPECT_EQ(layout.emission, gbuffer::EmissionEncoding::None);
    EXPECT_NE(layout.explain().find("does not read emission"), std::string::npos)
        << layout.explain();
}

// A texture with a zero factor emits nothing: no plane.
TEST(EmissionLayout, ATextureWithAZeroFactorEmitsNothing) {
    scenes::Scene scene = emissiveQuads(false, 1);
    scene.materials[1].emissiveTexture = 0;
    EXPECT_EQ(gbuffer::deriveLayout(scene, kWholeSurface).emission,
              gbuffer::EmissionEncoding::None);
}

} // namespace
