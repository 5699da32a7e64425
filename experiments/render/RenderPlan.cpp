#include "experiments/render/RenderPlan.h"

#include <algorithm>
#include <string>
#include <thread>
#include <vector>

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
    checkOptions(options);         // every input error before the scene is loaded
    checkSceneLoadMemory(options); // a 10^6-node glTF takes a GiB to parse
    return planRenderWithScene(options, loadRequestedScene(options));
}

RenderPlan planRenderWithScene(const RenderOptions& options, scenes::Scene scene) {
    CheckedOptions checked = checkOptions(options);
    RenderPlan plan;
    plan.options = options;
    plan.threads = effectiveThreads(options.threads);
    plan.scene = std::move(scene);
    plan.stage = std::move(checked.stage);
    plan.isa = checked.isa;
    plan.postAa = checked.postAa;
    plan.shadows = checked.shadows;
    plan.requirements = plan.stage->requirements();
    std::vector<gbuffer::Channel> reads = plan.requirements.channels;
    std::vector<gbuffer::Channel> addedByPostAa;
    for (gbuffer::Channel channel : lighting::postaa::requiredChannels(plan.postAa))
        if (std::find(reads.begin(), reads.end(), channel) == reads.end()) {
            reads.push_back(channel);
            addedByPostAa.push_back(channel);
        }
    const std::string postAaName = lighting::postaa::postAaName(plan.postAa);
    const std::string reader = addedByPostAa.empty()
                                   ? plan.stage->name()
                                   : plan.stage->name() + " with --post-aa " + postAaName;
    plan.layout = usageErrorFrom(
        [&] { return gbuffer::makeLayout(plan.scene, reads, reader, checked.layoutRequest); });
    // The derivation says "the stage reads ...": here the filter does, not the stage.
    static const std::string kStageReads = "the stage reads ";
    for (gbuffer::Channel channel : addedByPostAa) {
        std::string& reason = plan.layout.reasons[channel];
        const std::string filterReads = "--post-aa " + postAaName + " (not the stage) reads ";
        reason = reason.rfind(kStageReads, 0) == 0
                     ? filterReads + reason.substr(kStageReads.size())
                     : filterReads + gbuffer::channelName(channel) + ": " + reason;
    }
    plan.memory = estimateRenderMemory(options, plan.scene, plan.layout, plan.requirements);
    return plan;
}

} // namespace experiments
