// Viewpoints: a scene's named cameras ("views"), how one is chosen for a render, and camera paths.
// A result from one hand-picked camera does not generalise, so every scene carries several
// views: the built-in scenes a few sensible ones each (ProceduralScenes.cpp), a glTF file every
// perspective camera it has (or, without one, the default framing camera and three orbit views of
// its bounds), a JSON scene its `cameras` list and `cameraPath` (scenes/README.md).
//
// Conventions: Scene::cameras[0] is the camera a render uses; choosing a view moves it to the
// front and keeps the others in their order. View names are unique within a scene (the loaders
// make them so: a repeated name gets " (2)", " (3)", ...). Pure functions, thread-safe.
#pragma once

#include <string>
#include <vector>

#include "scenes/Scene.h"

namespace scenes {

// The names of the scene's views, in order (cameras[0] first).
std::vector<std::string> viewNames(const Scene& scene);

// Makes the view `name` the one rendered (cameras[0]); the others follow in their order. Throws
// SceneError naming the valid views when there is no such view.
void selectView(Scene& scene, const std::string& name);

// Renames cameras so that every name is unique: the second "x" becomes "x (2)", and so on. An
// empty name becomes "camera N" (N its index).
void makeViewNamesUnique(std::vector<Camera>& cameras);

// `frames` cameras along a path through the keys (at least 2), evenly spaced in the path's
// parameter: positions and the other numbers are interpolated piecewise linearly between
// consecutive keys (frame 0 is the first key, the last frame the last key), the viewing and up
// directions are normalised linear interpolations (keys must not turn by 180 degrees between
// them). Named "<name>/000", "<name>/001", ... (zero-padded to the width of frames - 1).
std::vector<Camera> cameraPath(const std::string& name, const std::vector<Camera>& keys,
                               int frames);

// Three views orbiting the bounds beside the framing camera `front` (SceneLoader.h's
// cameraFramingBounds): "left" and "right" (90 degrees around the vertical axis through the
// centre) and "above" (looking down from 60 degrees), at the same distance, lens and planes.
// boundsWorld: the geometry's bounds (Scene::boundsWorld before any camera is added).
std::vector<Camera> orbitViews(const Camera& front, const Aabb& boundsWorld);

} // namespace scenes
