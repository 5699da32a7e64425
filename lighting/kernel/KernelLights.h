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
#include "lighting/shadows/ShadowMapsView.h"

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
    static inline const std::vector<LightInView<float>> kNoLights;

public:
    KernelLights() = default;
    // lights: the frame's list, which must outlive this (it is read, not copied: 10^6 lights are
    // 80 MB, and a fresh copy every frame costs its page faults); shadows: null (no light casts a
    // shadow), or the frame's shadows, which must outlive this too.
    explicit KernelLights(const std::vector<LightInView<float>>& lights,
                          const shadows::ShadowLookup* shadows = nullptr);
    KernelLights(std::vector<LightInView<float>>&&,
                 const shadows::ShadowLookup* = nullptr) = delete;
    // Large record arrays go back to a small pool for the next frame's KernelLights (below).
    ~KernelLights();
    KernelLights(const KernelLights&) = default;
    KernelLights(KernelLights&&) noexcept = default;
    KernelLights& operator=(const KernelLights&) = default;
    KernelLights& operator=(KernelLights&&) noexcept = default;

    size_t size() const { return mSource->size(); }
    const KernelLight* records() const { return mRecords.data(); }
    const std::vector<LightInView<float>>& source() const { return *mSource; }
    const shadows::ShadowLookup* shadows() const { return mShadows; }
    // shadows()->view(), asked once here: the vector kernel's plain-data lookup, or null (the
    // kernel then calls shadows()->visibility() lane by lane).
    const shadows::ShadowMapsView* shadowView() const { return mShadowView; }
    // The shadow of light `index` (records()[index].shadow), for the scalar path.
    uint32_t shadowOf(size_t index) const { return mRecords[index].shadow; }

private:
    const std::vector<LightInView<float>>* mSource = &kNoLights;
    // alignas(64) element: the allocator aligns (C++17). Arrays of kPooledRecords records or more
    // are taken from and returned to a pool of at most kPoolSize arrays (KernelLights.cpp): a
    // fresh 64 MB array for 10^6 lights every frame cost 16,000 page faults, ~170 ms on this
    // virtual machine, more than the shading. Every record is rewritten on construction, so the
    // reuse changes no value.
    std::vector<KernelLight> mRecords;
    const shadows::ShadowLookup* mShadows = nullptr;
    const shadows::ShadowMapsView* mShadowView = nullptr;
};

} // namespace lighting::kernel
