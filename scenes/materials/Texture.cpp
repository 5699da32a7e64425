#include "scenes/materials/Texture.h"

#include <array>
#include <cmath>

#include "scenes/materials/TextureAlpha.h"

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

// i / 255.0f for every byte: the same values as the division, without one per texel (the alpha
// tests of shadow casters read millions a frame).
const std::array<float, 256>& unorm8Table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i)
            t[size_t(i)] = float(i) / 255.0f;
        return t;
    }();
    return table;
}

int wrap(int i, int n) {
    int r = i % n;
    return r < 0 ? r + n : r;
}

// The four texels around a lookup and the bilinear weights between them.
struct Footprint {
    int x0, y0, x1, y1;
    float tx, ty;
};

// The footprint of uv, or nothing when uv is not finite.
bool footprintOf(const Texture& texture, glm::vec2 uv, Footprint& out) {
    // Texel centres at half-integers; bilinear between the four around the lookup.
    const float x = uv.x * float(texture.width) - 0.5f;
    const float y = uv.y * float(texture.height) - 0.5f;
    if (!std::isfinite(x) || !std::isfinite(y))
        return false;
    const float fx = std::floor(x), fy = std::floor(y);
    out.tx = x - fx;
    out.ty = y - fy;
    // The integer part reduced modulo the size: directly when it fits an int (the remainder is
    // exact either way), else reduced first with fmod so that huge uvs cannot overflow.
    // Inside the image (the common case) no division at all.
    auto reduce = [](float f, int n) {
        if (f >= 0.0f && f < float(n))
            return int(f);
        constexpr float kIntSafe = 1073741824.0f; // 2^30
        return wrap(std::abs(f) < kIntSafe ? int(f) % n : int(std::fmod(f, float(n))), n);
    };
    out.x0 = reduce(fx, texture.width);
    out.y0 = reduce(fy, texture.height);
    out.x1 = out.x0 + 1 == texture.width ? 0 : out.x0 + 1;
    out.y1 = out.y0 + 1 == texture.height ? 0 : out.y0 + 1;
    return true;
}

float alphaOf(const Texture& texture, const Footprint& f) {
    const std::array<float, 256>& toFloat = unorm8Table();
    auto texel = [&](int xi, int yi) {
        return toFloat[texture.rgba8[(size_t(yi) * size_t(texture.width) + size_t(xi)) * 4 + 3]];
    };
    const float top = glm::mix(texel(f.x0, f.y0), texel(f.x1, f.y0), f.tx);
    const float bottom = glm::mix(texel(f.x0, f.y1), texel(f.x1, f.y1), f.tx);
    return glm::mix(top, bottom, f.ty);
}

} // namespace

glm::vec4 Texture::sample(glm::vec2 uv) const {
    Footprint f;
    if (!valid() || !footprintOf(*this, uv, f))
        return glm::vec4(1.0f);
    const std::array<float, 256>& toLinear = srgbToLinearTable();
    auto texel = [&](int xi, int yi) {
        const uint8_t* p = &rgba8[(size_t(yi) * width + xi) * 4];
        if (srgb)
            return glm::vec3(toLinear[p[0]], toLinear[p[1]], toLinear[p[2]]);
        return glm::vec3(p[0], p[1], p[2]) / 255.0f;
    };
    const glm::vec3 top = glm::mix(texel(f.x0, f.y0), texel(f.x1, f.y0), f.tx);
    const glm::vec3 bottom = glm::mix(texel(f.x0, f.y1), texel(f.x1, f.y1), f.tx);
    return glm::vec4(glm::mix(top, bottom, f.ty), alphaOf(*this, f));
}

float sampleAlpha(const Texture& texture, glm::vec2 uv) {
    Footprint f;
    if (!texture.valid() || !footprintOf(texture, uv, f))
        return 1.0f;
    return alphaOf(texture, f);
}

} // namespace scenes
