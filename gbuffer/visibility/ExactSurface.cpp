#include "gbuffer/visibility/ExactSurface.h"

#include <tbb/parallel_for.h>

#include "gbuffer/visibility/NormalMapping.h"

namespace gbuffer {

void ExactSurface::resize(int w, int h) {
    width = w;
    height = h;
    const size_t n = size_t(w) * h;
    triangle.assign(n, kNoTriangle);
    backFacing.assign(n, 0);
    albedo.assign(n, glm::vec3(0.0f));
    specular.assign(n, glm::vec2(0.0f));
    roughnessMetallic.assign(n, glm::vec2(1.0f, 0.0f));
    model.assign(n, scenes::MaterialModel::BlinnPhong);
    occlusion.assign(n, 1.0f);
    emissive.assign(n, glm::vec3(0.0f));
    positionView.assign(n, glm::dvec3(0.0));
    normalView.assign(n, glm::dvec3(0.0));
}

void ExactSurface::computeGeometry(const scenes::Scene& scene, const SceneGeometry& geometry,
                                   const CameraView& view) {
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            const uint32_t t = triangle[pixel];
            if (t == kNoTriangle)
                continue;
            hit(scene, geometry, view, t, backFacing[pixel] != 0, x, y, positionView[pixel],
                normalView[pixel]);
        }
    });
}

bool ExactSurface::hit(const scenes::Scene& scene, const SceneGeometry& geometry,
                       const CameraView& view, uint32_t t, bool backFace, int x, int y,
                       glm::dvec3& positionView, glm::dvec3& normalView) {
    const glm::dmat3 normalViewFromWorld(view.viewFromWorldExact);
    const int width = view.width, height = view.height;
    // View ray through the pixel centre: the point on the near plane, from the origin.
    const double ndcX = (x + 0.5) / width * 2.0 - 1.0;
    const double ndcY = 1.0 - (y + 0.5) / height * 2.0;
    const glm::dvec4 onNear = view.viewFromClipExact * glm::dvec4(ndcX, ndcY, 0.0, 1.0);
    const glm::dvec3 direction = glm::dvec3(onNear) / onNear.w;
    glm::dvec3 p[3];
    for (int i = 0; i < 3; ++i)
        p[i] =
            glm::dvec3(view.viewFromWorldExact *
                       glm::dvec4(geometry.positionWorldExact[geometry.indices[3 * t + i]], 1.0));
    // Moeller-Trumbore without the inside test: the rasterizer already decided coverage;
    // barycentrics slightly outside [0,1] at edges are the honest extrapolation.
    const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const glm::dvec3 h = glm::cross(direction, e2);
    const double det = glm::dot(e1, h);
    if (det == 0.0) // ray parallel to the plane (edge-on): nothing to intersect
        return false;
    const double inv = 1.0 / det;
    const glm::dvec3 s = -p[0];
    const double u = glm::dot(s, h) * inv;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(direction, q) * inv;
    const double distance = glm::dot(e2, q) * inv;
    positionView = direction * distance;
    glm::dvec3 n(0.0);
    const double w[3] = {1.0 - u - v, u, v};
    for (int i = 0; i < 3; ++i)
        n += w[i] * glm::dvec3(geometry.normalWorld[geometry.indices[3 * t + i]]);
    n = glm::normalize(normalViewFromWorld * n);
    normalView = backFace ? -n : n;
    const scenes::Material& material = scene.materials[geometry.triangleMaterial[t]];
    if (material.normalTexture < 0 || geometry.tangentWorld.empty())
        return true;
    glm::dvec3 tangent(0.0), uv0(0.0), uv1(0.0);
    double sign = 0.0;
    for (int i = 0; i < 3; ++i) {
        const uint32_t vertex = geometry.indices[3 * t + i];
        tangent += w[i] * glm::dvec3(glm::vec3(geometry.tangentWorld[vertex]));
        sign += w[i] * double(geometry.tangentWorld[vertex].w);
        uv0 += w[i] * glm::dvec3(glm::dvec2(geometry.uv[vertex]), 0.0);
        if (!geometry.uv1.empty())
            uv1 += w[i] * glm::dvec3(glm::dvec2(geometry.uv1[vertex]), 0.0);
    }
    const scenes::TextureMapping& mapping = material.normalMapping;
    const glm::vec2 uv =
        mapping.apply(glm::vec2(mapping.texCoord == 1 && !geometry.uv1.empty() ? uv1 : uv0));
    const glm::vec4 texel = scene.textures[size_t(material.normalTexture)].sample(uv);
    normalView =
        normalMapped(normalView, backFace, normalViewFromWorld * tangent, sign < 0.0 ? -1.0 : 1.0,
                     glm::dvec3(glm::vec3(texel)), double(material.normalScale));
    return true;
}

} // namespace gbuffer
