#include "lighting/postaa/EdgeBlur.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <tbb/parallel_for.h>

namespace lighting::postaa {

namespace {

// 0 at `start`, 1 at `end`, linear between, clamped (start > end allowed: a falling ramp). The
// scale is computed once: the per-pixel work is a subtraction and a multiplication.
struct Ramp {
    float start;
    float scale;
    Ramp(float rampStart, float rampEnd) : start(rampStart), scale(1.0f / (rampEnd - rampStart)) {}
    float operator()(float value) const { return std::clamp((value - start) * scale, 0.0f, 1.0f); }
};

std::string text(float value) {
    std::ostringstream stream;
    stream << value;
    return stream.str();
}

} // namespace

std::map<std::string, std::string> EdgeBlurParameters::describe() const {
    return {{"depth_ramp_start", text(depthRampStart)},
            {"depth_ramp_end", text(depthRampEnd)},
            {"normal_cosine_start", text(normalCosineStart)},
            {"normal_cosine_end", text(normalCosineEnd)},
            {"kernel_pixels", text(kernelPixels)}};
}

void SurfacePlanes::extract(const gbuffer::GBuffer& gbuffer) {
    width = gbuffer.width();
    height = gbuffer.height();
    const size_t n = gbuffer.pixelCount();
    inverseDepth.resize(n);
    const bool hasNormals = gbuffer.layout().provides(gbuffer::Channel::Normal);
    const bool floatPlanes = hasNormals && gbuffer.normalPlane(0).size() == n;
    for (std::vector<float>& plane : normal) {
        if (hasNormals)
            plane.resize(n);
        else
            plane.clear();
    }
    const std::span<const float> depth = gbuffer.depth();
    const gbuffer::DepthDecoder& decoder = gbuffer.depthDecoder();
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * size_t(width) + size_t(x);
            if (!gbuffer.covered(pixel)) {
                inverseDepth[pixel] = 0.0f;
                for (int axis = 0; axis < 3 && hasNormals; ++axis)
                    normal[axis][pixel] = 0.0f;
                continue;
            }
            inverseDepth[pixel] = 1.0f / decoder.viewDepthMetres(x, y, depth[pixel]);
            if (floatPlanes) {
                for (int axis = 0; axis < 3; ++axis)
                    normal[axis][pixel] = gbuffer.normalPlane(axis)[pixel];
            } else if (hasNormals) {
                const glm::vec3 n = gbuffer.decode(x, y).normalView;
                for (int axis = 0; axis < 3; ++axis)
                    normal[axis][pixel] = n[axis];
            }
        }
    });
}

void edgeWeights(const SurfacePlanes& surface, const EdgeBlurParameters& p, float* edges) {
    const int w = surface.width, h = surface.height;
    const std::vector<float>& inv = surface.inverseDepth;
    const bool normals = !surface.normal[0].empty();
    const Ramp depthRamp(p.depthRampStart, p.depthRampEnd);
    const Ramp normalRamp(p.normalCosineStart, p.normalCosineEnd);
    tbb::parallel_for(0, h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const size_t c = size_t(y) * size_t(w) + size_t(x);
            // The 4 neighbours (left, right, up, down); -1 outside the image.
            const long long neighbour[4] = {
                x > 0 ? (long long)c - 1 : -1, x + 1 < w ? (long long)c + 1 : -1,
                y > 0 ? (long long)c - w : -1, y + 1 < h ? (long long)c + w : -1};
            const bool covered = inv[c] > 0.0f;
            bool silhouette = false; // a neighbour whose coverage differs
            for (long long n : neighbour)
                silhouette = silhouette || (n >= 0 && (inv[size_t(n)] > 0.0f) != covered);
            if (silhouette || !covered) {
                edges[c] = silhouette ? 1.0f : 0.0f;
                continue;
            }
            // Depth: the larger second difference of 1/depth over the two axes (zero on a
            // plane, where 1/depth is affine in screen space), relative to the pixel's; the ramps
            // are monotonic, so the ramp of the largest is the largest of the ramps.
            float kink = 0.0f;
            if (neighbour[0] >= 0 && neighbour[1] >= 0)
                kink =
                    std::abs(inv[size_t(neighbour[0])] + inv[size_t(neighbour[1])] - 2.0f * inv[c]);
            if (neighbour[2] >= 0 && neighbour[3] >= 0)
                kink = std::max(kink, std::abs(inv[size_t(neighbour[2])] +
                                               inv[size_t(neighbour[3])] - 2.0f * inv[c]));
            const float depthEdge = depthRamp(kink / inv[c]);
            // Normals: the smallest cosine with a neighbour (the falling ramp's largest value).
            float normalEdge = 0.0f;
            if (normals) {
                const std::vector<float>(&nv)[3] = surface.normal;
                float smallestCosine = 1.0f;
                for (long long n : neighbour) {
                    if (n < 0)
                        continue;
                    const size_t m = size_t(n);
                    smallestCosine =
                        std::min(smallestCosine,
                                 nv[0][c] * nv[0][m] + nv[1][c] * nv[1][m] + nv[2][c] * nv[2][m]);
                }
                normalEdge = normalRamp(smallestCosine);
            }
            edges[c] = 1.0f - (1.0f - depthEdge) * (1.0f - normalEdge);
        }
    });
}

void edgeBlur(const SurfacePlanes& surface, const EdgeBlurParameters& p, const RadianceIn& in,
              const RadianceOut& out) {
    edgeWeights(surface, p, out.edges);
    const int w = in.width, h = in.height;
    const float kernel = std::clamp(p.kernelPixels, 0.0f, 1.0f);
    tbb::parallel_for(0, h, [&](int y) {
        const int up = std::max(y - 1, 0), down = std::min(y + 1, h - 1);
        for (int x = 0; x < w; ++x) {
            const size_t c = size_t(y) * size_t(w) + size_t(x);
            const float s = out.edges[c] * kernel;
            if (s <= 0.0f) {
                for (int ch = 0; ch < 3; ++ch)
                    out.rgb[ch][c] = in.rgb[ch][c];
                continue;
            }
            // The mean of the 4 bilinear taps at (x +- s, y +- s), as 3x3 weights.
            const float centre = (1.0f - s) * (1.0f - s);
            const float side = 0.5f * s * (1.0f - s);
            const float corner = 0.25f * s * s;
            const int left = std::max(x - 1, 0), right = std::min(x + 1, w - 1);
            const size_t rowUp = size_t(up) * size_t(w), row = size_t(y) * size_t(w),
                         rowDown = size_t(down) * size_t(w);
            for (int ch = 0; ch < 3; ++ch) {
                const float* v = in.rgb[ch];
                const float sides =
                    (v[row + left] + v[row + right]) + (v[rowUp + x] + v[rowDown + x]);
                const float corners =
                    (v[rowUp + left] + v[rowUp + right]) + (v[rowDown + left] + v[rowDown + right]);
                out.rgb[ch][c] = centre * v[c] + side * sides + corner * corners;
            }
        }
    });
}

} // namespace lighting::postaa
