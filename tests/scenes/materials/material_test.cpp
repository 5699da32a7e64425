// Material helpers (scenes/materials/Material.h): the KHR_texture_transform mapping against the
// extension's own example, the Blinn-Phong approximation of a metallic-roughness material and its
// inverse, and which materials read the second uv set.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/glm.hpp>

#include "scenes/materials/Material.h"

namespace {

using scenes::TextureMapping;

void expectNear(glm::vec2 actual, glm::vec2 expected) {
    EXPECT_NEAR(actual.x, expected.x, 1e-6f);
    EXPECT_NEAR(actual.y, expected.y, 1e-6f);
}

TEST(TextureMapping, TheExtensionsExampleMapsOntoTheLowerLeftQuadrant) {
    // KHR_texture_transform's example: offset [0, 1], rotation pi/2, scale [0.5, 0.5] "utilizes
    // only the lower left quadrant of the source image, rotated clockwise 90 degrees" (uv (0, 0)
    // is the image's top-left corner, so the lower-left quadrant is u in [0, .5], v in [.5, 1]).
    TextureMapping mapping;
    mapping.offset = {0.0f, 1.0f};
    mapping.rotationRadians = float(M_PI / 2);
    mapping.scale = {0.5f, 0.5f};
    expectNear(mapping.apply({0, 0}), {0.0f, 1.0f});
    expectNear(mapping.apply({1, 0}), {0.0f, 0.5f});
    expectNear(mapping.apply({0, 1}), {0.5f, 1.0f});
    expectNear(mapping.apply({1, 1}), {0.5f, 0.5f});
}

TEST(TextureMapping, IdentityLeavesUvsBitwiseAlone) {
    const TextureMapping identity;
    EXPECT_TRUE(identity.isIdentity());
    EXPECT_EQ(identity.apply({0.1f, 0.7f}), glm::vec2(0.1f, 0.7f));
    TextureMapping offset;
    offset.offset = {0.25f, -1.0f};
    EXPECT_EQ(offset.apply({0.5f, 0.5f}), glm::vec2(0.75f, -0.5f));
}

TEST(Material, BlinnPhongApproximationOfMetallicRoughness) {
    scenes::Material material;
    material.metallic = 0.5f;
    material.roughness = 0.5f;
    scenes::setBlinnPhongFromMetallicRoughness(material);
    EXPECT_FLOAT_EQ(material.specularIntensity, 0.52f); // 0.04 + 0.96 * 0.5
    EXPECT_FLOAT_EQ(material.specularPower, 30.0f);     // 2 / 0.5^4 - 2
    EXPECT_FLOAT_EQ(scenes::roughnessForSpecularPower(30.0f), 0.5f);
    material.roughness = 1.0f; // 2 / 1 - 2 = 0, clamped to the broadest lobe
    scenes::setBlinnPhongFromMetallicRoughness(material);
    EXPECT_EQ(material.specularPower, 1.0f);
    material.roughness = 0.0f; // roughness^4 floored at 1e-4: 2e4 - 2, clamped to 2048
    scenes::setBlinnPhongFromMetallicRoughness(material);
    EXPECT_EQ(material.specularPower, 2048.0f);
}

TEST(Material, SecondUvSetIsUsedOnlyByPresentTextures) {
    scenes::Material material;
    material.occlusionMapping.texCoord = 1;
    EXPECT_FALSE(material.usesSecondUvSet()); // no occlusion texture
    material.occlusionTexture = 3;
    EXPECT_TRUE(material.usesSecondUvSet());
    EXPECT_STREQ(scenes::materialModelName(scenes::MaterialModel::MetallicRoughness),
                 "metallic-roughness");
}

} // namespace
