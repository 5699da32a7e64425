#include "experiments/studies/NormalSampling.h"

#include <cmath>

#include "gbuffer/codecs/NormalCodec.h"
#include "lighting/PreparedScene.h"
#include "scenes/SceneLoader.h"

namespace experiments::normal_study {

std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

glm::dvec3 uniformSphere(double u1, double u2) {
    const double z = 1.0 - 2.0 * u1;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * kPi * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

void basisAround(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

glm::dvec3 hemisphereAround(const glm::dvec3& axis, double u1, double u2, bool cosineWeighted) {
    const double cosTheta = cosineWeighted ? std::sqrt(1.0 - u1) : 1.0 - u1;
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const double phi = 2.0 * kPi * u2;
    glm::dvec3 t, b;
    basisAround(axis, t, b);
    return sinTheta * std::cos(phi) * t + sinTheta * std::sin(phi) * b + cosTheta * axis;
}

glm::dvec3 randomPixelRay(double u1, double u2, double verticalFovDegrees, double aspect) {
    const double tanHalf = std::tan(0.5 * verticalFovDegrees / kDegreesPerRadian);
    return {(2.0 * u1 - 1.0) * tanHalf * aspect, (2.0 * u2 - 1.0) * tanHalf, -1.0};
}

Dataset sphereDataset(std::uint64_t count, std::uint64_t seed) {
    Dataset data{"sphere", std::vector<glm::vec3>(count), {}};
    const CounterRng rng(seed, kSaltSphere);
    forEachChunk(count, [&](std::uint64_t, std::uint64_t begin, std::uint64_t end) {
        for (std::uint64_t i = begin; i < end; ++i)
            data.normals[i] = glm::vec3(uniformSphere(rng.uniform(2 * i), rng.uniform(2 * i + 1)));
    });
    return data;
}

Dataset visibleDataset(std::uint64_t count, std::uint64_t seed) {
    Dataset data{"visible-60", std::vector<glm::vec3>(count), std::vector<glm::vec3>(count)};
    const CounterRng rng(seed, kSaltVisible);
    forEachChunk(count, [&](std::uint64_t, std::uint64_t begin, std::uint64_t end) {
        for (std::uint64_t i = begin; i < end; ++i) {
            const glm::dvec3 ray = randomPixelRay(rng.uniform(4 * i), rng.uniform(4 * i + 1),
                                                  kVisibleFovDegrees, kVisibleAspect);
            data.rays[i] = glm::vec3(ray);
            data.normals[i] = glm::vec3(hemisphereAround(
                -glm::normalize(ray), rng.uniform(4 * i + 2), rng.uniform(4 * i + 3), true));
        }
    });
    return data;
}

Dataset hardDataset() {
    Dataset data{"hard", {}, {}};
    for (const HardNormalCase& c : hardNormalCases()) {
        data.normals.push_back(c.normalView);
        data.rays.push_back(c.viewRayView);
    }
    return data;
}

namespace {

// The covered pixels' normals and view rays of one render, and its figures.
Dataset renderedNormals(scenes::Scene scene, const std::string& name, const std::string& source,
                        int width, int height, NormalStudyScene& info) {
    lighting::PreparedScene prepared(std::move(scene), width, height);
    const gbuffer::GBuffer& gb = *prepared.gbuffer;
    const gbuffer::CameraView& view = prepared.view;
    Dataset data{name, {}, {}};
    std::uint64_t negative = 0, backFacing = 0;
    for (int y = 0; y < gb.height(); ++y)
        for (int x = 0; x < gb.width(); ++x) {
            if (!gb.covered(std::size_t(y) * gb.width() + x))
                continue;
            const glm::vec3 n = gb.decode(x, y).normalView;
            const glm::vec3 ray = gbuffer::viewRayOfNdc(view, view.ndcOfPixel(x, y));
            data.normals.push_back(n);
            data.rays.push_back(ray);
            negative += n.z < 0.0f;
            backFacing += glm::dot(n, ray) > 0.0f;
        }
    info.dataset = data.name;
    info.source = source;
    info.width = width;
    info.height = height;
    info.coveredPixels = data.normals.size();
    const double covered = std::max<double>(1.0, double(data.normals.size()));
    info.negativeZFraction = double(negative) / covered;
    info.backFacingFraction = double(backFacing) / covered;
    return data;
}

} // namespace

Dataset sceneDataset(const std::string& source, const std::string& label, int width, int height,
                     NormalStudyScene& info, std::vector<std::string>& warnings, Dataset& geometric,
                     NormalStudyScene& geometricInfo) {
    scenes::SceneRequest request; // no generated lights: only the geometry matters here
    scenes::Scene scene = scenes::loadScene(source, request);
    for (const std::string& warning : scene.warnings)
        warnings.push_back(label + ": " + warning);
    const bool normalMapped =
        std::any_of(scene.meshes.begin(), scene.meshes.end(), [&](const scenes::Mesh& mesh) {
            return mesh.material < scene.materials.size() &&
                   scene.materials[mesh.material].normalTexture >= 0;
        });
    scenes::Scene withoutMaps = scene;
    Dataset data = renderedNormals(std::move(scene), "scene:" + label, source, width, height, info);
    geometric = {};
    if (!normalMapped)
        return data;
    for (scenes::Material& material : withoutMaps.materials)
        material.normalTexture = -1;
    geometric = renderedNormals(std::move(withoutMaps), "scene:" + label + ":geometric", source,
                                width, height, geometricInfo);
    geometricInfo.geometric = true;
    // The same triangles through the same rasterizer cover the same pixels in the same order.
    std::uint64_t changed = 0;
    for (std::size_t i = 0; i < data.normals.size() && i < geometric.normals.size(); ++i)
        changed += data.normals[i] != geometric.normals[i];
    info.normalMappedFraction =
        double(changed) / std::max<double>(1.0, double(data.normals.size()));
    return data;
}

std::vector<std::filesystem::path> findModels(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> models;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
        const std::string ext = entry.path().extension().string();
        if (entry.is_regular_file() && (ext == ".gltf" || ext == ".glb"))
            models.push_back(entry.path());
    }
    std::sort(models.begin(), models.end());
    return models;
}

} // namespace experiments::normal_study
