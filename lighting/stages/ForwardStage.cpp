// `forward`: single-pass, many-light forward shading. Per object (a scene instance) the lights
// whose conservative view-space sphere touches the object's view-space box are listed once per
// frame ("cull", ascending indices); the scene is then rasterized once ("shading") and every
// fragment that passes the depth test is shaded with its object's whole list, overwriting the
// pixel. Overdraw is real cost: lightsEvaluated adds the list length of EVERY shaded fragment, so
// it is at least the visible fragment's count.
//
// Options:
//   prepass=0|1 (default 0): 1 draws a depth-only pre-pass first ("prepass": the visibility draw,
//     gbuffer/VisibilityPass.h), then shades with a depth-equal test (closer-or-equal plus the
//     pre-pass's visible triangle, VisibilityPass::redrawState), so each pixel is shaded once and
//     overdraw disappears.
//
// Exactness: the visible fragment's surface and position are computed by the G-buffer's own
// functions (ForwardGeometry.h) and lights are summed in ascending order, so the image is bitwise
// `brute`'s. Reads no G-buffer channel: it rasterizes the scene itself (inputs.scene, .geometry).
// Deterministic: one draw, each pixel written only by the thread owning its tile, in submission
// order.
//
// Shading stays scalar (not lighting/LightAccumulation.h): it shades rasterized fragments as they
// are drawn, not 4x4 packets decoded from a G-buffer.
#include "lighting/StageRegistry.h"

#include <tbb/parallel_for.h>

#include "lighting/BlendedPass.h"
#include "lighting/ForwardGeometry.h"
#include "lighting/LightBounds.h"
#include "lighting/LightListShading.h"
#include "lighting/PassNames.h"

namespace lighting {

namespace {

class ForwardStage final : public ShadingStage {
public:
    explicit ForwardStage(bool prepass) : mPrepass(prepass) {}

    std::string name() const override { return "forward"; }
    StageRequirements requirements() const override { return {{}, false}; }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::CameraView& view = *inputs.view;
        const int width = view.width;
        result.resize(width, view.height, false);
        result.parameters["prepass"] = mPrepass ? "1" : "0";

        mForward.prepare(inputs, result);
        {
            PassTimer cull(result, pass::kCull);
            mForward.objectLightLists(boundingSpheresView(*inputs.lights), mObjectLights);
        }

        const gbuffer::VisibilityPass& visibility = mForward.visibility();
        if (mPrepass)
            mForward.drawDepthPrepass(result);
        else
            mForward.clearDepth();

        PassTimer shading(result, pass::kShading);
        const std::vector<LightInView<float>>& lights = inputs.lights->lights;
        const bool equalOnly = mPrepass;
        auto shadeFragment = [&](const raster::Fragment& fragment) {
            const size_t pixel = size_t(fragment.y) * width + fragment.x;
            if (equalOnly && !visibility.isVisible(fragment, fragment.triangle))
                return;
            // Overdraw: the pixel's radiance is replaced, its evaluations add up.
            const uint32_t evaluatedBefore = result.lightsEvaluated[pixel];
            shadeWithLightList(mForward.surfaceAt(fragment, fragment.triangle), pixel, lights,
                               mObjectLights[mForward.objectOfTriangle(fragment.triangle)], result);
            result.lightsEvaluated[pixel] += evaluatedBefore;
        };
        // Without a pre-pass, the visibility draw's own state (every fragment that passes the
        // closer test is shaded); with one, the redraw that passes each visible fragment once.
        mForward.draw(visibility.triangles(),
                      mPrepass ? visibility.redrawState() : visibility.drawState(), shadeFragment);
        shading.stop();
        // Blended surfaces: each fragment with its object's list.
        mForward.shadeBlended(inputs, mBlended, mObjectLights, result);
    }

private:
    bool mPrepass;
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
    ForwardGeometry mForward;
    LightIndexLists mObjectLights; // per object, ascending (ForwardGeometry::objectLightLists)
};

const StageRegistrar kRegistrar(
    {.name = "forward",
     .description = "single-pass forward, per-object light lists",
     .kind = StageKind::Exact,
     .options = {StageOption::boolean(
         "prepass", false, "depth-only pre-pass first, then shade each pixel once (no overdraw)")},
     .listOrder = 80},
    [](const StageOptions& options) {
        return std::make_unique<ForwardStage>(options.boolean("prepass"));
    });

} // namespace

} // namespace lighting
