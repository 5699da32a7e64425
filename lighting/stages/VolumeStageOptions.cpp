#include "lighting/stages/VolumeStageOptions.h"

#include "lighting/passes/PassNames.h"

namespace lighting {

std::vector<StageOption> volumeStageOptionTable() {
    return {
        StageOption::choice("volume", {"sphere", "rect"},
                            "light volume: back faces of a bounding icosphere, or the "
                            "sphere's screen rectangle"),
        StageOption::choice("spot", {"cone", "sphere"},
                            "volume=sphere only: a spot light's pyramid proxy when smaller "
                            "than its sphere, or always the sphere"),
        StageOption::boolean("stencil", false,
                             "also require the surface not in front of the volume's front "
                             "face (two draws per light)"),
        StageOption::boolean("vfc", true, "cull light spheres against the camera frustum first")};
}

VolumeStageOptions volumeStageOptions(const StageOptions& table) {
    VolumeStageOptions options;
    options.shape = table.text("volume") == "sphere" ? VolumeShape::Sphere : VolumeShape::Rect;
    if (options.shape == VolumeShape::Rect && table.given("spot"))
        throw StageError("stage '" + table.stageName() +
                         "': option spot applies to volume=sphere only");
    options.spotProxy = table.text("spot") == "cone" ? SpotProxy::Cone : SpotProxy::Sphere;
    options.stencil = table.boolean("stencil");
    options.frustumCull = table.boolean("vfc");
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
