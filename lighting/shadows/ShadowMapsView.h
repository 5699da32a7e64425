// ShadowMapsView: a frame's shadow maps as plain data, what the shading kernel's vector lookup
// (lighting/kernel/VectorShadows-inl.h) reads to do ShadowMaps::visibility's arithmetic for a
// whole vector of lanes at once, with the depth texels read by Highway gathers. ShadowMaps
// (ShadowMaps.h) builds it once per frame and hands it out through ShadowLookup::view(); every
// pointer points into the ShadowMaps, which must outlive every use of the view.
//
// The constants of the lookup live here, so that the scalar lookup (ShadowMaps.cpp) and the
// vector one read the very same numbers: the two are bitwise equal only because they perform the
// same IEEE operations on the same values. Conventions as ShadowMaps.h: camera view space, double
// precision, reversed-Z faces (1 = near plane, 0 = far plane / nothing), row 0 at the top.
#pragma once

#include <cstddef>
#include <cstdint>

#include "lighting/shadows/ShadowSettings.h"

namespace lighting {

// tan(theta) of the slope bias and of the receiver plane is clamped here (84 degrees): beyond it
// the tangent plane says nothing reliable about the depth a texel away.
inline constexpr double kMaxBiasTan = 10.0;
// A receiver-plane system whose determinant (texels^2 per texel of tangent step) is at or below
// this is degenerate: the tangent plane contains the light's direction.
inline constexpr double kMinReceiverPlaneDeterminant = 1e-12;
// Points up to this fraction of the face's size outside a face still use it: a point on a cube
// face's edge, which the major axis assigns to this face, may project a rounding error outside.
inline constexpr double kFaceEdgeTolerance = 1e-9;
// The 16-tap Poisson disk of radius 1 (a common fixed set), scaled by kPoissonRadiusTexels.
inline constexpr double kPoissonRadiusTexels = 2.5;
inline constexpr int kPoissonTapCount = 16;
inline constexpr double kPoissonDisk[kPoissonTapCount][2] = {
    {-0.94201624, -0.39906216}, {0.94558609, -0.76890725},  {-0.094184101, -0.92938870},
    {0.34495938, 0.29387760},   {-0.91588581, 0.45771432},  {-0.81544232, -0.87912464},
    {-0.38277543, 0.27676845},  {0.97484398, 0.75648379},   {0.44323325, -0.97511554},
    {0.53742981, -0.47373420},  {-0.26496911, -0.41893023}, {0.79197514, 0.19090188},
    {-0.24188840, 0.99706507},  {-0.81409955, 0.91437590},  {0.19984126, 0.78641367},
    {0.14383161, -0.14100790},
};

// Unorm16 faces (ShadowDepthFormat): a texel's 16 bits over this are its linear depth, 0 = the
// far plane, 1 = the near plane.
inline constexpr double kUnorm16Max = 65535.0;

namespace shadows {

// Texel k of a Unorm16 face: bits [16 (k & 1), 16 (k & 1) + 16) of word k / 2 (the vector lookup
// gathers the word and shifts the same way).
inline uint32_t unorm16Texel(const uint32_t* packed, size_t k) {
    return (packed[k >> 1] >> ((k & 1u) * 16u)) & 0xFFFFu;
}

// One face (ShadowFace in ShadowMaps.h).
struct ShadowFaceView {
    // camera view -> face clip, column-major as glm::dmat4 (lightClipFromView[column][row]).
    double lightClipFromView[4][4];
    double nearMetres;
    double farMetres;
    double tanHalfFov;   // perspective faces
    double extentMetres; // orthographic faces
    const float* depth;  // Float32 faces: mapSize^2 floats; else null (and when empty)
    // Unorm16 faces: mapSize^2 texels packed two per word (unorm16Texel); else null.
    const uint32_t* packedDepth;
    bool orthographic;
    bool empty; // nothing to receive: every lookup is lit
};

// One shadow (one casting light).
struct ShadowView {
    uint32_t type; // scenes::LightType
    uint32_t firstFace;
    uint32_t faceCount;
    double positionView[3];            // point lights: the cube's centre
    const double* cascadeFarDepthView; // directional: faceCount far splits, ascending
    // The vector lookup does not handle this shadow: its faces are dual-paraboloid, or its light
    // has settings of its own (scenes/LightShadow.h) that differ from the view's. The kernel then
    // calls the scalar lookup lane by lane (the same answer, bitwise, as always).
    bool scalarOnly;
};

struct ShadowMapsView {
    const ShadowView* shadows = nullptr;
    uint32_t shadowCount = 0;
    const ShadowFaceView* faces = nullptr;
    // The rotation of world from camera view (the cube faces are world-aligned), column-major.
    double worldFromViewRotation[3][3] = {};
    int mapSize = 0;
    ShadowFilter filter = ShadowFilter::None;
    float biasConstant = 0.0f;
    float biasSlope = 0.0f;
    float normalOffset = 0.0f;
};

} // namespace shadows
} // namespace lighting
