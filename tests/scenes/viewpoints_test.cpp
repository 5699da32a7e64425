// Tests of scenes/Viewpoints.h: choosing a view, unique names, camera paths, and the views the
// built-in scenes carry (every one sees the scene: a render from it covers pixels).
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scenes/SceneLoader.h"
#include "scenes/Viewpoints.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

using scenes::Camera;
using scenes::Scene;

Camera named(const std::string& name) {
    Camera camera;
    camera.name = name;
    return camera;
}

TEST(Viewpoints, SelectViewMovesItFirstAndKeepsTheOthersInOrder) {
    Scene scene;
    scene.name = "test";
    scene.cameras = {named("a"), named("b"), named("c"), named("d")};
    scenes::selectView(scene, "c");
    EXPECT_EQ(scenes::viewNames(scene), (std::vector<std::string>{"c", "a", "b", "d"}));
    scenes::selectView(scene, "c"); // already first: unchanged
    EXPECT_EQ(scenes::viewNames(scene), (std::vector<std::string>{"c", "a", "b", "d"}));
}

TEST(Viewpoints, UnknownViewIsAnErrorListingTheViews) {
    Scene scene;
    scene.name = "test";
    scene.cameras = {named("nave"), named("gallery")};
    try {
        scenes::selectView(scene, "roof");
        ADD_FAILURE() << "no error";
    } catch (const scenes::SceneError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("'roof'"), std::string::npos) << message;
        EXPECT_NE(message.find("nave, gallery"), std::string::npos) << message;
        EXPECT_EQ(message.find("did you mean"), std::string::npos) << message; // nothing close
    }
    try {
        scenes::selectView(scene, "galery");
        ADD_FAILURE() << "no error";
    } catch (const scenes::SceneError& error) {
        EXPECT_NE(std::string(error.what()).find("did you mean 'gallery'?"), std::string::npos)
            << error.what();
    }
}

TEST(Viewpoints, NamesAreMadeUniqueWithoutTakingAnExistingName) {
    std::vector<Camera> cameras = {named("x"), named("x (2)"), named("x"), named(""), named("x")};
    scenes::makeViewNamesUnique(cameras);
    std::vector<std::string> names;
    for (const Camera& camera : cameras)
        names.push_back(camera.name);
    EXPECT_EQ(names, (std::vector<std::string>{"x", "x (2)", "x (3)", "camera 3", "x (4)"}));
}

TEST(Viewpoints, CameraPathPassesThroughEveryKey) {
    std::vector<Camera> keys(3);
    keys[0].positionWorld = {0, 0, 0};
    keys[1].positionWorld = {2, 0, 0};
    keys[2].positionWorld = {2, 4, 0};
    keys[2].verticalFovRadians = 0.5f;
    const std::vector<Camera> path = scenes::cameraPath("fly", keys, 11);
    ASSERT_EQ(path.size(), 11u);
    EXPECT_EQ(path[0].name, "fly/00");
    EXPECT_EQ(path[10].name, "fly/10");
    EXPECT_EQ(path[0].positionWorld, keys[0].positionWorld);
    EXPECT_EQ(path[5].positionWorld, keys[1].positionWorld); // 2 segments, 10 steps
    EXPECT_EQ(path[10].positionWorld, keys[2].positionWorld);
    EXPECT_FLOAT_EQ(path[10].verticalFovRadians, 0.5f);
    EXPECT_NEAR(path[1].positionWorld.x, 0.4f, 1e-6f);
    EXPECT_THROW(scenes::cameraPath("fly", {keys[0]}, 5), scenes::SceneError);
    EXPECT_THROW(scenes::cameraPath("fly", keys, 1), scenes::SceneError);
}

// Every built-in scene has several views with unique names; its first (default) view is the one
// it had before views existed (renders of the default view are unchanged); the other views look
// at the scene: the centre of its bounds is in front of each.
TEST(Viewpoints, BuiltInScenesHaveSeveralViewsOfTheScene) {
    const std::vector<std::pair<std::string, std::string>> firstViews = {
        {"atrium", "nave"}, {"wall", "wall-45"}, {"spheres", "front"}};
    for (const auto& [name, first] : firstViews) {
        scenes::SceneRequest request;
        request.lightCount = 4;
        const Scene scene = scenes::loadScene(name, request);
        const std::vector<std::string> views = scenes::viewNames(scene);
        EXPECT_GE(views.size(), 4u) << name;
        EXPECT_EQ(views.front(), first) << name;
        EXPECT_EQ(std::set<std::string>(views.begin(), views.end()).size(), views.size()) << name;
        const glm::vec3 centre = scene.boundsWorld().centre();
        for (const Camera& camera : scene.cameras) {
            const glm::vec3 toCentre = centre - camera.positionWorld;
            EXPECT_GT(glm::dot(toCentre, camera.forwardWorld), 0.0f) << name << " " << camera.name;
        }
    }
}

} // namespace
