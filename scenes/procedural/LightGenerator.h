// Deterministic light placement. The same (count, seed, region) gives the same lights on every
// machine: we use our own integer-to-float mapping over std::mt19937_64, never the
// implementation-defined std::uniform_*_distribution.
#pragma once

#include <cstdint>
#include <random>

#include "scenes/Scene.h"

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

// Appends `count` point lights to scene.lights, with random saturated colours.
void scatterPointLights(Scene& scene, const PointLightScatter& scatter, int count, uint64_t seed);

// Region and radii suited to an arbitrary scene (used for glTF and JSON scenes without their own
// generator): the scene's bounds, radii a fraction of its diagonal.
PointLightScatter defaultScatterFor(const Scene& scene);

} // namespace scenes
