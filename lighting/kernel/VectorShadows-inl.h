// The shading kernel's vector shadow lookup: ShadowMaps::visibility (lighting/shadows/
// ShadowMaps.cpp) for a vector of lanes at once, once per compiled instruction set (included by
// LightKernel-inl.h). It reads the maps as plain data (ShadowMapsView.h) and does, for every lane,
// the scalar lookup's steps: the finiteness guard, the face (cube face by the major axis of the
// world-space direction from the light, cascade by view depth, the spot's one face), the
// projection, the normal offset, the coverage test, the receiver-plane depth gradient and the
// slope bias, then the filter's taps (nearest / 3x3 / 5x5 / 16 Poisson), each a Highway gather of
// one depth texel per lane (hn::GatherIndex) compared with the receiver plane's depth there.
//
// Precision: the scalar lookup computes in double from the float position and normal; so does
// this, in double lanes: a float vector of N lanes is looked up as N / 2-lane halves, each promoted
// to a full-width double vector (AVX2: 8 float lanes = 2 x 4 doubles). Every operation is the
// scalar code's, in its order (glm's dmat4 x dvec4 is (m0 x + m1 y) + (m2 z + m3), its dot
// products (x + y) + z, normalize is v * (1 / sqrt(v.v)), its cross products as glm writes them;
// exact IEEE division, square root and floor; -ffp-contract=off keeps multiply and add apart), and
// the branches are selections, so the answer is bitwise the scalar one on every lane
// (tests/kernel/vector_shadows_test.cpp). No transcendental is involved.
//
// Faces per lane: lanes of one vector may fall on different faces (a cube's seams, a cascade
// split). The lookup runs once per distinct face among the lanes, the face's constants broadcast,
// and keeps each lane's own face's answer: usually one pass, two or three at a seam. Texel indices
// are clamped to the map in integer lanes before the gather, so a gather never reads outside the
// map, whatever a lane that is not looked up holds (NaN converts to an index that the clamp maps
// into the map).
#include "lighting/kernel/ShadingPacket.h"
#include "lighting/shadows/ShadowMapsView.h"
#include "scenes/Scene.h"

#if defined(LIGHTING_KERNEL_VECTOR_SHADOWS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef LIGHTING_KERNEL_VECTOR_SHADOWS_INL_H_
#undef LIGHTING_KERNEL_VECTOR_SHADOWS_INL_H_
#else
#define LIGHTING_KERNEL_VECTOR_SHADOWS_INL_H_
#endif

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace lighting::kernel::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Full-width double vectors: half as many lanes as the kernel's float vectors.
using ShadowDoubleTag = hn::Repartition<double, hn::ScalableTag<float>>;
using ShadowDouble = hn::Vec<ShadowDoubleTag>;
using ShadowMask = hn::Mask<ShadowDoubleTag>;
// The same lane count in float (the packet's inputs, the visibility) and int32 (texel indices).
using ShadowFloatTag = hn::Rebind<float, ShadowDoubleTag>;
using ShadowFloat = hn::Vec<ShadowFloatTag>;
using ShadowIndexTag = hn::Rebind<int32_t, ShadowDoubleTag>;
using ShadowIndex = hn::Vec<ShadowIndexTag>;
constexpr size_t kShadowLanes = hn::MaxLanes(ShadowDoubleTag());
static_assert(kShadowLanes <= 8, "a half vector's lanes fit in one byte of mask bits");

struct ShadowVec3 {
    ShadowDouble x, y, z;
};

// glm::dot: (x x' + y y') + z z'.
HWY_INLINE ShadowDouble shadowDot(const ShadowVec3& a, const ShadowVec3& b) {
    return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
}

// glm::cross, its operands in glm's order.
HWY_INLINE ShadowVec3 shadowCross(const ShadowVec3& a, const ShadowVec3& b) {
    return {hn::Sub(hn::Mul(a.y, b.z), hn::Mul(b.y, a.z)),
            hn::Sub(hn::Mul(a.z, b.x), hn::Mul(b.z, a.x)),
            hn::Sub(hn::Mul(a.x, b.y), hn::Mul(b.x, a.y))};
}

// a + s b, componentwise (glm's p + s * t).
HWY_INLINE ShadowVec3 shadowAddScaled(const ShadowVec3& a, ShadowDouble s, const ShadowVec3& b) {
    return {hn::Add(a.x, hn::Mul(s, b.x)), hn::Add(a.y, hn::Mul(s, b.y)),
            hn::Add(a.z, hn::Mul(s, b.z))};
}

// ShadowMaps' upFor: the world axis least aligned with n, (1,0,0), (0,1,0) or (0,0,1).
HWY_INLINE ShadowVec3 shadowUpFor(const ShadowVec3& n) {
    const ShadowDoubleTag d;
    const ShadowDouble ax = hn::Abs(n.x), ay = hn::Abs(n.y), az = hn::Abs(n.z);
    const ShadowMask isX = hn::And(hn::Le(ax, ay), hn::Le(ax, az));
    const ShadowMask isY = hn::AndNot(isX, hn::Le(ay, az));
    const ShadowMask isZ = hn::Not(hn::Or(isX, isY));
    const ShadowDouble one = hn::Set(d, 1.0);
    return {hn::IfThenElseZero(isX, one), hn::IfThenElseZero(isY, one),
            hn::IfThenElseZero(isZ, one)};
}

// faceVisibility's `project`: texel coordinates (u right, v down) and light-space depth; lanes
// outside `valid` (behind a perspective face) hold values nobody reads.
struct ShadowProjected {
    ShadowDouble u, v, depth;
    ShadowMask valid;
};

HWY_INLINE ShadowProjected shadowProject(const shadows::ShadowFaceView& face, double sizeD,
                                         const ShadowVec3& q) {
    const ShadowDoubleTag d;
    const auto& m = face.lightClipFromView;
    // glm's dmat4 x dvec4(q, 1): (m0 q.x + m1 q.y) + (m2 q.z + m3 1).
    auto row = [&](int r) HWY_ATTR {
        return hn::Add(
            hn::Add(hn::Mul(hn::Set(d, m[0][r]), q.x), hn::Mul(hn::Set(d, m[1][r]), q.y)),
            hn::Add(hn::Mul(hn::Set(d, m[2][r]), q.z), hn::Set(d, m[3][r])));
    };
    const ShadowDouble half = hn::Set(d, 0.5);
    const ShadowDouble size = hn::Set(d, sizeD);
    const ShadowDouble cx = row(0), cy = row(1), cz = row(2);
    ShadowProjected r;
    if (face.orthographic) {
        r.depth = hn::Sub(hn::Set(d, face.farMetres),
                          hn::Mul(cz, hn::Set(d, face.farMetres - face.nearMetres)));
        r.u = hn::Mul(hn::Add(hn::Mul(cx, half), half), size);
        r.v = hn::Mul(hn::Sub(half, hn::Mul(half, cy)), size);
        r.valid = hn::Eq(half, half);
    } else {
        const ShadowDouble cw = row(3);
        r.depth = cw;
        // (c.x / c.w * 0.5 + 0.5) * size and (0.5 - 0.5 * c.y / c.w) * size, left to right.
        r.u = hn::Mul(hn::Add(hn::Mul(hn::Div(cx, cw), half), half), size);
        r.v = hn::Mul(hn::Sub(half, hn::Div(hn::Mul(half, cy), cw)), size);
        r.valid = hn::Gt(cw, hn::Zero(d));
    }
    return r;
}

// faceVisibility's texelWorld: the side of one texel at light-space depth `depth`, metres.
HWY_INLINE ShadowDouble shadowTexelWorld(const shadows::ShadowFaceView& face, double sizeD,
                                         ShadowDouble depth) {
    const ShadowDoubleTag d;
    if (face.orthographic)
        return hn::Set(d, face.extentMetres / sizeD);
    return hn::Div(hn::Mul(hn::Mul(hn::Set(d, 2.0), depth), hn::Set(d, face.tanHalfFov)),
                   hn::Set(d, sizeD));
}

// faceVisibility on one face for the lanes of `lanes` (those on this face): the number of lit
// taps, or tapCount where the lookup is lit outright (empty face, behind it, outside its
// coverage), so that count / tapCount is the scalar lookup's float answer. Other lanes: tapCount.
HWY_INLINE ShadowDouble shadowFaceLitCount(const shadows::ShadowMapsView& view,
                                           const shadows::ShadowFaceView& face, ShadowMask lanes,
                                           const ShadowVec3& position, const ShadowVec3& n,
                                           ShadowMask hasNormal, int tapCount) {
    const ShadowDoubleTag d;
    const ShadowIndexTag di;
    const ShadowFloatTag df;
    const ShadowDouble allLit = hn::Set(d, double(tapCount));
    if (face.empty)
        return allLit;
    const int size = view.mapSize;
    const double sizeD = size;

    ShadowProjected r = shadowProject(face, sizeD, position);
    ShadowMask litOutright = hn::Or(hn::Not(lanes), hn::Not(r.valid));
    ShadowVec3 p = position;
    if (view.normalOffset != 0.0f) {
        const ShadowDouble shift =
            hn::Mul(hn::Set(d, double(view.normalOffset)), shadowTexelWorld(face, sizeD, r.depth));
        const ShadowVec3 moved = shadowAddScaled(p, shift, n);
        p = {hn::IfThenElse(hasNormal, moved.x, p.x), hn::IfThenElse(hasNormal, moved.y, p.y),
             hn::IfThenElse(hasNormal, moved.z, p.z)};
        // Lanes without a normal project the same point again: the same r.
        r = shadowProject(face, sizeD, p);
        litOutright = hn::Or(litOutright, hn::Not(r.valid));
    }
    const double tolerance = kFaceEdgeTolerance * sizeD;
    const ShadowDouble low = hn::Set(d, -tolerance), high = hn::Set(d, sizeD + tolerance);
    const ShadowMask inside = hn::And(hn::And(hn::And(hn::Ge(r.u, low), hn::Le(r.u, high)),
                                              hn::And(hn::Ge(r.v, low), hn::Le(r.v, high))),
                                      hn::And(hn::Ge(r.depth, hn::Set(d, face.nearMetres)),
                                              hn::Le(r.depth, hn::Set(d, face.farMetres))));
    litOutright = hn::Or(litOutright, hn::Not(inside));
    if (hn::AllTrue(d, litOutright))
        return allLit;

    // Receiver plane: depth change per texel along u and v, from two tangent directions.
    const ShadowDouble zero = hn::Zero(d);
    const ShadowDouble maxTan = hn::Set(d, kMaxBiasTan);
    const ShadowDouble texel = shadowTexelWorld(face, sizeD, r.depth);
    ShadowDouble gradientU = zero, gradientV = zero, tanTheta = zero;
    const ShadowMask planeLanes = hn::And(hasNormal, hn::Gt(texel, zero));
    if (!hn::AllFalse(d, hn::AndNot(litOutright, planeLanes))) {
        const ShadowVec3 t1Raw = shadowCross(n, shadowUpFor(n));
        const ShadowDouble inverseLength =
            hn::Div(hn::Set(d, 1.0), hn::Sqrt(shadowDot(t1Raw, t1Raw)));
        const ShadowVec3 t1 = {hn::Mul(t1Raw.x, inverseLength), hn::Mul(t1Raw.y, inverseLength),
                               hn::Mul(t1Raw.z, inverseLength)};
        const ShadowVec3 t2 = shadowCross(n, t1);
        const ShadowProjected a = shadowProject(face, sizeD, shadowAddScaled(p, texel, t1));
        const ShadowProjected b = shadowProject(face, sizeD, shadowAddScaled(p, texel, t2));
        const ShadowDouble du1 = hn::Sub(a.u, r.u), dv1 = hn::Sub(a.v, r.v),
                           dd1 = hn::Sub(a.depth, r.depth);
        const ShadowDouble du2 = hn::Sub(b.u, r.u), dv2 = hn::Sub(b.v, r.v),
                           dd2 = hn::Sub(b.depth, r.depth);
        const ShadowDouble det = hn::Sub(hn::Mul(du1, dv2), hn::Mul(dv1, du2));
        const ShadowMask solvable =
            hn::And(hn::And(a.valid, b.valid),
                    hn::Gt(hn::Abs(det), hn::Set(d, kMinReceiverPlaneDeterminant)));
        ShadowDouble gu = hn::Div(hn::Sub(hn::Mul(dd1, dv2), hn::Mul(dv1, dd2)), det);
        ShadowDouble gv = hn::Div(hn::Sub(hn::Mul(du1, dd2), hn::Mul(dd1, du2)), det);
        ShadowDouble tangent = hn::Div(hn::Sqrt(hn::Add(hn::Mul(gu, gu), hn::Mul(gv, gv))), texel);
        // Not solvable: the plane contains the light's direction; no gradient, the largest tan.
        gu = hn::IfThenElseZero(solvable, gu);
        gv = hn::IfThenElseZero(solvable, gv);
        tangent = hn::IfThenElse(solvable, tangent, maxTan);
        const ShadowMask steep = hn::Gt(tangent, maxTan);
        const ShadowDouble scale = hn::Div(maxTan, tangent);
        gu = hn::IfThenElse(steep, hn::Mul(gu, scale), gu);
        gv = hn::IfThenElse(steep, hn::Mul(gv, scale), gv);
        tangent = hn::IfThenElse(steep, maxTan, tangent);
        gradientU = hn::IfThenElseZero(planeLanes, gu);
        gradientV = hn::IfThenElseZero(planeLanes, gv);
        tanTheta = hn::IfThenElseZero(planeLanes, tangent);
    }
    const ShadowDouble bias =
        hn::Add(hn::Set(d, double(view.biasConstant)),
                hn::Mul(hn::Mul(hn::Set(d, double(view.biasSlope)), texel), tanTheta));

    // Stored depth -> light-space depth (reversed Z; 0 = nothing = the far plane).
    const double n0 = face.nearMetres, f0 = face.farMetres;
    const double planeA = -n0 / (f0 - n0), planeB = n0 * f0 / (f0 - n0);
    const ShadowIndex lastTexel = hn::Set(di, size - 1);
    const ShadowIndex rowStride = hn::Set(di, size);
    const ShadowDouble texelCentre = hn::Set(d, 0.5);
    const ShadowDouble one = hn::Set(d, 1.0);
    // faceVisibility's lit(ti, tj): 1 where the receiver plane at texel (ti, tj), less the bias,
    // is not behind the stored occluder.
    auto litTap = [&](ShadowIndex ti, ShadowIndex tj) HWY_ATTR {
        ti = hn::Min(hn::Max(ti, hn::Zero(di)), lastTexel);
        tj = hn::Min(hn::Max(tj, hn::Zero(di)), lastTexel);
        const ShadowIndex index = hn::Add(hn::Mul(tj, rowStride), ti);
        ShadowDouble occluder;
        if (face.packedDepth) {
            // unorm16Texel: the word of texel k / 2, shifted right by 16 (k & 1), low 16 bits.
            const ShadowIndex word = hn::GatherIndex(
                di, reinterpret_cast<const int32_t*>(face.packedDepth), hn::ShiftRight<1>(index));
            const ShadowIndex shift = hn::ShiftLeft<4>(hn::And(index, hn::Set(di, 1)));
            const ShadowDouble stored =
                hn::PromoteTo(d, hn::And(hn::Shr(word, shift), hn::Set(di, 0xFFFF)));
            occluder = hn::Sub(hn::Set(d, f0), hn::Mul(hn::Div(stored, hn::Set(d, kUnorm16Max)),
                                                       hn::Set(d, f0 - n0)));
        } else {
            const ShadowDouble stored = hn::PromoteTo(d, hn::GatherIndex(df, face.depth, index));
            occluder = face.orthographic
                           ? hn::Sub(hn::Set(d, f0), hn::Mul(stored, hn::Set(d, f0 - n0)))
                           : hn::Div(hn::Set(d, planeB), hn::Sub(stored, hn::Set(d, planeA)));
        }
        const ShadowDouble receiver = hn::Add(
            hn::Add(r.depth,
                    hn::Mul(gradientU, hn::Sub(hn::Add(hn::PromoteTo(d, ti), texelCentre), r.u))),
            hn::Mul(gradientV, hn::Sub(hn::Add(hn::PromoteTo(d, tj), texelCentre), r.v)));
        return hn::IfThenElseZero(hn::Le(hn::Sub(receiver, bias), occluder), one);
    };
    // int(floor(x)): x is within the face here (lanes that are not are dropped below).
    auto texelOf = [&](ShadowDouble x) HWY_ATTR { return hn::DemoteTo(di, hn::Floor(x)); };
    ShadowDouble count = zero;
    switch (view.filter) {
    case ShadowFilter::None:
        count = litTap(texelOf(r.u), texelOf(r.v));
        break;
    case ShadowFilter::Pcf3:
    case ShadowFilter::Pcf5: {
        const int radius = view.filter == ShadowFilter::Pcf3 ? 1 : 2;
        const ShadowIndex i = texelOf(r.u), j = texelOf(r.v);
        for (int dj = -radius; dj <= radius; ++dj)
            for (int dx = -radius; dx <= radius; ++dx)
                count = hn::Add(count,
                                litTap(hn::Add(i, hn::Set(di, dx)), hn::Add(j, hn::Set(di, dj))));
        break;
    }
    case ShadowFilter::Poisson:
        for (const auto& offset : kPoissonDisk)
            count = hn::Add(
                count, litTap(texelOf(hn::Add(r.u, hn::Set(d, kPoissonRadiusTexels * offset[0]))),
                              texelOf(hn::Add(r.v, hn::Set(d, kPoissonRadiusTexels * offset[1])))));
        break;
    }
    return hn::IfThenElse(litOutright, allLit, count);
}

// The filter's number of taps (faceVisibility's tapCount; 1 for the nearest texel).
HWY_INLINE int shadowTapCount(ShadowFilter filter) {
    switch (filter) {
    case ShadowFilter::None:
        return 1;
    case ShadowFilter::Pcf3:
        return 9;
    case ShadowFilter::Pcf5:
        return 25;
    case ShadowFilter::Poisson:
        return kPoissonTapCount;
    }
    return 1;
}

// ShadowMaps::visibility for kShadowLanes consecutive lanes of a packet, from lane `first` (the
// packet's float positionView and normalView, as the scalar path passes them): the
// lanes whose bit is set in `lanes` (bit 0 = lane `first`) are looked up, the others are 1.
HWY_INLINE ShadowFloat shadowVisibilityLanes(const shadows::ShadowMapsView& view, uint32_t shadow,
                                             const ShadingPacket& packet, size_t first,
                                             uint32_t lanes) {
    const ShadowDoubleTag d;
    const ShadowFloatTag df;
    const ShadowFloat litFloat = hn::Set(df, 1.0f);
    if (lanes == 0 || shadow >= view.shadowCount)
        return litFloat;
    const shadows::ShadowView& light = view.shadows[shadow];
    if (light.faceCount == 0) // faceFor finds no face: lit
        return litFloat;
    const uint8_t laneBits[8] = {uint8_t(lanes)};
    ShadowMask todo = hn::LoadMaskBits(d, laneBits);
    const ShadowVec3 p = {hn::PromoteTo(d, hn::LoadU(df, packet.positionView[0] + first)),
                          hn::PromoteTo(d, hn::LoadU(df, packet.positionView[1] + first)),
                          hn::PromoteTo(d, hn::LoadU(df, packet.positionView[2] + first))};
    const ShadowVec3 normal = {hn::PromoteTo(d, hn::LoadU(df, packet.normalView[0] + first)),
                               hn::PromoteTo(d, hn::LoadU(df, packet.normalView[1] + first)),
                               hn::PromoteTo(d, hn::LoadU(df, packet.normalView[2] + first))};
    // Non-finite input: lit.
    const ShadowMask finite = hn::And(hn::And(hn::And(hn::IsFinite(p.x), hn::IsFinite(p.y)),
                                              hn::And(hn::IsFinite(p.z), hn::IsFinite(normal.x))),
                                      hn::And(hn::IsFinite(normal.y), hn::IsFinite(normal.z)));
    todo = hn::And(todo, finite);
    const int tapCount = shadowTapCount(view.filter);
    ShadowDouble count = hn::Set(d, double(tapCount));
    if (hn::AllFalse(d, todo))
        return litFloat;

    // The unit normal, or 0 without one (a zero normal disables the receiver plane).
    const ShadowDouble normalLength = hn::Sqrt(shadowDot(normal, normal));
    const ShadowMask hasNormal =
        hn::And(hn::Gt(normalLength, hn::Zero(d)), hn::IsFinite(normalLength));
    const ShadowVec3 n = {hn::IfThenElseZero(hasNormal, hn::Div(normal.x, normalLength)),
                          hn::IfThenElseZero(hasNormal, hn::Div(normal.y, normalLength)),
                          hn::IfThenElseZero(hasNormal, hn::Div(normal.z, normalLength))};

    // faceFor, per lane, as a face index (small integers in double lanes).
    ShadowDouble face = hn::Set(d, double(light.firstFace));
    if (light.type == uint32_t(scenes::LightType::Point)) {
        const auto& m = view.worldFromViewRotation;
        const ShadowVec3 offset = {hn::Sub(p.x, hn::Set(d, light.positionView[0])),
                                   hn::Sub(p.y, hn::Set(d, light.positionView[1])),
                                   hn::Sub(p.z, hn::Set(d, light.positionView[2]))};
        // glm's dmat3 x dvec3: m[0][r] x + m[1][r] y + m[2][r] z, left to right.
        auto row = [&](int r) HWY_ATTR {
            return hn::Add(hn::Add(hn::Mul(hn::Set(d, m[0][r]), offset.x),
                                   hn::Mul(hn::Set(d, m[1][r]), offset.y)),
                           hn::Mul(hn::Set(d, m[2][r]), offset.z));
        };
        const ShadowDouble wx = row(0), wy = row(1), wz = row(2);
        const ShadowDouble ax = hn::Abs(wx), ay = hn::Abs(wy), az = hn::Abs(wz);
        const ShadowMask yMajor = hn::And(hn::Gt(ay, ax), hn::Ge(ay, az));
        const ShadowMask zMajor = hn::AndNot(yMajor, hn::And(hn::Gt(az, ax), hn::Gt(az, ay)));
        const ShadowDouble along = hn::IfThenElse(yMajor, wy, hn::IfThenElse(zMajor, wz, wx));
        const ShadowDouble axisFace =
            hn::IfThenElse(yMajor, hn::Set(d, 2.0), hn::IfThenElseZero(zMajor, hn::Set(d, 4.0)));
        face = hn::Add(hn::Add(face, axisFace),
                       hn::IfThenElseZero(hn::Lt(along, hn::Zero(d)), hn::Set(d, 1.0)));
    } else if (light.type == uint32_t(scenes::LightType::Directional)) {
        // The first cascade whose far split is at or beyond the view depth, else the last.
        const ShadowDouble depth = hn::Neg(p.z);
        face = hn::Set(d, double(light.firstFace + light.faceCount - 1));
        for (uint32_t c = light.faceCount - 1; c-- > 0;)
            face = hn::IfThenElse(hn::Le(depth, hn::Set(d, light.cascadeFarDepthView[c])),
                                  hn::Set(d, double(light.firstFace + c)), face);
    }

    // Once per distinct face among the lanes to look up.
    HWY_ALIGN double faceOfLane[kShadowLanes];
    hn::Store(face, d, faceOfLane);
    while (!hn::AllFalse(d, todo)) {
        const double faceIndex = faceOfLane[size_t(hn::FindFirstTrue(d, todo))];
        const ShadowMask onFace = hn::And(todo, hn::Eq(face, hn::Set(d, faceIndex)));
        count = hn::IfThenElse(onFace,
                               shadowFaceLitCount(view, view.faces[size_t(faceIndex)], onFace, p, n,
                                                  hasNormal, tapCount),
                               count);
        todo = hn::AndNot(onFace, todo);
    }
    // float(litCount) / float(tapCount) (the nearest texel: float(lit), the same number), then
    // visibility()'s guard: finite and clamped to [0, 1].
    ShadowFloat v = hn::DemoteTo(df, count);
    if (view.filter != ShadowFilter::None)
        v = hn::Div(v, hn::Set(df, float(tapCount)));
    // std::clamp's selections (v < 0 ? 0 : 1 < v ? 1 : v), which keep a -0 as it is.
    const ShadowFloat zeroFloat = hn::Zero(df);
    const ShadowFloat clamped = hn::IfThenElse(hn::Lt(v, zeroFloat), zeroFloat,
                                               hn::IfThenElse(hn::Lt(litFloat, v), litFloat, v));
    return hn::IfThenElse(hn::IsFinite(v), clamped, litFloat);
}

} // namespace lighting::kernel::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // include guard toggle
