// PostAaImage: the image views the post-process anti-aliasing filters (EdgeBlur.h, Fxaa.h) read
// and write, and the one bilinear fetch they share.
//
// Conventions: planes are row-major, width x height floats, row 0 the top row (y down), as
// StageResult's radiance and the G-buffer. Pixel (x, y) has its centre at the point (x, y): a
// fetch at (x + 0.5, y) lies half-way between two pixel centres. Fetches outside the image are
// clamped to its border (a GPU sampler's clamp-to-edge).
//
// A filter reads a RadianceIn and writes a RadianceOut that must not alias it: every output pixel
// is computed from the unfiltered input only, so rows can be filtered in any order, on any number
// of threads, and give bitwise the same image.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace lighting::postaa {

// Linear HDR radiance, read-only.
struct RadianceIn {
    int width = 0;
    int height = 0;
    const float* rgb[3] = {};
};

// Where a filter writes: the filtered radiance and a per-pixel edge plane in [0, 1] (what each
// filter puts there is documented with the filter). No plane may alias the input.
struct RadianceOut {
    float* rgb[3] = {};
    float* edges = nullptr;
};

// A bilinear fetch at a point: the four texels and their weights, computed once and applied to
// every plane of an image (the colour planes of FXAA share the luma's weights). The weights sum to
// one; a fetch at a pixel centre has weight 1 on that pixel and 0 elsewhere.
struct BilinearTap {
    size_t index[4] = {}; // top-left, top-right, bottom-left, bottom-right
    float weight[4] = {1.0f, 0.0f, 0.0f, 0.0f};

    // The fetch at point (x, y) (pixel coordinates, centres at integers), clamped to the image.
    static BilinearTap at(int width, int height, float x, float y) {
        x = std::clamp(x, 0.0f, float(width - 1));
        y = std::clamp(y, 0.0f, float(height - 1));
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
        const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
        const float fx = x - float(x0), fy = y - float(y0);
        BilinearTap tap;
        tap.index[0] = size_t(y0) * size_t(width) + size_t(x0);
        tap.index[1] = size_t(y0) * size_t(width) + size_t(x1);
        tap.index[2] = size_t(y1) * size_t(width) + size_t(x0);
        tap.index[3] = size_t(y1) * size_t(width) + size_t(x1);
        tap.weight[0] = (1.0f - fx) * (1.0f - fy);
        tap.weight[1] = fx * (1.0f - fy);
        tap.weight[2] = (1.0f - fx) * fy;
        tap.weight[3] = fx * fy;
        return tap;
    }

    // The fetch from one plane, the four products summed in a fixed order.
    float apply(const float* plane) const {
        return weight[0] * plane[index[0]] + weight[1] * plane[index[1]] +
               weight[2] * plane[index[2]] + weight[3] * plane[index[3]];
    }
};

} // namespace lighting::postaa
