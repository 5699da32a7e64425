// Texture: an RGBA8 image with bilinear, wrapping lookup. Colour textures are stored as sRGB and
// decoded to linear when sampled; data textures (normal maps) are stored linear.
// Sampling is const and thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace scenes {

struct Texture {
    std::string name; // file name or URI, for messages
    int width = 0;
    int height = 0;
    bool srgb = true;           // true: texels are sRGB-encoded colour
    std::vector<uint8_t> rgba8; // width * height * 4, rows top to bottom

    bool valid() const {
        return width > 0 && height > 0 && rgba8.size() == size_t(width) * height * 4;
    }
    // Bilinear filtered, repeat wrapping, returns linear RGBA in [0,1]. uv (0,0) is the top-left
    // of the image (glTF convention).
    glm::vec4 sample(glm::vec2 uv) const;
};

} // namespace scenes
