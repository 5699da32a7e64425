// SceneLoader: loadScene() routes a scene name or file to its builder (procedural scenes, glTF
// models, JSON scene files) and applies the policy a bare model needs before it can be rendered:
// generated point lights when the file brings none, and a default camera framing the scene when
// the file has none (cameraFramingBounds, also used by the glTF and JSON loaders).
//
// Conventions: those of Scene.h (right-handed, metres, cameras look down -Z). Every error is one
// SceneError whose message starts with the path or name it is about. Not thread-safe to share a
// Scene being loaded; separate loads may run on separate threads.
#include "scenes/SceneLoader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iostream>
#include <system_error>

#include "scenes/input/MessageText.h"
#include "scenes/procedural/LightGenerator.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace scenes {

namespace {

std::string lowercaseExtension(const std::filesystem::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return extension;
}

std::string commaSeparated(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names)
        text += (text.empty() ? "" : ", ") + name;
    return text;
}

} // namespace

Camera cameraFramingBounds(const Aabb& boundsWorld) {
    // 60 degrees: a moderate lens that shows the whole object without strong perspective.
    const float fovYRadians = glm::radians(60.0f);
    const glm::vec3 centre = boundsWorld.empty() ? glm::vec3(0.0f) : boundsWorld.centre();
    // A point-sized or empty scene still gets a usable camera: 1 mm is the smallest radius framed.
    const float radius =
        std::max(boundsWorld.empty() ? 0.0f : 0.5f * glm::length(boundsWorld.size()), 1e-3f);
    // The bounding sphere fills the vertical field of view with a 10% margin.
    const float distance = 1.1f * radius / std::sin(0.5f * fovYRadians);
    // From the front (+Z, where glTF models face) and a little above, so the top shows too.
    const glm::vec3 towardCamera = glm::normalize(glm::vec3(0.0f, 0.3f, 1.0f));

    Camera camera;
    camera.name = "default";
    camera.positionWorld = centre + distance * towardCamera;
    camera.forwardWorld = -towardCamera;
    camera.upWorld = glm::vec3(0.0f, 1.0f, 0.0f);
    camera.verticalFovRadians = fovYRadians;
    // Near and far bracket the bounding sphere with a factor 2 of margin; a near plane as far out
    // as possible keeps depth precision. distance - radius = 1.2 radius > 0.
    camera.nearMetres = 0.5f * (distance - radius);
    camera.farMetres = 2.0f * (distance + radius);
    return camera;
}

Scene loadScene(const std::string& nameOrPath, const SceneRequest& request) {
    if (isProceduralScene(nameOrPath))
        return buildProceduralScene(nameOrPath, request);

    const std::filesystem::path path(nameOrPath);
    const std::string extension = lowercaseExtension(path);
    if (extension == ".json")
        return loadJsonScene(path, request);
    if (extension == ".gltf" || extension == ".glb") {
        if (!request.options.empty())
            throw SceneError(nameOrPath + ": option '" + request.options.begin()->first +
                             "' is not valid: glTF files take no options");
        const int lightCount = request.lightCount.value_or(0);
        if (lightCount < 0)
            throw SceneError(nameOrPath + ": light count must be >= 0, got " +
                             std::to_string(lightCount));
        Scene scene = loadGltf(path);
        const bool fileHasLights = !scene.lights.empty();
        if (!fileHasLights) {
            // A model file brings no lighting of its own: a weak ambient and a key light from
            // above the camera make it visible even without generated lights, as for the
            // built-in scenes (which add one ambient and one directional light too).
            Light ambient;
            ambient.type = LightType::Ambient;
            ambient.color = glm::vec3(1.0f);
            ambient.intensity = 0.05f;
            Light key;
            key.type = LightType::Directional;
            const Camera& camera = scene.cameras.front();
            key.directionWorld = glm::normalize(camera.forwardWorld - 0.8f * camera.upWorld);
            key.color = glm::vec3(1.0f, 0.97f, 0.92f);
            key.intensity = 2.0f;
            scene.lights = {ambient, key};
        }
        if (lightCount > 0 && !fileHasLights) {
            try {
                scatterPointLights(
                    scene,
                    scatterForDensity(defaultScatterFor(scene), request.lightDensity, lightCount),
                    lightCount, request.seed);
            } catch (const SceneError& error) {
                throw SceneError(nameOrPath + ": " + error.what());
            }
        } else if (lightCount > 0) {
            // The file's own lights define the scene; adding random ones would change it.
            const std::string warning = nameOrPath + ": the file has its own lights; the " +
                                        std::to_string(lightCount) +
                                        " requested generated lights were not added";
            std::cerr << "warning: " << escapeControlCharacters(warning) << '\n';
            scene.warnings.push_back(warning);
        }
        validate(scene);
        return scene;
    }

    std::error_code error;
    if (std::filesystem::exists(path, error))
        throw SceneError(nameOrPath + ": unknown scene file type '" + extension +
                         "' (expected .gltf, .glb or .json)");
    throw SceneError("'" + nameOrPath + "' is neither a procedural scene (" +
                     commaSeparated(proceduralSceneNames()) + ") nor a scene file");
}

} // namespace scenes
