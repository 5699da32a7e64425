#include "lighting/PreparedScene.h"

#include "gbuffer/LayoutDerivation.h"

namespace lighting {

namespace {

// GBufferLayout::reference() and lossless() know no scene: they get the scene's material table
// and what its metallic-roughness materials need (model, roughness and metallic in float32), and
// its emission.
gbuffer::GBufferLayout withSceneMaterials(gbuffer::GBufferLayout layout,
                                          const scenes::Scene& scene) {
    if (!layout.materials.empty())
        return layout;
    layout.materials = gbuffer::materialTable(scene);
    gbuffer::addMaterialModels(layout, scene, layout.provides(gbuffer::Channel::Specular), false);
    gbuffer::addEmission(layout, scene, true);
    return layout;
}

} // namespace

PreparedScene::PreparedScene(scenes::Scene sceneIn, int width, int height, bool withExactSurface,
                             const gbuffer::GBufferLayout& layout,
                             const Multisampling& multisampling)
    : scene(std::move(sceneIn)) {
    if (multisampling.samples > 1) {
        multisample = std::make_unique<gbuffer::MultisampleTarget>();
        multisample->samples = multisampling.samples;
        multisample->options = multisampling.layers;
        multisample->alphaToCoverage = multisampling.alphaToCoverage;
    }
    geometry = gbuffer::SceneGeometry::build(scene);
    view = gbuffer::CameraView::fromCamera(scene.cameras.front(), width, height,
                                           layout.depth.convention(), layout.depth.infiniteFar);
    gbuffer = std::make_unique<gbuffer::GBuffer>(withSceneMaterials(layout, scene), view);
    if (withExactSurface)
        exact = std::make_unique<gbuffer::ExactSurface>();
    mRasterizer = std::make_unique<raster::Rasterizer>(width, height);
    mPass = std::make_unique<gbuffer::GBufferPass>(scene, geometry);
    renderGBuffer();
    setLights(scene.lights);
    inputs.scene = &scene;
    inputs.geometry = &geometry;
    inputs.view = &view;
    inputs.gbuffer = gbuffer.get();
    inputs.exact = exact.get();
    inputs.lights = &lights;
    inputs.samples = multisample ? multisampling.samples : 1;
    inputs.fragmentLayers = multisample ? &multisample->layers : nullptr;
    inputs.sampleDepths = multisample ? &multisample->sampleDepth : nullptr;
    inputs.alphaToCoverage = multisample && multisampling.alphaToCoverage;
}

PreparedScene::PreparedScene(scenes::Scene sceneIn, int width, int height, bool withExactSurface,
                             gbuffer::DepthConvention depth)
    : PreparedScene(std::move(sceneIn), width, height, withExactSurface,
                    gbuffer::GBufferLayout::lossless(depth)) {}

void PreparedScene::renderGBuffer() {
    gbufferTimings = mPass->render(*mRasterizer, *gbuffer, exact.get(), multisample.get());
    rasterStats = mRasterizer->lastStats();
    exactSurfacePasses += exact ? 1 : 0;
}

void PreparedScene::addExactSurface() {
    if (exact)
        return;
    exact = std::make_unique<gbuffer::ExactSurface>();
    mPass->render(*mRasterizer, *gbuffer, exact.get(), multisample.get());
    ++exactSurfacePasses;
    inputs.exact = exact.get();
}

std::unique_ptr<gbuffer::GBuffer> PreparedScene::renderLosslessGBuffer() {
    auto lossless = std::make_unique<gbuffer::GBuffer>(
        withSceneMaterials(gbuffer::GBufferLayout::lossless(view.depthConvention, view.infiniteFar),
                           scene),
        view);
    mPass->render(*mRasterizer, *lossless, nullptr);
    // A visibility-buffer frame fetches its surfaces from the pass, which has just prepared
    // another frame (the same view, but its reads check the frame): draw the frame's own again.
    if (gbuffer->layout().visibilityBuffer)
        mPass->render(*mRasterizer, *gbuffer, exact.get(), multisample.get());
    return lossless;
}

void PreparedScene::setPixelOffset(glm::dvec2 pixelOffset) {
    view = gbuffer::CameraView::fromCamera(scene.cameras.front(), view.width, view.height,
                                           view.depthConvention, view.infiniteFar, pixelOffset);
    gbuffer = std::make_unique<gbuffer::GBuffer>(gbuffer->layout(), view);
    inputs.gbuffer = gbuffer.get();
    renderGBuffer();
    setLights(scene.lights);
}

void PreparedScene::setLights(const std::vector<scenes::Light>& sceneLights) {
    if (&sceneLights != &scene.lights)
        scene.lights = sceneLights;
    lights = LightList::build(scene.lights, view);
}

} // namespace lighting
