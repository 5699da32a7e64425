// `forward-multipass`: multi-pass, multi-light forward shading with illumination sets (Hargreaves
// & Harris 2004; O'Rorke 2004). A depth pre-pass ("prepass") lays down depth and the visible
// triangle; per light, in ascending index order, its illumination set (the objects whose
// view-space box its conservative sphere touches, "cull") is drawn again with a depth-equal test
// and each visible fragment evaluates that one light and ADDS it to the pixel ("shading").
// Directional and ambient lights are unbounded: drawn over every object.
//
// Options: none.
//
// Why the pre-pass is mandatory: additive passes without an equal test would add the light once
// per overdrawn fragment. The equal test is closer-or-equal plus the pre-pass's visible triangle
// (gbuffer/visibility/VisibilityPass.h redrawState), so exact depth ties never add a light twice.
//
// Shading on the light kernel (FragmentShading.h): each light pass queues its visible fragments;
// 16 consecutive fragments of a raster tile form a packet the kernel shades with the pass's one
// light on inputs.isa, and each result is ADDED to its pixel (FragmentApply::Add). Every pass is
// flushed before the next one starts, so a pixel still receives its lights in ascending order.
// Records "isa" (what ran) and the SIMT counters (one warp = 32 or 64 consecutive visible
// fragments of one pass, paying its one light).
//
// Multisampling (inputs.samples > 1, hardware-style MSAA, ForwardGeometry.h): the pre-pass and
// the light passes run at the frame's sample count; a light pass shades each visible fragment
// once and adds its light to the samples whose pre-pass code is its triangle; the emission is
// added per sample; the samples are averaged at the end ("resolve"). The object boxes the
// illumination sets come from are grown to the samples' shading positions first
// (ForwardGeometry::boundShadedSamples: extrapolated pixel centres), timed in "cull".
//
// Exactness: the fragment's surface and position are the G-buffer's own (ForwardGeometry.h), and
// per pixel the lights are added in ascending order starting from zero, the same sequence of
// float additions as `brute` on the same ISA minus lights that add exactly zero, so the image is
// bitwise brute's. lightsEvaluated counts one per (light, visible fragment) drawn. Reads no
// G-buffer channel. Deterministic: draws run one after another; within a draw each pixel is
// written only by the task owning its raster tile.
#include "lighting/StageRegistry.h"

#include "lighting/culling/LightBounds.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/ForwardGeometry.h"
#include "lighting/passes/FragmentShading.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

class ForwardMultipassStage final : public ShadingStage {
public:
    std::string name() const override { return "forward-multipass"; }
    StageRequirements requirements() const override { return {{}, false}; }

    void shade(const StageInputs& inputs, StageResult& result) override {
        mForward.beginFrame(inputs, result, true);

        PassTimer cull(result, pass::kCull);
        mForward.boundShadedSamples();
        mForward.objectLightLists(boundingSpheresView(*inputs.lights), mObjectLights);
        mSets = mObjectLights.transposed(inputs.lights->size());
        cull.stop();

        PassTimer shading(result, pass::kShading);
        const size_t lightCount = inputs.lights->size();
        mShading.begin(inputs, FragmentApply::Add, result, mForward.sampleTarget());
        const bool multisampled = mForward.samples() > 1;
        const std::vector<ForwardObject>& objects = mForward.objects();
        const std::vector<uint32_t>& allIndices = inputs.geometry->indices;
        const gbuffer::VisibilityPass& visibility = mForward.visibility();
        const raster::RasterState state = visibility.redrawState();
        for (uint32_t l = 0; l < lightCount; ++l) {
            const std::span<const uint32_t> set = mSets[l];
            if (set.empty())
                continue;
            // The set's triangles as one list; globalTriangle maps a drawn triangle back to the
            // scene's (null: the whole scene, drawn as is).
            const uint32_t* globalTriangle = nullptr;
            std::span<const uint32_t> indices = allIndices;
            if (set.size() != objects.size()) {
                mSetIndices.clear();
                mSetTriangles.clear();
                for (uint32_t o : set) {
                    const ForwardObject& object = objects[o];
                    const auto first = allIndices.begin() + 3 * size_t(object.firstTriangle);
                    mSetIndices.insert(mSetIndices.end(), first,
                                       first + 3 * size_t(object.triangleCount));
                    for (uint32_t t = 0; t < object.triangleCount; ++t)
                        mSetTriangles.push_back(object.firstTriangle + t);
                }
                indices = mSetIndices;
                globalTriangle = mSetTriangles.data();
            }
            const uint32_t light[1] = {l}; // the pass's list, alive until its flush
            auto addLight = [&](const raster::Fragment& drawn) {
                const uint32_t triangle =
                    globalTriangle ? globalTriangle[drawn.triangle] : drawn.triangle;
                raster::Fragment fragment = drawn;
                if (multisampled)
                    fragment.coverage = visibility.visibleCoverage(drawn, triangle);
                if (multisampled ? fragment.coverage == 0 : !visibility.isVisible(drawn, triangle))
                    return;
                // Outside the light's range it adds exactly zero: queued for its lane and its
                // count, without decoding its surface (FragmentShading::addBeyondRange).
                if (mShading.beyondRange(l, mForward.positionAt(fragment)))
                    mShading.addBeyondRange(fragment, triangle, l, light);
                else
                    mShading.add(fragment, triangle, mForward.surfaceAt(fragment, triangle), l,
                                 light);
            };
            mForward.draw(
                raster::TriangleList{visibility.clipPositions(), indices}, state, addLight,
                [&](uint32_t drawn) { return globalTriangle ? globalTriangle[drawn] : drawn; });
            mShading.flush();
        }
        mShading.end();
        mForward.addEmission(result);
        shading.stop();
        // Blended surfaces: each fragment with its object's lights (the lists the
        // illumination sets were transposed from: ascending per object). "Over" does not
        // distribute over one additive pass per light, so the blended layers are shaded whole.
        mForward.shadeBlended(inputs, mBlended, mObjectLights, result);
        mForward.endFrame(result);
    }
    bool multisamplesNatively() const override { return true; }

private:
    ForwardGeometry mForward;
    FragmentShading mShading;
    LightIndexLists mObjectLights; // per object, the lights touching it, ascending
    LightIndexLists mSets;         // per light, the objects it touches, ascending (transposed)
    std::vector<uint32_t> mSetIndices;
    std::vector<uint32_t> mSetTriangles;
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
};

const StageRegistrar
    kRegistrar({.name = "forward-multipass",
                .description = "one additive pass per light over its illumination set",
                .kind = StageKind::Exact,
                .options = {}, // none
                .listOrder = 90,
                .msaaNative = true},
               [](const StageOptions&) { return std::make_unique<ForwardMultipassStage>(); });

} // namespace

} // namespace lighting
