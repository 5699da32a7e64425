// `forward`: single-pass, many-light forward shading. Per object (a scene instance) the lights
// whose conservative view-space sphere touches the object's view-space box are listed once per
// frame ("cull", ascending indices); the scene is then rasterized once ("shading") and every
// fragment that passes the depth test is shaded with its object's whole list, overwriting the
// pixel. Overdraw is real cost: lightsEvaluated adds the list length of EVERY shaded fragment, so
// it is at least the visible fragment's count.
//
// Options:
//   prepass=0|1 (default 0): 1 draws a depth-only pre-pass first ("prepass": the visibility draw,
//     gbuffer/visibility/VisibilityPass.h), then shades with a depth-equal test (closer-or-equal
//     plus the pre-pass's visible triangle, VisibilityPass::redrawState), so each pixel is shaded
//     once and overdraw disappears.
//
// Shading on the light kernel (FragmentShading.h): the draw queues each fragment with its
// object's list; 16 consecutive fragments of a raster tile form a packet the kernel shades on
// inputs.isa, and the results replace the pixels in fragment order (FragmentApply::Replace), so
// the last fragment drawn at a pixel is the one it keeps, as when each was shaded as drawn.
// Records "isa" (what ran) and the SIMT counters (one warp = 32 or 64 consecutive fragments).
//
// Multisampling (inputs.samples > 1, hardware-style MSAA, ForwardGeometry.h): the draws run at
// the frame's sample count over a per-sample depth plane; a fragment is shaded once, at the pixel
// centre, and replaces the samples it covers and passes (with the pre-pass: the samples whose
// pre-pass code is its triangle, so each visible (pixel, triangle) is shaded exactly once: the
// fragments of the G-buffer's fragment layers with primitive detection); the samples are
// averaged at the end ("resolve"). A fragment is shaded at the pixel centre, extrapolated beyond
// its triangle when only off-centre samples are covered, so its object's box must hold it: with
// the pre-pass the boxes are grown to every sample's shading position before the lists are built
// (ForwardGeometry::boundShadedSamples, in "cull"); without one, a fragment shaded outside its
// object's box takes every light. lightsEvaluated counts once per shaded fragment; the light
// trace of a pixel is the union of the lists of the fragments its samples kept. Records
// "shaded_fragments" (opaque fragments shaded, overdraw included).
//
// Exactness: the visible fragment's surface and position are computed by the G-buffer's own
// functions (ForwardGeometry.h) and lights are summed in ascending order with the kernel's
// arithmetic, so the image is bitwise `brute`'s on the same ISA (`--isa scalar`: evaluateLight per
// fragment, the image of the scalar loop). Reads no G-buffer channel: it rasterizes the scene
// itself (inputs.scene, .geometry). Deterministic: one draw, each pixel written only by the task
// owning its raster tile, in submission order (FragmentShading.h).
#include "lighting/StageRegistry.h"

#include <numeric>
#include <string>

#include "lighting/culling/LightBounds.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/ForwardGeometry.h"
#include "lighting/passes/FragmentShading.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

class ForwardStage final : public ShadingStage {
public:
    explicit ForwardStage(bool prepass) : mPrepass(prepass) {}

    std::string name() const override { return "forward"; }
    StageRequirements requirements() const override { return {{}, false}; }

    void shade(const StageInputs& inputs, StageResult& result) override {
        mForward.beginFrame(inputs, result, mPrepass);
        result.parameters["prepass"] = mPrepass ? "1" : "0";
        {
            PassTimer cull(result, pass::kCull);
            if (mPrepass)
                mForward.boundShadedSamples();
            mForward.objectLightLists(boundingSpheresView(*inputs.lights), mObjectLights);
        }

        PassTimer shading(result, pass::kShading);
        const gbuffer::VisibilityPass& visibility = mForward.visibility();
        if (mEveryLight.size() != inputs.lights->size()) {
            mEveryLight.resize(inputs.lights->size());
            std::iota(mEveryLight.begin(), mEveryLight.end(), 0u);
        }
        mShading.begin(inputs, FragmentApply::Replace, result, mForward.sampleTarget());
        const bool equalOnly = mPrepass;
        const bool multisampled = mForward.samples() > 1;
        auto shadeFragment = [&](const raster::Fragment& drawn) {
            raster::Fragment fragment = drawn;
            if (multisampled) {
                // The samples it writes: those that show it after the pre-pass, else every
                // sample it passed (a later, closer fragment replaces them again).
                if (equalOnly)
                    fragment.coverage = visibility.visibleCoverage(drawn, drawn.triangle);
                else
                    mForward.noteShaded(drawn, drawn.coverage);
                if (fragment.coverage == 0)
                    return;
            } else if (equalOnly && !visibility.isVisible(fragment, fragment.triangle)) {
                return;
            }
            const uint32_t object = mForward.objectOfTriangle(fragment.triangle);
            const gbuffer::Surface surface = mForward.surfaceAt(fragment, fragment.triangle);
            // Without a pre-pass the boxes could not be grown to the extrapolated centres: a
            // fragment shaded outside its object's box takes every light (conservative).
            if (multisampled && !equalOnly && !mForward.insideBounds(object, surface.positionView))
                mShading.add(fragment, fragment.triangle, surface, kEveryLightKey, mEveryLight);
            else
                mShading.add(fragment, fragment.triangle, surface, object, mObjectLights[object]);
        };
        // Without a pre-pass, the visibility draw's own state (every fragment that passes the
        // closer test is shaded); with one, the redraw that passes each visible fragment once.
        mForward.draw(visibility.triangles(),
                      mPrepass ? visibility.redrawState() : visibility.drawState(), shadeFragment);
        mShading.flush();
        mShading.end();
        result.parameters["shaded_fragments"] = std::to_string(mShading.fragmentCount());
        shading.stop();
        // Blended surfaces: each fragment with its object's list.
        mForward.shadeBlended(inputs, mBlended, mObjectLights, result);
        mForward.endFrame(result);
    }
    bool multisamplesNatively() const override { return true; }

private:
    bool mPrepass;
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
    ForwardGeometry mForward;
    FragmentShading mShading;
    LightIndexLists mObjectLights;     // per object, ascending (ForwardGeometry::objectLightLists)
    std::vector<uint32_t> mEveryLight; // 0 .. lightCount - 1: the fallback list
    // The fallback list's key (FragmentShading::add): above every object index, below 2^63.
    static constexpr uint64_t kEveryLightKey = (uint64_t(1) << 62);
};

const StageRegistrar kRegistrar(
    {.name = "forward",
     .description = "single-pass forward, per-object light lists",
     .kind = StageKind::Exact,
     .options = {StageOption::boolean(
         "prepass", false, "depth-only pre-pass first, then shade each pixel once (no overdraw)")},
     .listOrder = 80,
     .msaaNative = true},
    [](const StageOptions& options) {
        return std::make_unique<ForwardStage>(options.boolean("prepass"));
    });

} // namespace

} // namespace lighting
