// Deterministic light placement. The same (count, seed, region) gives the same lights on every
// machine: we use our own integer-to-float mapping over std::mt19937_64, never the
// implementation-defined std::uniform_*_distribution.
#pragma once

#include <cstdint>
#include <random>

#include "scenes/Scene.h"
#include "scenes/SceneRequest.h"

namespace scenes {

// A reproducible uniform random source.
class DeterministicRandom {
public:
    explicit DeterministicRandom(uint64_t seed) : mEngine(seed) {}
    double uniform01() { return double(mEngine() >> 11) * 0x1.0p-53; } // [0,1)
    float uniform(float lo, float hi) { return lo + float(uniform01()) * (hi - lo); }

private:
    std::mt19937_64 mEngine;
};

struct PointLightScatter {
    Aabb region; // light centres are uniform inside this box
    float minRangeMetres = 1.0f;
    float maxRangeMetres = 4.0f;
    float minIntensity = 0.5f;
    float maxIntensity = 2.0f;
};

// The light count at which the constant-overlap mode keeps a scatter's own radii and intensities
// (the atrium's ranges give about 25 lights reaching a point of its courtyard at this count).
inline constexpr int kOverlapReferenceCount = 1000;

// The scatter for `count` lights under `density`: unchanged for FixedRadius; for ConstantOverlap
// radii times (kOverlapReferenceCount / count)^(1/3) (the expected lights whose sphere holds a
// point: density x mean sphere volume, constant) and intensities times the ratio of the mean
// windowed falloff over the old and the new ball (Brdf's (1 - (d/r)^4)^2 / (d^2 + 1)), so that
// the radiance the lights add at a point keeps its expectation. count <= 0 changes nothing.
PointLightScatter scatterForDensity(PointLightScatter scatter, LightDensity density, int count);

// "fixed" / "constant-overlap" and back; parseLightDensity throws SceneError for other names.
LightDensity parseLightDensity(const std::string& name);
const char* lightDensityName(LightDensity density);

// The mean of the windowed inverse-square falloff over a ball of radius r (metres) around the
// light, by the midpoint rule on 1024 shells.
double meanFalloffOverBall(double radiusMetres);

// Appends `count` point lights to scene.lights, with random saturated colours.
void scatterPointLights(Scene& scene, const PointLightScatter& scatter, int count, uint64_t seed);

// Region and radii suited to an arbitrary scene (used for glTF and JSON scenes without their own
// generator): the scene's bounds, radii a fraction of its diagonal.
PointLightScatter defaultScatterFor(const Scene& scene);

} // namespace scenes
