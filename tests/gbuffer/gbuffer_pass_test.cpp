// The G-buffer pass against closed-form answers: a plane facing the camera and a tilted plane,
// with position reconstructed from depth and the exact (double) surface.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "gbuffer/GBufferPass.h"
#include "gbuffer/visibility/ExactSurface.h"
#include "gbuffer/visibility/SceneGeometry.h"

namespace {

// A square of side `size` in the plane z = 0 of object space, facing +Z, placed by
// `worldFromObject`.
scenes::Scene planeScene(float size, const glm::mat4& worldFromObject) {
    scenes::Scene scene;
    scene.name = "plane";
    scenes::Mesh mesh;
    const float h = size / 2;
    mesh.positions = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
    mesh.normals.assign(4, glm::vec3(0, 0, 1));
    mesh.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    scene.meshes.push_back(mesh);
    scenes::Material material;
    material.baseColorFactor = {0.25f, 0.5f, 0.75f, 1.0f};
    material.specularIntensity = 0.3f;
    material.specularPower = 40.0f;
    scene.materials.push_back(material);
    scene.instances.push_back({0, worldFromObject});
    scenes::Camera camera;
    camera.positionWorld = {0, 0, 0};
    camera.forwardWorld = {0, 0, -1};
    camera.verticalFovRadians = 1.0f;
    camera.nearMetres = 0.1f;
    camera.farMetres = 100.0f;
    scene.cameras.push_back(camera);
    scenes::validate(scene);
    return scene;
}

struct Rendered {
    std::unique_ptr<gbuffer::GBuffer> gbuffer;
    gbuffer::ExactSurface exact;
};

Rendered render(const scenes::Scene& scene, int width, int height) {
    const gbuffer::SceneGeometry geometry = gbuffer::SceneGeometry::build(scene);
    const gbuffer::CameraView view =
        gbuffer::CameraView::fromCamera(scene.cameras[0], width, height);
    Rendered r;
    r.gbuffer = std::make_unique<gbuffer::GBuffer>(gbuffer::GBufferLayout::reference(), view);
    raster::Rasterizer rasterizer(width, height);
    gbuffer::GBufferPass pass(scene, geometry);
    pass.render(rasterizer, *r.gbuffer, &r.exact);
    return r;
}

TEST(GBufferPass, PlaneFacingTheCamera) {
    const scenes::Scene scene =
        planeScene(100.0f, glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -5)));
    const Rendered r = render(scene, 64, 48);
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) {
            const size_t pixel = size_t(y) * 64 + x;
            ASSERT_TRUE(r.gbuffer->covered(pixel));
            const gbuffer::Surface s = r.gbuffer->decode(x, y);
            EXPECT_NEAR(s.positionView.z, -5.0f, 5e-5f);
            EXPECT_EQ(s.normalView, glm::vec3(0, 0, 1));
            EXPECT_NEAR(s.albedo.g, 0.5f, 0.0f);
            EXPECT_EQ(s.specularPower, 40.0f);
            EXPECT_NEAR(r.exact.positionView[pixel].z, -5.0, 1e-12);
            EXPECT_NEAR(glm::length(glm::dvec3(s.positionView) - r.exact.positionView[pixel]), 0.0,
                        1e-4);
        }
}

TEST(GBufferPass, TiltedPlaneReconstructsExactPositions) {
    // A plane tilted 60 degrees about X, 8 m away: depth varies across the image.
    glm::mat4 worldFromObject = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -8));
    worldFromObject = glm::rotate(worldFromObject, glm::radians(-60.0f), glm::vec3(1, 0, 0));
    const scenes::Scene scene = planeScene(200.0f, worldFromObject);
    const Rendered r = render(scene, 96, 64);
    const glm::dvec3 planeNormal =
        glm::normalize(glm::dvec3(worldFromObject * glm::vec4(0, 0, 1, 0)));
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 96; ++x) {
            const size_t pixel = size_t(y) * 96 + x;
            if (!r.gbuffer->covered(pixel))
                continue;
            // The exact position lies on the plane to double precision.
            const glm::dvec3 p = r.exact.positionView[pixel];
            EXPECT_NEAR(glm::dot(p - glm::dvec3(0, 0, -8), planeNormal), 0.0,
                        1e-9 * glm::length(p));
            EXPECT_NEAR(glm::distance(r.exact.normalView[pixel], planeNormal), 0.0, 1e-12);
            // The float reconstruction is close in relative terms.
            const glm::vec3 q = r.gbuffer->decode(x, y).positionView;
            EXPECT_NEAR(glm::distance(glm::dvec3(q), p), 0.0, 2e-5 * glm::length(p))
                << x << "," << y;
        }
}

TEST(SceneGeometry, MirroredInstanceKeepsFrontFaces) {
    // A mirroring transform (negative scale) must not turn the plane's front face away.
    const glm::mat4 mirrored =
        glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -5)), glm::vec3(-1, 1, 1));
    const Rendered r = render(planeScene(100.0f, mirrored), 32, 32);
    EXPECT_TRUE(r.gbuffer->covered(16 * 32 + 16));
}

} // namespace
