// DsfFilter: inferred lighting's discontinuity-sensitive filter (Kircher & Lawrance 2009) over the
// 4 bilinear taps of a light buffer's sample lattice, the one implementation `inferred`'s material
// pass and its stipple composite (InferredStipple.h) both run. Two bilinear filters at once:
// `same` keeps the taps that pass the depth, normal AND object-ID tests, `surface` the taps that
// pass depth and normal only (with ids=0 they coincide); the nearest covered tap (largest weight,
// the first among equals) is the last resort. The caller decides the tests (its thresholds, its
// notion of an ID) and feeds the covered taps in tap order; the sums are taken in that order, so
// the result is bitwise what the two stages computed inline before.
#pragma once

#include <glm/glm.hpp>

#include "lighting/brdf/SplitLighting.h"

namespace lighting {

class DsfFilter {
public:
    enum class Source {
        Same,    // the ID-tested filter
        Surface, // no tap passed the ID test: the depth and normal filter (a fallback)
        Nearest, // no tap passed depth and normal: the nearest covered tap (a fallback)
        None,    // no covered tap: no light
    };

    // A covered tap of bilinear weight `weight` whose light is `light` (which must outlive
    // resolve()); `passesSurface`: depth and normal tests passed, `passesId`: the ID test too.
    void add(float weight, const SplitLighting& light, bool passesSurface, bool passesId) {
        if (weight > mNearestWeight) {
            mNearestWeight = weight;
            mNearest = &light;
        }
        if (!passesSurface)
            return;
        addWeighted(mSurface, mSurfaceWeight, weight, light);
        if (passesId)
            addWeighted(mSame, mSameWeight, weight, light);
    }

    // The filtered light into `light` (zero for Source::None) and where it came from.
    Source resolve(SplitLighting& light) const {
        if (mSameWeight > 0.0f) {
            light = normalised(mSame, mSameWeight);
            return Source::Same;
        }
        if (mSurfaceWeight > 0.0f) {
            light = normalised(mSurface, mSurfaceWeight);
            return Source::Surface;
        }
        if (mNearest != nullptr) {
            light = *mNearest;
            return Source::Nearest;
        }
        light = SplitLighting{};
        return Source::None;
    }

private:
    static void addWeighted(SplitLighting& sum, float& sumWeight, float weight,
                            const SplitLighting& light) {
        sum.diffuse += weight * light.diffuse;
        sum.specular += weight * light.specular;
        sum.specularEdge += weight * light.specularEdge;
        sumWeight += weight;
    }
    static SplitLighting normalised(const SplitLighting& sum, float weight) {
        return {sum.diffuse / weight, sum.specular / weight, sum.specularEdge / weight};
    }

    SplitLighting mSame;
    SplitLighting mSurface;
    float mSameWeight = 0.0f;
    float mSurfaceWeight = 0.0f;
    float mNearestWeight = -1.0f;
    const SplitLighting* mNearest = nullptr;
};

} // namespace lighting
