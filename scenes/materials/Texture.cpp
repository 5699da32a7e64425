#include "scenes/materials/Texture.h"

#include <array>
#include <cmath>

namespace scenes {

namespace {

// sRGB EOTF as a 256-entry table: texels are 8-bit, so the table is exact and cheap.
const std::array<float, 256>& srgbToLinearTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) {
            float c = float(i) / 255.0f;
            t[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
        }
        return t;
    }();
    return table;
}

int wrap(int i, int n) {
    int r = i % n;
    return r < 0 ? r + n : r;
}

} // namespace

glm::vec4 Texture::sample(glm::vec2 uv) const {
    if (!valid())
        return glm::vec4(1.0f);
    const std::array<float, 256>& toLinear = srgbToLinearTable();
    // Texel centres at half-integers; bilinear between the four around the lookup.
    float x = uv.x * float(width) - 0.5f;
    float y = uv.y * float(height) - 0.5f;
    if (!std::isfinite(x) || !std::isfinite(y))
        return glm::vec4(1.0f);
    float fx = std::floor(x), fy = std::floor(y);
    float tx = x - fx, ty = y - fy;
    // Reduce before converting to int so huge uvs cannot overflow.
    int x0 = wrap(int(std::fmod(fx, float(width))), width),
        y0 = wrap(int(std::fmod(fy, float(height))), height);
    int x1 = wrap(x0 + 1, width), y1 = wrap(y0 + 1, height);
    auto texel = [&](int xi, int yi) {
        const uint8_t* p = &rgba8[(size_t(yi) * width + xi) * 4];
        if (srgb)
            return glm::vec4(toLinear[p[0]], toLinear[p[1]], toLinear[p[2]], p[3] / 255.0f);
        return glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f;
    };
    glm::vec4 top = glm::mix(texel(x0, y0), texel(x1, y0), tx);
    glm::vec4 bottom = glm::mix(texel(x0, y1), texel(x1, y1), tx);
    return glm::mix(top, bottom, ty);
}

} // namespace scenes
