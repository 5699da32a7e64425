// Surface: the shading inputs at one surface point, the one struct the G-buffer stores and
// decodes, the visibility pass resolves, the exact surface gives the reference and the lighting
// function (lighting/brdf/Brdf.h evaluateLight) shades with the sample's material model. Templated
// on the scalar type: float everywhere, double for the reference (BasicSurface<double>, from
// gbuffer::ExactSurface).
//
// Conventions: view space right-handed, camera at the origin looking down -Z, metres. The
// defaults are what background pixels hold in every plane (GBuffer::Writer::writeBackground):
// zero position and albedo, normal +Z, no specular, Blinn-Phong.
// Which fields a model reads: Blinn-Phong reads albedo (diffuse colour), specularIntensity and
// specularPower; metallic-roughness reads albedo (base colour), metallic, roughness and occlusion.
// emissive is not read by the lighting function: the stages add it once per pixel.
// normalView is the shading normal: after normal mapping where the material has a normal map.
// A channel a G-buffer layout does not provide decodes to its default (GBuffer::decode). New
// material parameters (e.g. roughness, metallic, emissive) are new fields with a default here,
// a channel in GBufferLayout.h, and a line in the resolve (TriangleCorners.h) and the decoder.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scenes/materials/Material.h"

namespace gbuffer {

template <class T> struct BasicSurface {
    glm::vec<3, T> positionView{T(0)};
    glm::vec<3, T> normalView{T(0), T(0), T(1)}; // unit
    glm::vec<3, T> albedo{T(0)};                 // linear RGB, times the base colour texture
    T specularIntensity = T(0);
    T specularPower = T(1); // Blinn-Phong exponent
    T roughness = T(1);     // metallic-roughness: perceptual, after the texture's G channel
    T metallic = T(0);      // metallic-roughness: after the texture's B channel
    T occlusion = T(1);     // metallic-roughness: ambient occlusion, 1 = none
    // Emitted radiance (linear RGB, either model): emissive factor x strength x texture, added
    // once per pixel after the light sum, never per light.
    glm::vec<3, T> emissive{T(0)};
    scenes::MaterialModel model = scenes::MaterialModel::BlinnPhong;
    uint32_t material = 0; // index into the scene's materials (written, not always stored)
};

using Surface = BasicSurface<float>;

} // namespace gbuffer
