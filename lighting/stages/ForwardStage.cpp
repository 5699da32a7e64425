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
#include "lighting/stages/Stages.h"

#include <chrono>

#include <tbb/parallel_for.h>

#include "lighting/ForwardGeometry.h"
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

        auto start = std::chrono::steady_clock::now();
        mForward.prepare(inputs);
        result.timingsMs.emplace_back(pass::kTransform, millisecondsSince(start));

        start = std::chrono::steady_clock::now();
        buildObjectLightLists(*inputs.lights);
        result.timingsMs.emplace_back(pass::kCull, millisecondsSince(start));

        const gbuffer::VisibilityPass& visibility = mForward.visibility();
        if (mPrepass) {
            start = std::chrono::steady_clock::now();
            mForward.drawDepthPrepass();
            result.timingsMs.emplace_back(pass::kPrepass, millisecondsSince(start));
        } else {
            mForward.clearDepth();
        }

        start = std::chrono::steady_clock::now();
        const std::vector<LightInView<float>>& lights = inputs.lights->lights;
        const bool equalOnly = mPrepass;
        auto shadeFragment = [&](const raster::Fragment& fragment) {
            const size_t pixel = size_t(fragment.y) * width + fragment.x;
            if (equalOnly && !visibility.isVisible(fragment, fragment.triangle))
                return;
            const uint32_t object = mForward.objectOfTriangle(fragment.triangle);
            const uint32_t* index = mLightIndices.data() + mLightOffsets[object];
            const uint32_t* end = mLightIndices.data() + mLightOffsets[object + 1];
            const gbuffer::Surface point = mForward.surfaceAt(fragment, fragment.triangle);
            const glm::vec3 toViewer = glm::normalize(-point.positionView);
            glm::vec3 sum(0.0f);
            for (; index != end; ++index)
                sum += evaluateLight(point, toViewer, lights[*index]);
            sum += point.emissive; // once per shaded fragment; the pixel keeps the visible one
            result.radiance[0][pixel] = sum.x;
            result.radiance[1][pixel] = sum.y;
            result.radiance[2][pixel] = sum.z;
            result.lightsEvaluated[pixel] += mLightOffsets[object + 1] - mLightOffsets[object];
            result.traceLightList(pixel, {mLightIndices.data() + mLightOffsets[object],
                                          mLightIndices.data() + mLightOffsets[object + 1]});
        };
        // Without a pre-pass, the visibility draw's own state (every fragment that passes the
        // closer test is shaded); with one, the redraw that passes each visible fragment once.
        mForward.draw(visibility.triangles(),
                      mPrepass ? visibility.redrawState() : visibility.drawState(), shadeFragment);
        result.timingsMs.emplace_back(pass::kShading, millisecondsSince(start));
    }

private:
    // Per object, the lights whose sphere touches its box, ascending; flattened so the fragment
    // loop reads one contiguous range. Objects in parallel, each into its own list, then
    // concatenated in object order (deterministic).
    void buildObjectLightLists(const LightList& lightList) {
        const std::vector<LightSphere> spheres = boundingSpheresView(lightList);
        const std::vector<ForwardObject>& objects = mForward.objects();
        mPerObject.resize(objects.size());
        tbb::parallel_for(size_t(0), objects.size(), [&](size_t o) {
            std::vector<uint32_t>& list = mPerObject[o];
            list.clear();
            for (uint32_t l = 0; l < spheres.size(); ++l)
                if (sphereTouchesObject(spheres[l], objects[o]))
                    list.push_back(l);
        });
        mLightOffsets.assign(objects.size() + 1, 0);
        for (size_t o = 0; o < objects.size(); ++o)
            mLightOffsets[o + 1] = mLightOffsets[o] + uint32_t(mPerObject[o].size());
        mLightIndices.resize(mLightOffsets.back());
        for (size_t o = 0; o < objects.size(); ++o)
            std::copy(mPerObject[o].begin(), mPerObject[o].end(),
                      mLightIndices.begin() + mLightOffsets[o]);
    }

    bool mPrepass;
    ForwardGeometry mForward;
    std::vector<std::vector<uint32_t>> mPerObject;
    std::vector<uint32_t> mLightOffsets;
    std::vector<uint32_t> mLightIndices;
};

} // namespace

std::unique_ptr<ShadingStage> makeForwardStage(const StageSpec& spec) {
    rejectUnknownOptions(spec, {"prepass"});
    return std::make_unique<ForwardStage>(intOption(spec, "prepass", 0, 0, 1) != 0);
}

} // namespace lighting
