// TextureAlpha: a texture's alpha alone at a uv, bitwise Texture::sample(uv).a (which computes its
// alpha with this function), for the alpha tests that read nothing else: the shadow maps'
// alpha-tested casters test every covered texel of every face (foliage, 16 cube-mapped lights:
// millions of lookups a frame), and decoding three colour channels they never read would be
// most of their cost. Same conventions as Texture.h (bilinear, repeat wrapping, uv (0,0) the
// image's top-left; 1 for an invalid texture or a non-finite uv). Pure and thread-safe.
#pragma once

#include <glm/glm.hpp>

#include "scenes/materials/Texture.h"

namespace scenes {

float sampleAlpha(const Texture& texture, glm::vec2 uv);

} // namespace scenes
