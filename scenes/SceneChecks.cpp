// SceneChecks: the rules of SceneChecks.h and validate(const Scene&) (Scene.h), which applies
// them to every element of a scene. Messages name the element; the loaders name fields.
#include "scenes/SceneChecks.h"

#include <cmath>
#include <limits>
#include <utility>

#include "scenes/input/FloatRange.h"
#include "scenes/input/Limits.h"

namespace scenes {

namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

const char* axisName(int axis) {
    return axis == 0 ? "x" : axis == 1 ? "y" : "z";
}

std::string limitText(double limit) {
    return numberText(limit);
}

// "" when a point's coordinates, computed in double, are within the coordinate limit.
std::string pointProblem(const glm::dvec3& point) {
    for (int axis = 0; axis < 3; ++axis) {
        if (std::isnan(point[axis]))
            return std::string(axisName(axis)) + " is NaN";
        if (!(std::abs(point[axis]) <= limits::kMaxCoordinateMetres))
            return std::string(axisName(axis)) + " = " + numberText(point[axis]) +
                   " m, beyond the limit of +-" + limitText(limits::kMaxCoordinateMetres) + " m";
    }
    return "";
}

// The uv rectangle of a uv set (empty: the mesh has none, sampled at (0, 0)).
struct UvBounds {
    glm::vec2 min{std::numeric_limits<float>::max()};
    glm::vec2 max{-std::numeric_limits<float>::max()};
};

UvBounds uvBoundsOf(const std::vector<glm::vec2>& uvs) {
    UvBounds bounds;
    if (uvs.empty())
        bounds.min = bounds.max = glm::vec2(0.0f);
    for (const glm::vec2& uv : uvs) {
        bounds.min = glm::min(bounds.min, uv);
        bounds.max = glm::max(bounds.max, uv);
    }
    return bounds;
}

} // namespace

std::string transformProblem(const glm::mat4& worldFromObject) {
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row)
            if (!std::isfinite(worldFromObject[column][row]))
                return "its world transform has a non-finite entry (row " + std::to_string(row) +
                       ", column " + std::to_string(column) + ": " +
                       numberText(worldFromObject[column][row]) +
                       "): the transforms composed overflow float";
    return "";
}

std::string pointProblem(const glm::vec3& pointWorld) {
    return pointProblem(glm::dvec3(pointWorld));
}

std::string lengthProblem(float metres) {
    if (std::isnan(metres) || metres < 0.0f)
        return numberText(metres) + " is not a length >= 0";
    if (!(double(metres) <= limits::kMaxCoordinateMetres))
        return numberText(metres) + " m is beyond the limit of " +
               limitText(limits::kMaxCoordinateMetres) + " m";
    return "";
}

std::string radianceProblem(const glm::vec3& color, float scale) {
    // Computed as the renderer computes it: in float.
    const glm::vec3 radiance = color * scale;
    for (int c = 0; c < 3; ++c)
        if (!(std::abs(radiance[c]) <= float(limits::kMaxRadiance)))
            return "radiance " + numberText(color[c]) + " x " + numberText(scale) + " = " +
                   numberText(double(color[c]) * double(scale)) +
                   " (in float: " + numberText(radiance[c]) + ") is beyond the limit of " +
                   limitText(limits::kMaxRadiance);
    return "";
}

Aabb boundsOf(const Mesh& mesh) {
    Aabb bounds;
    for (const glm::vec3& p : mesh.positions)
        bounds.extend(p);
    return bounds;
}

std::string placedBoundsProblem(const Aabb& boundsObject, const glm::mat4& worldFromObject) {
    if (std::string problem = transformProblem(worldFromObject); !problem.empty())
        return problem;
    if (boundsObject.empty())
        return "";
    // The corners in double: a coordinate past float's range shows as the number it is. Every
    // point of the box lies within the placed corners' extremes (the map is affine).
    const glm::dmat4 transform(worldFromObject);
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p((corner & 1) ? boundsObject.max.x : boundsObject.min.x,
                           (corner & 2) ? boundsObject.max.y : boundsObject.min.y,
                           (corner & 4) ? boundsObject.max.z : boundsObject.min.z);
        const glm::dvec3 placed(transform * glm::dvec4(p, 1.0));
        if (std::string problem = pointProblem(placed); !problem.empty())
            return "placed in the world, a corner of its bounds is at " + problem;
    }
    return "";
}

std::string cameraProblem(const Camera& camera) {
    if (std::string problem = pointProblem(camera.positionWorld); !problem.empty())
        return "position: " + problem;
    auto unit = [](const glm::vec3& v) {
        return finite(v) && std::abs(glm::length(v) - 1.0f) < 1e-3f;
    };
    if (!unit(camera.forwardWorld))
        return "the viewing direction is not a unit vector (a flattened or non-finite transform?)";
    if (!unit(camera.upWorld))
        return "the up direction is not a unit vector (a flattened or non-finite transform?)";
    if (!(glm::length(glm::cross(camera.forwardWorld, camera.upWorld)) >= kMinUpViewSine))
        return "up is parallel to the viewing direction (within 0.057 degrees): the image's "
               "horizontal axis is undefined";
    if (!(camera.nearMetres > 0.0f) || !(camera.farMetres > camera.nearMetres))
        return "need 0 < near < far, got near " + numberText(camera.nearMetres) + " and far " +
               numberText(camera.farMetres);
    if (std::string problem = lengthProblem(camera.farMetres); !problem.empty())
        return "far plane: " + problem;
    if (!(camera.verticalFovRadians > 0.0f && camera.verticalFovRadians < 3.1f))
        return "vertical field of view " + numberText(camera.verticalFovRadians) +
               " rad is outside (0, 3.1)";
    const glm::mat4 viewFromWorld = camera.viewFromWorld();
    for (int column = 0; column < 4; ++column)
        if (!finite(glm::vec3(viewFromWorld[column])))
            return "its view matrix is not finite in float";
    return "";
}

std::string lightProblem(const Light& light) {
    if (light.type == LightType::Point || light.type == LightType::Spot)
        if (std::string problem = pointProblem(light.positionWorld); !problem.empty())
            return "position: " + problem;
    if (light.type == LightType::Spot || light.type == LightType::Directional)
        if (!finite(light.directionWorld) ||
            !(std::abs(glm::length(light.directionWorld) - 1.0f) < 1e-3f))
            return "direction is not a unit vector (a flattened or non-finite transform?)";
    if (!finite(light.color) ||
        !(glm::min(light.color.r, glm::min(light.color.g, light.color.b)) >= 0.0f))
        return "colour is not finite and non-negative";
    if (!(light.intensity >= 0.0f) || !std::isfinite(light.intensity))
        return "intensity is not a finite number >= 0";
    if (std::string problem = radianceProblem(light.color, light.intensity); !problem.empty())
        return problem;
    if (std::string problem = lengthProblem(light.rangeMetres); !problem.empty())
        return "range: " + problem;
    if (light.type == LightType::Spot &&
        !(std::isfinite(light.spotInnerCos) && std::isfinite(light.spotOuterCos)))
        return "spot cone is not finite";
    return "";
}

std::string materialProblem(const Material& material) {
    const glm::vec4& base = material.baseColorFactor;
    if (!finite(glm::vec3(base)) || !std::isfinite(base.a))
        return "base colour is not finite";
    if (std::string problem = radianceProblem(material.emissiveFactor, material.emissiveStrength);
        !problem.empty())
        return "emission: " + problem;
    const std::pair<const char*, float> factors[] = {
        {"normal scale", material.normalScale},
        {"occlusion strength", material.occlusionStrength},
        {"alpha cutoff", material.alphaCutoff},
        {"specular intensity", material.specularIntensity},
        {"specular power", material.specularPower},
        {"metallic", material.metallic},
        {"roughness", material.roughness}};
    for (const auto& [name, value] : factors)
        if (!std::isfinite(value))
            return std::string(name) + " is not finite";
    for (const TextureMapping* mapping : material.textureMappings())
        if (!std::isfinite(mapping->offset.x) || !std::isfinite(mapping->offset.y) ||
            !std::isfinite(mapping->scale.x) || !std::isfinite(mapping->scale.y) ||
            !std::isfinite(mapping->rotationRadians))
            return "a texture transform is not finite";
    return "";
}

void validate(const Scene& scene) {
    auto fail = [&](const std::string& what) { throw SceneError(scene.name + ": " + what); };
    std::vector<Aabb> meshBounds;
    meshBounds.reserve(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const std::string where = "mesh " + std::to_string(m) + " '" + mesh.name + "'";
        if (mesh.indices.size() % 3 != 0)
            fail(where + ": index count is not a multiple of 3");
        if (mesh.normals.size() != mesh.positions.size())
            fail(where + ": " + std::to_string(mesh.normals.size()) + " normals for " +
                 std::to_string(mesh.positions.size()) + " positions");
        if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
            fail(where + ": uv count differs from position count");
        if (!mesh.uvs1.empty() && mesh.uvs1.size() != mesh.positions.size())
            fail(where + ": second uv set's count differs from position count");
        if (!mesh.tangents.empty() && mesh.tangents.size() != mesh.positions.size())
            fail(where + ": tangent count differs from position count");
        for (uint32_t index : mesh.indices)
            if (index >= mesh.positions.size())
                fail(where + ": index " + std::to_string(index) + " out of range (" +
                     std::to_string(mesh.positions.size()) + " vertices)");
        for (const glm::vec3& p : mesh.positions)
            if (!finite(p))
                fail(where + ": position is NaN or infinite");
        for (const glm::vec3& n : mesh.normals)
            if (!finite(n))
                fail(where + ": normal is NaN or infinite");
        if (mesh.material >= scene.materials.size())
            fail(where + ": material " + std::to_string(mesh.material) + " out of range");
        meshBounds.push_back(boundsOf(mesh));
        // A texture transform maps the mesh's uvs; where the result is not finite the sampler
        // has nothing to read (it would return white). Checked on the uv sets' rectangles.
        const Material& material = scene.materials[mesh.material];
        const UvBounds uvSets[2] = {uvBoundsOf(mesh.uvs), uvBoundsOf(mesh.uvs1)};
        for (const TextureMapping* mapping : material.textureMappings()) {
            if (mapping->isIdentity() || mapping->texCoord < 0 || mapping->texCoord > 1)
                continue;
            const UvBounds& uv = uvSets[mapping->texCoord];
            for (const glm::vec2 corner :
                 {uv.min, uv.max, glm::vec2(uv.min.x, uv.max.y), glm::vec2(uv.max.x, uv.min.y)}) {
                const glm::vec2 mapped = mapping->apply(corner);
                if (!std::isfinite(mapped.x) || !std::isfinite(mapped.y))
                    fail(where + ": material '" + material.name +
                         "''s texture transform maps its uvs to infinity");
            }
        }
    }
    for (const Material& material : scene.materials) {
        for (int t : material.textureIndices())
            if (t >= int(scene.textures.size()))
                fail("material '" + material.name + "': texture index out of range");
        for (const TextureMapping* mapping : material.textureMappings())
            if (mapping->texCoord != 0 && mapping->texCoord != 1)
                fail("material '" + material.name + "': texCoord " +
                     std::to_string(mapping->texCoord) + " (only 0 and 1 are kept)");
        if (std::string problem = materialProblem(material); !problem.empty())
            fail("material '" + material.name + "': " + problem);
    }
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& instance = scene.instances[i];
        if (instance.mesh >= scene.meshes.size())
            fail("instance refers to a missing mesh");
        if (std::string problem =
                placedBoundsProblem(meshBounds[instance.mesh], instance.worldFromObject);
            !problem.empty())
            fail("instance " + std::to_string(i) + " (mesh '" + scene.meshes[instance.mesh].name +
                 "'): " + problem);
    }
    if (scene.cameras.empty())
        fail("no camera");
    for (const Camera& camera : scene.cameras)
        if (std::string problem = cameraProblem(camera); !problem.empty())
            fail("camera '" + camera.name + "': " + problem);
    for (size_t i = 0; i < scene.lights.size(); ++i)
        if (std::string problem = lightProblem(scene.lights[i]); !problem.empty())
            fail("light " + std::to_string(i) + ": " + problem);
}

} // namespace scenes
