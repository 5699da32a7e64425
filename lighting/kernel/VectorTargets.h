// VectorTargets: the kernel's per-instruction-set entry points, one set for every target Highway
// compiled (VectorTargets.cpp includes the per-target code through hwy/foreach_target.h), and the
// list of those this CPU can run. Internal to lighting/kernel: stages go through KernelIsa,
// shadePacket (LightKernel.h) and PacketDecoder.
//
// Which targets are compiled: Highway's default policy for the project's baseline
// (-march=x86-64-v2, i.e. SSSE3 as Highway sees it, without AES/CLMUL) is every x86 target from
// it upwards: SSSE3, SSE4, AVX2 and AVX3 (AVX-512 F/BW/DQ/VL). AVX3_DL adds nothing to float
// arithmetic and is left out (Highway builds it only on request). Scalable targets (SVE, RVV) are
// disabled in VectorTargets.cpp because the kernel keeps a packet as an array of vectors.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/ShadingPacket.h"
#include "lighting/kernel/SplitLightKernel.h"

namespace lighting::kernel {

struct PacketDecodeTables; // PacketDecoder.h

struct ShadeArgs {
    const ShadingPacket* packet;
    uint32_t laneMask;
    const KernelLight* lights;
    const uint32_t* indices;
    size_t count;
    PacketAccumulator* accumulator;
    bool countContributing;
    // Optional (nullptr: every light on every lane of laneMask): per light of `indices`, the
    // lanes that evaluate it (LightKernel.h, shadePacket with per-light lane masks).
    const uint16_t* lightLaneMasks = nullptr;
    // The lights' shadows (KernelLights::shadows()); null when no light casts one.
    const shadows::ShadowLookup* shadows = nullptr;
    // Their plain-data view (KernelLights::shadowView()): when given, the shadow factor is the
    // vector lookup's (VectorShadows-inl.h), else shadows->visibility() lane by lane.
    const shadows::ShadowMapsView* shadowView = nullptr;
};

// shadePacketSplit's arguments (SplitLightKernel.h).
struct ShadeSplitArgs {
    const ShadingPacket* packet;
    uint32_t laneMask;
    const KernelLight* lights;
    const uint32_t* indices;
    size_t count;
    SplitPacketAccumulator* accumulator;
    const shadows::ShadowLookup* shadows = nullptr;      // as ShadeArgs::shadows
    const shadows::ShadowMapsView* shadowView = nullptr; // as ShadeArgs::shadowView
};

// shadowVisibility's arguments: the vector lookup alone, for tests and benchmarks.
struct ShadowVisibilityArgs {
    const shadows::ShadowMapsView* view;
    uint32_t shadow;
    const ShadingPacket* packet; // positionView and normalView are read
    uint32_t laneMask;           // lanes to look up; the others get 1
    float* visibility;           // kPacketLanes values
};

struct DecodeArgs {
    const PacketDecodeTables* tables;
    int x0;
    int y0;
    ShadingPacket* packet;
};

struct VectorFunctions {
    int64_t target;   // Highway's HWY_* bit
    const char* name; // Highway's name: "SSSE3", "SSE4", "AVX2", "AVX3", "NEON"
    int vectorLanes;  // floats per hardware vector
    void (*shade)(const ShadeArgs&);
    void (*decode)(const DecodeArgs&);
    // out[i] = x[i]^y[i] as the kernel computes the specular lobe (x, y >= 0): for the accuracy
    // study of tests/kernel/vector_pow_test.cpp.
    void (*pow)(const float* x, const float* y, float* out, size_t count);
    void (*shadeSplit)(const ShadeSplitArgs&); // SplitLightKernel.h
    // The shadow lookup the kernel makes for a shadowed light (VectorShadows-inl.h), for every
    // lane of a packet: bitwise ShadowMaps::visibility. For tests and benchmarks.
    void (*shadowVisibility)(const ShadowVisibilityArgs&);
};

// The compiled targets this CPU supports, narrowest to widest. Built once (thread-safe).
const std::vector<const VectorFunctions*>& supportedVectorTargets();
// What Highway's dynamic dispatch picks on this CPU: the widest supported target.
const VectorFunctions* dispatchedVectorTarget();

} // namespace lighting::kernel
