// LightGenerator: uniform scattering of point lights, and the default scatter for scenes that do
// not bring their own (glTF models, JSON scenes without a generator).
//
// Reproducibility: every random number comes from DeterministicRandom, drawn in a fixed order
// per light (position x, y, z, range, intensity, hue, saturation), so a light's values depend
// only on the seed and its index; the first n lights of a larger count are the n lights of the
// smaller count.
#include "scenes/procedural/LightGenerator.h"

#include <cmath>
#include <string>

#include "scenes/input/Limits.h"

namespace scenes {

namespace {

// Linear RGB of a colour given by hue in [0,1), saturation in [0,1], value 1: the standard HSV
// hexcone, so one channel is always 1 and the smallest is 1 - saturation.
glm::vec3 saturatedColour(float hue, float saturation) {
    const float sector = hue * 6.0f;
    const int index = int(sector) % 6;
    const float f = sector - std::floor(sector);
    const float p = 1.0f - saturation;
    const float q = 1.0f - saturation * f;
    const float t = 1.0f - saturation * (1.0f - f);
    switch (index) {
    case 0:
        return {1.0f, t, p};
    case 1:
        return {q, 1.0f, p};
    case 2:
        return {p, 1.0f, t};
    case 3:
        return {p, q, 1.0f};
    case 4:
        return {t, p, 1.0f};
    default:
        return {1.0f, p, q};
    }
}

// Geometry only: Scene::boundsWorld() also holds the cameras, and a default camera framing a
// model from afar would stretch the region into empty space.
Aabb geometryBoundsWorld(const Scene& scene) {
    Aabb bounds;
    for (const Instance& instance : scene.instances)
        for (const glm::vec3& p : scene.meshes[instance.mesh].positions)
            bounds.extend(glm::vec3(instance.worldFromObject * glm::vec4(p, 1.0f)));
    return bounds;
}

} // namespace

void scatterPointLights(Scene& scene, const PointLightScatter& scatter, int count, uint64_t seed) {
    auto fail = [&](const std::string& what) {
        throw SceneError(scene.name + ": cannot scatter point lights: " + what);
    };
    if (count < 0)
        fail("light count must be >= 0, got " + std::to_string(count));
    if (uint64_t(count) + scene.lights.size() > uint64_t(limits::kMaxLights))
        fail(std::to_string(count) + " lights and the scene's " +
             std::to_string(scene.lights.size()) + " are over the limit of " +
             std::to_string(limits::kMaxLights));
    if (scatter.region.empty())
        fail("the region is empty");
    if (!(scatter.minRangeMetres >= 0.0f) || !(scatter.maxRangeMetres >= scatter.minRangeMetres))
        fail("need 0 <= minRangeMetres <= maxRangeMetres");
    if (!(scatter.minIntensity >= 0.0f) || !(scatter.maxIntensity >= scatter.minIntensity))
        fail("need 0 <= minIntensity <= maxIntensity");

    DeterministicRandom random(seed);
    scene.lights.reserve(scene.lights.size() + size_t(count));
    for (int i = 0; i < count; ++i) {
        Light light;
        light.type = LightType::Point;
        for (int axis = 0; axis < 3; ++axis)
            light.positionWorld[axis] =
                random.uniform(scatter.region.min[axis], scatter.region.max[axis]);
        light.rangeMetres = random.uniform(scatter.minRangeMetres, scatter.maxRangeMetres);
        light.intensity = random.uniform(scatter.minIntensity, scatter.maxIntensity);
        const float hue = random.uniform(0.0f, 1.0f);
        const float saturation = random.uniform(0.5f, 1.0f);
        light.color = saturatedColour(hue, saturation);
        scene.lights.push_back(light);
    }
    scene.generatedLightCount += count;
}

double meanFalloffOverBall(double radiusMetres) {
    if (!(radiusMetres > 0.0))
        return 1.0;
    constexpr int kShells = 1024;
    double weighted = 0.0, volume = 0.0;
    for (int i = 0; i < kShells; ++i) {
        const double d = (i + 0.5) / kShells * radiusMetres;
        const double window = std::max(0.0, 1.0 - std::pow(d / radiusMetres, 4.0));
        const double shell = d * d; // 4 pi d^2 dd, constant factors cancel
        weighted += shell * window * window / (d * d + 1.0);
        volume += shell;
    }
    return weighted / volume;
}

PointLightScatter scatterForDensity(PointLightScatter scatter, LightDensity density, int count) {
    if (density == LightDensity::FixedRadius || count <= 0)
        return scatter;
    const double scale = std::cbrt(double(kOverlapReferenceCount) / double(count));
    const double typical = 0.5 * (scatter.minRangeMetres + scatter.maxRangeMetres);
    const double exposure = meanFalloffOverBall(typical) / meanFalloffOverBall(typical * scale);
    scatter.minRangeMetres = float(scatter.minRangeMetres * scale);
    scatter.maxRangeMetres = float(scatter.maxRangeMetres * scale);
    scatter.minIntensity = float(scatter.minIntensity * exposure);
    scatter.maxIntensity = float(scatter.maxIntensity * exposure);
    return scatter;
}

LightDensity parseLightDensity(const std::string& name) {
    if (name == "fixed")
        return LightDensity::FixedRadius;
    if (name == "constant-overlap")
        return LightDensity::ConstantOverlap;
    throw SceneError("light density '" + name + "' is not fixed or constant-overlap");
}

const char* lightDensityName(LightDensity density) {
    return density == LightDensity::FixedRadius ? "fixed" : "constant-overlap";
}

PointLightScatter defaultScatterFor(const Scene& scene) {
    const Aabb bounds = geometryBoundsWorld(scene);
    if (bounds.empty())
        throw SceneError(scene.name + ": cannot place lights: the scene has no geometry");
    const float diagonal = glm::length(bounds.size());
    if (!(diagonal > 0.0f) || !std::isfinite(diagonal))
        throw SceneError(scene.name + ": cannot place lights: the scene's bounds are degenerate");

    PointLightScatter scatter;
    // Shrunk by 5% on each side, so that lights sit among the geometry rather than on its hull;
    // but never thinner than 10% of the diagonal, so that a flat model (a floor, a wall) gets
    // lights off its plane, which can light it, instead of in it, which cannot.
    const glm::vec3 halfSize = glm::max(0.45f * bounds.size(), glm::vec3(0.05f * diagonal));
    scatter.region.min = bounds.centre() - halfSize;
    scatter.region.max = bounds.centre() + halfSize;
    // 2%-8% of the diagonal: in a roughly cubic model 1000 lights then overlap about five at a
    // point, so culling has work to do and each light still covers some surface.
    scatter.minRangeMetres = 0.02f * diagonal;
    scatter.maxRangeMetres = 0.08f * diagonal;
    return scatter;
}

} // namespace scenes
