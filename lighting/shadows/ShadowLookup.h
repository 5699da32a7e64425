// ShadowLookup: what the shading kernel asks of a frame's shadows, and nothing else: which shadow
// (if any) a light casts, and the fraction of that light reaching a surface point. The kernel
// (lighting/kernel) multiplies a light's radiance at a lane by this fraction, on the scalar and
// the vector path alike, so a stage shades shadows exactly as it shades light: every stage whose
// shading goes through the kernel applies shadows the same way, with no second copy of the loop.
// The shadow maps (ShadowMaps.h) implement it, and hand the kernel their plain-data view too
// (view(), ShadowMapsView.h), from which its vector path computes visibility() for a vector of
// lanes at once, bitwise; tests implement it with analytic occluders (no view: the kernel then
// calls visibility() lane by lane).
// ExactShadowLookup is the reference's counterpart, in double: ray-traced visibility (RayShadows.h)
// for the same shadow-casting lights, the ground truth the maps are measured against.
//
// Conventions: camera view space (the kernel's), float. visibility() must be a pure function of
// its arguments (same answer on every call and thread: the image must not depend on the thread
// count or the instruction set), finite, in [0, 1], and thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace lighting::shadows {

inline constexpr uint32_t kNoShadow = ~0u;

struct ShadowMapsView; // ShadowMapsView.h

class ShadowLookup {
public:
    virtual ~ShadowLookup() = default;
    // The shadow of light `lightIndex` (the scene's light order, which LightList keeps), or
    // kNoShadow when that light casts none (it then lights through walls, as without shadows).
    virtual uint32_t shadowOf(size_t lightIndex) const = 0;
    // Fraction of light reaching the surface point (view space) with unit normal normalView, for
    // a shadow returned by shadowOf: 0 = fully shadowed, 1 = fully lit.
    virtual float visibility(uint32_t shadow, const glm::vec3& positionView,
                             const glm::vec3& normalView) const = 0;
    // The lookup as plain data (ShadowMapsView.h), for the kernel's vector lookup, which gives
    // bitwise visibility()'s answers; null (the default): the kernel calls visibility() lane by
    // lane. Called once per frame when the kernel's lights are built; O(1), thread-safe.
    virtual const ShadowMapsView* view() const { return nullptr; }
};

// The reference's shadows: whether light `lightIndex` casts (the same lights as the stages'
// ShadowLookup), and its visibility, 0 or 1 or between for an area test, at a point of the exact
// surface (view space, double). Same contract otherwise.
class ExactShadowLookup {
public:
    virtual ~ExactShadowLookup() = default;
    virtual bool casts(size_t lightIndex) const = 0;
    virtual double visibility(size_t lightIndex, const glm::dvec3& positionView,
                              const glm::dvec3& normalView) const = 0;
};

} // namespace lighting::shadows
