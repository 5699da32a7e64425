#include "lighting/PreparedFrame.h"

namespace lighting {

PreparedFrame::PreparedFrame(scenes::Scene sceneIn, int width, int height, bool withExactSurface,
                             gbuffer::DepthConvention depth)
    : scene(std::move(sceneIn)) {
    geometry = gbuffer::SceneGeometry::build(scene);
    view = gbuffer::FrameView::fromCamera(scene.cameras.front(), width, height, depth);
    gbuffer = std::make_unique<gbuffer::GBuffer>(gbuffer::GBufferLayout::reference(), view);
    if (withExactSurface) exact = std::make_unique<gbuffer::ExactSurface>();
    raster::Rasterizer rasterizer(width, height);
    gbufferTimings = gbuffer::GBufferPass(scene, geometry).render(rasterizer, *gbuffer, exact.get());
    rasterStats = rasterizer.lastStats();
    setLights(scene.lights);
    frame.scene = &scene;
    frame.geometry = &geometry;
    frame.view = &view;
    frame.gbuffer = gbuffer.get();
    frame.exact = exact.get();
    frame.lights = &lights;
}

void PreparedFrame::setLights(const std::vector<scenes::Light>& sceneLights) {
    if (&sceneLights != &scene.lights) scene.lights = sceneLights;
    lights = LightList::build(scene.lights, view);
}

}  // namespace lighting
