#include "experiments/render/RenderPlan.h"

#include <algorithm>
#include <thread>

#include "scenes/SceneLoader.h"
#include "scenes/Viewpoints.h"

namespace experiments {

int effectiveThreads(int requested) {
    return requested > 0 ? requested : std::max(1, int(std::thread::hardware_concurrency()));
}

scenes::Scene loadRequestedScene(const RenderOptions& options) {
    scenes::SceneRequest request;
    request.lightCount = requestedLights(options);
    request.seed = options.seed;
    request.lightDensity = options.lightDensity;
    request.options = options.sceneOptions;
    scenes::Scene scene = scenes::loadScene(options.scene, request);
    if (!options.view.empty())
        scenes::selectView(scene, options.view);
    if (options.brdf != "auto") {
        const scenes::MaterialModel model = scenes::parseMaterialModel(options.brdf);
        for (scenes::Material& material : scene.materials)
            scenes::forceMaterialModel(material, model);
    }
    return scene;
}

RenderPlan planRender(const RenderOptions& options) {
    CheckedOptions checked = checkOptions(options);
    RenderPlan plan;
    plan.options = options;
    plan.threads = effectiveThreads(options.threads);
    plan.scene = loadRequestedScene(options);
    plan.stage = std::move(checked.stage);
    plan.isa = checked.isa;
    plan.requirements = plan.stage->requirements();
    plan.layout = usageErrorFrom([&] {
        return gbuffer::makeLayout(plan.scene, plan.requirements.channels, plan.stage->name(),
                                   checked.layoutRequest);
    });
    return plan;
}

} // namespace experiments
