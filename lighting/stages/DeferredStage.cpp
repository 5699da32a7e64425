// `deferred`: traditional deferred shading with light volumes (Ishmukhametov 2013, 1.3 and 3.5;
// Thaler 2011). Lights are processed one after another in ascending light order; each bounded
// light's volume is rasterized over the G-buffer (LightVolumes.h) and, in the fragment function,
// decodes the G-buffer surface, evaluates the light and ADDS it to the pixel. Decoding the
// G-buffer once per light per pixel is the honest bandwidth cost of this technique. Directional
// and ambient lights are full-screen quads at their place in the light order. Emission is added
// once per pixel after the last light (addEmission, LightListShading.h), inside "shading".
//
// Exactness: every pixel receives its lights in ascending index order and skipped lights
// contribute exactly zero, so the image is bitwise equal to `brute`'s. All volumes go through
// one rasterizer draw in light order (LightVolumes.h: the rasterizer keeps submission order per
// tile), parallel over tiles, a pixel written by one task only: deterministic.
//
// Options (defaults first):
//   volume=sphere|rect  sphere: back faces of a circumscribing proxy (icosphere), depth test
//                       "surface not behind the back face"; rect: the sphere's screen rectangle
//   spot=cone|sphere    volume=sphere only: cone draws a spot light's pyramid proxy when it is
//                       smaller than its sphere proxy (LightVolumes.h); sphere always the sphere
//   stencil=0|1         1: also require the surface not in front of the volume's front face
//                       (two draws per light, a per-pixel mark)
//   vfc=1|0             CPU view-frustum culling of light spheres before any rasterizer set-up
// Every volume ends with the depth-bounds test (surface view depth within centre +- radius, and
// within the pyramid's depth range for cones).
// Passes: "cull" (view-frustum culling), "shading" (volume rasterization and shading, interleaved).
//
// Shading stays scalar (evaluateLight per pixel, not lighting/LightAccumulation.h): the stage sums
// light by light over each light volume's pixels, decoding the G-buffer once per light, so there is
// no per-pixel list for a packet to walk; its pass structure is what the stage measures.
#include "lighting/StageRegistry.h"

#include "lighting/BlendedPass.h"
#include "lighting/LightBounds.h"
#include "lighting/LightListShading.h"
#include "lighting/PassNames.h"
#include "lighting/culling/LightVolumes.h"
#include "lighting/stages/VolumeStageOptions.h"

namespace lighting {

namespace {

class DeferredStage final : public ShadingStage {
public:
    explicit DeferredStage(const VolumeStageOptions& volume) : mVolume(volume) {}

    std::string name() const override { return "deferred"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const std::vector<LightInView<float>>& lights = inputs.lights->lights;
        const int width = gb.width(), height = gb.height();
        result.resize(width, height, false);

        VolumeCull cull = cullLightVolumes(gb, *inputs.lights, mVolume, result);
        PassTimer shading(result, pass::kShading);
        float* radiance[3] = {result.radiance[0].data(), result.radiance[1].data(),
                              result.radiance[2].data()};
        uint32_t* evaluated = result.lightsEvaluated.data();
        // Adds one light at one pixel; the pixel belongs to the calling task alone.
        auto addLight = [&](int x, int y, size_t pixel, uint32_t light) {
            gbuffer::Surface point;
            if (!gb.surfaceAt(x, y, point))
                return;
            const glm::vec3 value =
                evaluateLight(point, glm::normalize(-point.positionView), lights[light]);
            radiance[0][pixel] += value.x;
            radiance[1][pixel] += value.y;
            radiance[2][pixel] += value.z;
            ++evaluated[pixel];
            result.traceAddedLight(pixel, light);
        };
        cull.volumes.draw(
            cull.spheres, cull.drawn,
            [&](uint32_t light, int x, int y, size_t pixel) { addLight(x, y, pixel, light); });
        addEmission(gb, result);
        shading.stop();
        // Blended surfaces: every light (light volumes are tested against the opaque depth).
        if (mBlended.prepare(inputs))
            mBlended.shadeWithEveryLight(gb.depth(), result);

        recordVolumeParameters(mVolume, cull.culled(), cull.volumes.stats(), result.parameters);
    }

private:
    VolumeStageOptions mVolume;
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
};

const StageRegistrar kRegistrar(
    {.name = "deferred",
     .description = "traditional deferred: one light volume per light, shaded and added per "
                    "fragment",
     .kind = StageKind::Exact,
     .options = volumeStageOptionTable(),
     .listOrder = 30},
    [](const StageOptions& options) {
        return std::make_unique<DeferredStage>(volumeStageOptions(options));
    });

} // namespace

} // namespace lighting
