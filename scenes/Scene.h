// Scene: the data every other folder reads. Meshes, materials, textures, instances, cameras,
// lights.
//
// Conventions (see ../shared/DESIGN.md): right-handed world space, metres, cameras look down -Z of
// their own view space (glTF's convention). Transforms are named destination-from-source
// (worldFromObject). Colours are linear RGB; sRGB textures are decoded when sampled.
// A Scene is plain data: building it is single-threaded, reading it is thread-safe.
#pragma once

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scenes/LightShadow.h"
#include "scenes/materials/Material.h"
#include "scenes/materials/Texture.h"

namespace scenes {

// Any problem with a scene's input: the message names the file (or scene) and what is wrong.
struct SceneError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct Aabb {
    glm::vec3 min{std::numeric_limits<float>::max()};
    glm::vec3 max{-std::numeric_limits<float>::max()};
    void extend(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void extend(const Aabb& b) {
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }
    bool empty() const { return min.x > max.x; }
    glm::vec3 centre() const { return 0.5f * (min + max); }
    glm::vec3 size() const { return max - min; }
};

// One triangle list with one material. Attributes are per vertex, in object space.
struct Mesh {
    std::string name;
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals; // unit length, same count as positions
    // xyz unit tangent (direction of increasing uv.x), w = +-1: the bitangent
    // w * cross(normal, xyz) points up the image (decreasing uv.y), glTF's convention. From the
    // file, or generated (Tangents.h) for glTF meshes with a normal texture; may be empty.
    std::vector<glm::vec4> tangents;
    std::vector<glm::vec2> uvs;    // TEXCOORD_0; empty when the mesh has no texture coordinates
    std::vector<glm::vec2> uvs1;   // TEXCOORD_1; empty unless a material's texture reads it
    std::vector<uint32_t> indices; // triangle list, 3 per triangle, counter-clockwise = front
    uint32_t material = 0;         // index into Scene::materials

    size_t triangleCount() const { return indices.size() / 3; }
};

struct Instance {
    uint32_t mesh = 0;
    glm::mat4 worldFromObject{1.0f};
};

// The right-handed view matrix of an eye looking along `forward` with `up` (not parallel to it):
// glm::lookAtRH's, built from the basis alone so that it stays exact far from the origin.
glm::dmat4 viewFromBasis(const glm::dvec3& eye, const glm::dvec3& forward, const glm::dvec3& up);

// A pinhole camera. Depth conventions (reversed Z, infinite far) are chosen by the G-buffer
// layout, not here; this only says where the camera is and what it sees.
struct Camera {
    std::string name;
    glm::vec3 positionWorld{0.0f};
    glm::vec3 forwardWorld{0.0f, 0.0f, -1.0f}; // unit
    glm::vec3 upWorld{0.0f, 1.0f, 0.0f};
    float verticalFovRadians = 1.0f;
    float nearMetres = 0.1f;
    float farMetres = 100.0f;

    // The view matrix (lookAt), built in double from the basis; the float one is its rounding.
    glm::dmat4 viewFromWorldExact() const;
    glm::mat4 viewFromWorld() const;
};

enum class LightType { Point, Spot, Directional, Ambient };

// Point and spot lights have finite support: radiance is exactly zero at and beyond rangeMetres.
struct Light {
    LightType type = LightType::Point;
    glm::vec3 positionWorld{0.0f};
    glm::vec3 directionWorld{0.0f, -1.0f, 0.0f}; // spot axis / direction the light travels
    glm::vec3 color{1.0f};                       // linear RGB
    float intensity = 1.0f;
    float rangeMetres = 1.0f;
    float spotInnerCos = 0.9f; // spot: full intensity inside this cosine
    float spotOuterCos = 0.8f; // spot: zero outside this cosine
    // Whether the light gets a shadow map (lighting/shadows): a JSON scene's "castsShadows", true
    // for every glTF punctual light. Ambient lights never cast, whatever this says.
    bool castsShadows = false;
    // Its own shadow map settings, overriding the renderer's global ones (LightShadow.h: a JSON
    // light's "shadow", which requires castsShadows); empty for every other source.
    LightShadow shadow;
};

struct Scene {
    std::string name;
    std::vector<Mesh> meshes;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<Instance> instances;
    std::vector<Camera> cameras; // cameras[0] is the one rendered
    std::vector<Light> lights;
    // How many of `lights` a light generator placed (scatterPointLights: the requested count, a
    // JSON scene's lightGenerator); the others came with the scene (a file's lights, a built-in
    // scene's ambient and sun). For the record of where a render's lights came from.
    int generatedLightCount = 0;
    std::vector<std::string> warnings; // non-fatal problems met while building (missing textures)

    uint64_t triangleCount() const; // over instances
    Aabb boundsWorld() const;       // over instances
};

// Throws SceneError naming the scene and the element when indices are out of range, attributes
// have the wrong count, positions are not finite, or a rule of SceneChecks.h is broken (float
// range of composed transforms, placed bounds, radiance; degenerate cameras). Every builder and
// loader calls it before returning (SceneChecks.cpp).
void validate(const Scene& scene);

} // namespace scenes
