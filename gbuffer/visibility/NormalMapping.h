// NormalMapping: the shading normal of a tangent-space normal map, the one formula the G-buffer
// resolve (float, TriangleCorners.h) and the reference's exact surface (double, ExactSurface.cpp)
// share. glTF 2.0 conventions (scenes/materials/Material.h): the texel's rgb in [0,1] maps to
// m = (2 rgb - 1) * (scale, scale, 1) in the frame (T, B, N), with T the interpolated tangent made
// orthogonal to N (Gram-Schmidt), B = w cross(N, T) pointing up the image, w = +-1 the tangent's
// bitangent sign; the result is normalize(m.x T + m.y B + m.z N).
// Two-sided surfaces seen from behind: the map is applied in the front face's frame and the
// result negated, so a bump seen from behind is the same bump (the whole frame flips with N).
// Degenerate input (zero tangent, tangent parallel to N, m = 0) keeps the unmapped normal.
// Pure, thread-safe.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

namespace gbuffer {

// normalVisible: unit interpolated normal of the visible side (negated on back faces);
// tangent: interpolated tangent direction (any length) with w its sign; texel: the normal map's
// linear rgb at the sample.
template <class T>
inline glm::vec<3, T> normalMapped(const glm::vec<3, T>& normalVisible, bool backFace,
                                   const glm::vec<3, T>& tangent, T bitangentSign,
                                   const glm::vec<3, T>& texel, T scale) {
    using V = glm::vec<3, T>;
    const V n = backFace ? -normalVisible : normalVisible;
    V t = tangent - n * glm::dot(n, tangent);
    const T tLength2 = glm::dot(t, t);
    if (!(tLength2 > T(0)))
        return normalVisible;
    t *= T(1) / std::sqrt(tLength2);
    const V b = bitangentSign * glm::cross(n, t);
    const V m((T(2) * texel.x - T(1)) * scale, (T(2) * texel.y - T(1)) * scale,
              T(2) * texel.z - T(1));
    const V mapped = m.x * t + m.y * b + m.z * n;
    const T length2 = glm::dot(mapped, mapped);
    if (!(length2 > T(0)))
        return normalVisible;
    return mapped * ((backFace ? T(-1) : T(1)) / std::sqrt(length2));
}

} // namespace gbuffer
