#include "lighting/stages/VolumeStageOptions.h"

#include "lighting/PassNames.h"
#include "lighting/stages/Stages.h"

namespace lighting {

VolumeStageOptions parseVolumeStageOptions(const StageSpec& spec) {
    VolumeStageOptions options;
    options.shape = choiceOption(spec, "volume", {"sphere", "rect"}) == "sphere"
                        ? VolumeShape::Sphere
                        : VolumeShape::Rect;
    if (options.shape == VolumeShape::Rect && spec.options.count("spot"))
        throw StageError("stage '" + spec.name + "': option spot applies to volume=sphere only");
    options.spotProxy = choiceOption(spec, "spot", {"cone", "sphere"}) == "cone"
                            ? SpotProxy::Cone
                            : SpotProxy::Sphere;
    options.stencil = boolOption(spec, "stencil", false);
    options.frustumCull = boolOption(spec, "vfc", true);
    return options;
}

VolumeCull cullLightVolumes(const gbuffer::GBuffer& gb, const LightList& lights,
                            const VolumeStageOptions& options, StageResult& result) {
    PassTimer timer(result, pass::kCull);
    VolumeCull cull{boundingSpheresView(lights),
                    LightVolumeRasterizer(gb, options.shape, options.stencil, options.spotProxy),
                    {}};
    cull.drawn = cull.volumes.lightsToDraw(cull.spheres, options.frustumCull);
    timer.stop();
    return cull;
}

void recordVolumeParameters(const VolumeStageOptions& options, size_t culled,
                            const LightVolumeStats& stats,
                            std::map<std::string, std::string>& parameters) {
    parameters["volume"] = options.shape == VolumeShape::Sphere ? "sphere" : "rect";
    if (options.shape == VolumeShape::Sphere)
        parameters["spot"] = options.spotProxy == SpotProxy::Cone ? "cone" : "sphere";
    parameters["stencil"] = options.stencil ? "1" : "0";
    parameters["vfc"] = options.frustumCull ? "1" : "0";
    parameters["lights_culled"] = std::to_string(culled);
    parameters["lights_drawn"] = std::to_string(stats.lightsDrawn);
    parameters["rect_fallbacks"] = std::to_string(stats.rectFallbacks);
    parameters["cone_proxies"] = std::to_string(stats.coneProxies);
    parameters["volume_fragments"] = std::to_string(stats.fragments);
}

} // namespace lighting
