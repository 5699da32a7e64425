// hardNormalCases() (NormalStudy.h): the hard inputs of the normal-encoding study, one group per
// function, appended in a fixed order (the order is part of the study's output).
#include "experiments/studies/NormalSampling.h"

#include <cmath>
#include <limits>

#include "gbuffer/codecs/NormalCodec.h"

namespace experiments {

namespace {

using normal_study::basisAround;
using normal_study::CounterRng;
using normal_study::kPi;
using normal_study::kSaltHard;
using normal_study::uniformSphere;

const glm::vec3 kCentral = gbuffer::kCentralViewRay;

struct Cases {
    std::vector<HardNormalCase> list;
    void add(glm::vec3 n, const char* group, glm::vec3 ray = kCentral) {
        list.push_back({n, ray, group});
    }
};

glm::vec3 unitFloat(double x, double y, double z) {
    const double l = std::sqrt(x * x + y * y + z * z);
    return glm::vec3(x / l, y / l, z / l);
}

void addAxesAndPoles(Cases& cases) {
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f}) {
            glm::vec3 n(0.0f);
            n[axis] = sign;
            cases.add(n, "axes");
        }
    // -Z: the spheremap and stereographic singularity (and the worst back face of xy-z); +-Z: the
    // spherical poles. Exactly there, signed zeros, and 1e-8..1e-2 rad away at 8 azimuths.
    for (float sign : {1.0f, -1.0f}) {
        const char* group = sign < 0 ? "minus-z" : "plus-z-pole";
        cases.add({-0.0f, -0.0f, sign}, group);
        cases.add({0.0f, -0.0f, sign}, group);
        for (double eps : {1e-8, 1e-6, 1e-4, 1e-3, 1e-2})
            for (int k = 0; k < 8; ++k) {
                const double phi = k * kPi / 4.0;
                cases.add(unitFloat(std::sin(eps) * std::cos(phi), std::sin(eps) * std::sin(phi),
                                    sign * std::cos(eps)),
                          group);
            }
    }
}

void addFoldsAndBackFaces(Cases& cases) {
    // Octahedral folds and the square's edges: |x| + |y| = 1 with z = 0 and z = +-1e-7.
    for (double t : {0.0, 1e-7, 0.25, 0.5, 0.75, 1.0 - 1e-7, 1.0})
        for (double sx : {1.0, -1.0})
            for (double sy : {1.0, -1.0})
                for (double z : {0.0, 1e-7, -1e-7})
                    cases.add(unitFloat(sx * t, sy * (1.0 - t), z), "octahedral-edge");
    // One zero component (the fold lines and the axes' great circles), every 15 degrees.
    for (int k = 0; k < 24; ++k) {
        const double a = k * kPi / 12.0, c = std::cos(a), s = std::sin(a);
        cases.add(unitFloat(c, 0.0, s), "one-zero-component");
        cases.add(unitFloat(0.0, c, s), "one-zero-component");
        cases.add(unitFloat(c, s, 0.0), "one-zero-component");
    }
    // Back-facing view-space normals, z slightly negative (visible off-centre under perspective).
    for (double z : {-1e-3, -3e-3, -1e-2, -3e-2, -0.1})
        for (int k = 0; k < 8; ++k) {
            const double phi = (k + 0.5) * kPi / 4.0, r = std::sqrt(1.0 - z * z);
            cases.add(unitFloat(r * std::cos(phi), r * std::sin(phi), z), "back-facing");
        }
}

void addUnusualLengths(Cases& cases) {
    const float sub = std::numeric_limits<float>::denorm_min();
    const float big = std::numeric_limits<float>::max();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    // Not-quite-unit lengths 1 +- 1e-3.
    const CounterRng rng(1, kSaltHard);
    for (int k = 0; k < 16; ++k) {
        const glm::dvec3 d = uniformSphere(rng.uniform(2 * k), rng.uniform(2 * k + 1));
        cases.add(glm::vec3(d * (1.0 + 1e-3)), "near-unit");
        cases.add(glm::vec3(d * (1.0 - 1e-3)), "near-unit");
    }
    // Subnormal, tiny and huge components (directions still defined).
    for (glm::vec3 n : {glm::vec3(sub, 0, 0), glm::vec3(0, sub, 0), glm::vec3(0, 0, sub),
                        glm::vec3(0, 0, -sub), glm::vec3(sub, sub, sub), glm::vec3(-sub, sub, -sub),
                        glm::vec3(1e-40f, -1e-40f, 1e-40f), glm::vec3(1e-30f, 2e-30f, -3e-30f)})
        cases.add(n, "subnormal");
    for (glm::vec3 n :
         {glm::vec3(big, big, big), glm::vec3(-big, 0, big), glm::vec3(1e38f, -1e38f, -1e38f)})
        cases.add(n, "huge");
    // No direction at all.
    for (glm::vec3 n : {glm::vec3(0, 0, 0), glm::vec3(-0.0f, -0.0f, -0.0f), glm::vec3(0, -0.0f, 0)})
        cases.add(n, "zero");
    for (glm::vec3 n : {glm::vec3(nan, 0, 1), glm::vec3(0, nan, 0), glm::vec3(nan, nan, nan),
                        glm::vec3(inf, 0, 0), glm::vec3(-inf, inf, 0), glm::vec3(0, 0, -inf),
                        glm::vec3(inf, inf, inf), glm::vec3(nan, inf, -inf)})
        cases.add(n, "non-finite");
}

// pixel-view: off-axis rays (corners and edges of a 90 degree 16:9 camera, a nearly horizontal
// and a nearly vertical ray) with a normal facing the ray, grazing it and slightly behind it;
// degenerate rays (zero, NaN/Inf, along view Y) that must fall back to the central ray.
void addViewRays(Cases& cases) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const double t = std::tan(kPi / 4.0), a = 16.0 / 9.0;
    for (glm::dvec3 ray :
         {glm::dvec3(t * a, t, -1), glm::dvec3(-t * a, t, -1), glm::dvec3(0, -t, -1),
          glm::dvec3(t * a, 0, -1), glm::dvec3(1, 0, -1e-3), glm::dvec3(0, 1, -1e-3)}) {
        const glm::dvec3 towards = -glm::normalize(ray);
        glm::dvec3 u, v;
        basisAround(towards, u, v);
        for (double z : {1.0, 0.5, 1e-3, 0.0, -1e-3, -0.1}) {
            const double r = std::sqrt(1.0 - z * z);
            cases.add(glm::vec3(z * towards + r * u), "off-axis-ray", glm::vec3(ray));
            cases.add(glm::vec3(z * towards - r * v), "off-axis-ray", glm::vec3(ray));
        }
    }
    for (glm::vec3 ray : {glm::vec3(0, 0, 0), glm::vec3(nan, 0, -1), glm::vec3(0, inf, -1),
                          glm::vec3(0, 1, 0), glm::vec3(0, -1e-30f, 0)})
        for (glm::vec3 n :
             {glm::vec3(0, 0, 1), unitFloat(0.6, 0.0, 0.8), unitFloat(0.3, -0.4, -0.1)})
            cases.add(n, "degenerate-ray", ray);
}

} // namespace

std::vector<HardNormalCase> hardNormalCases() {
    Cases cases;
    addAxesAndPoles(cases);
    addFoldsAndBackFaces(cases);
    addUnusualLengths(cases);
    addViewRays(cases);
    return std::move(cases.list);
}

} // namespace experiments
