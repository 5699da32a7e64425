// KernelLights: a frame's view-space lights as the shading kernel reads them, built once per frame
// from the float LightInView list (lighting/brdf/Brdf.h). Each light is one 64-byte record (one
// cache line) whose fields the vector kernel broadcasts to every lane; the parts of the formula
// that depend only on the light (range squared, spot cone width) are computed here once instead of
// once per pixel, with the very same float operations evaluateLight performs, so the values are
// bitwise the ones it would compute. The source list is kept for the scalar path, which calls
// evaluateLight itself. Shadows (lighting/shadows/ShadowLookup.h), when given: each record names
// its light's shadow, and the kernel multiplies the light's radiance at a lane by the lookup's
// visibility there. Immutable after construction: safe to share between threads.
#pragma once

#include <cstdint>
#include <vector>

#include "lighting/brdf/Brdf.h"
#include "lighting/shadows/ShadowLookup.h"

namespace lighting::kernel {

// The light types as the kernel switches on them (values of scenes::LightType, stored as an int).
struct alignas(64) KernelLight {
    float positionView[3];
    float rangeSquared; // rangeMetres * rangeMetres
    float directionView[3];
    float spotOuterCos;
    float radiance[3];
    float spotWidth; // spotInnerCos - spotOuterCos; the smoothstep is skipped when not > 0
    uint32_t type;   // scenes::LightType
    uint32_t shadow; // shadows::ShadowLookup::shadowOf, or shadows::kNoShadow
    uint32_t padding[2];
};
static_assert(sizeof(KernelLight) == 64, "one light per cache line");

class KernelLights {
public:
    KernelLights() = default;
    // shadows: null (no light casts a shadow), or the frame's shadows, which must outlive this.
    explicit KernelLights(std::vector<LightInView<float>> lights,
                          const shadows::ShadowLookup* shadows = nullptr);

    size_t size() const { return mSource.size(); }
    const KernelLight* records() const { return mRecords.data(); }
    const std::vector<LightInView<float>>& source() const { return mSource; }
    const shadows::ShadowLookup* shadows() const { return mShadows; }
    // The shadow of light `index` (records()[index].shadow), for the scalar path.
    uint32_t shadowOf(size_t index) const { return mRecords[index].shadow; }

private:
    std::vector<LightInView<float>> mSource;
    std::vector<KernelLight> mRecords; // alignas(64) element: the allocator aligns (C++17)
    const shadows::ShadowLookup* mShadows = nullptr;
};

} // namespace lighting::kernel
