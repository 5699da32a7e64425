// `inferred`: Inferred Lighting (Kircher & Lawrance 2009; Ishmukhametov 2013, section 2.2).
// An APPROXIMATE stage: lighting is computed at reduced resolution and upsampled with
// discontinuity-sensitive filtering (DSF); its error against `reference` is measured.
//
// Passes:
//   "cull"      tiled light culling (culling/TileFrusta.h, widened spheres of LightBounds.h,
//               ascending light indices). Tiles are tile x tile LOW-RES samples, i.e.
//               tile*scale full-res pixels; their bounds come from every full-res pixel of the
//               tile, a superset of its samples, so the lists stay conservative for the samples.
//   "lighting"  the L-buffer at ceil(W/scale) x ceil(H/scale). Low-res sample (i, j) reads the
//               G-buffer pixel (min(i*scale + scale/2, W-1), min(j*scale + scale/2, H-1)) -- the
//               full-res pixel at the sample's location; this stands in for the technique's
//               low-res G-buffer (whose pixel centres would lie between full-res pixels for even
//               scales). It stores diffuse RGB (the BRDF's diffuse part without albedo, plus
//               ambient radiance) and specular RGB (without the specular intensity), both from
//               the one BRDF (lighting/brdf/SplitLighting.h: albedo 1 / intensity 0, then albedo 0
//               / intensity 1; metallic-roughness: diffuse, F0 lobe and Fresnel edge). On the
//               shading kernel: accumulateSplitLights (lighting/passes/LightAccumulation.h) walks
//               the L-buffer in packets of 4x4 SAMPLES (lanes gathered from the G-buffer pixels the
//               samples read, GBuffer::surfaceAt; stippled samples left out), lanes grouped by
//               culling tile, kernel::shadePacketSplit on --isa: `--isa scalar` is the per-sample
//               splitLighting bitwise, a vector ISA differs only in Blinn-Phong specular sums
//               (pow); a layout the packet decoder refuses takes the per-pixel path
//               (stage_parameters.isa = scalar). SIMT counters count warps of 8x4 samples: the
//               light pass a GPU runs at L-buffer resolution. Specular is kept in colour (as
//               Pre-Lighting, Lee 2008, does) so that this stage's error is the resolution alone;
//               `light-prepass` measures the monochromatic-specular approximation separately. With
//               scale=1 the image equals brute's up to float summation order.
//   "material"  the second geometry pass (lighting/passes/MaterialPass.h): the scene is rasterized
//               again with the G-buffer pass's visibility draw, and each visible pixel's albedo
//               and specular intensity come from its triangle's surface. Object IDs (ids=1): a
//               pixel's ID is the scene instance of its visible triangle
//               (SceneGeometry::triangleInstance, MaterialPass::instanceAt); a sample's is
//               the ID of the full-res pixel it read, taken from the same visibility buffer (what
//               the technique writes into its DSF buffer in the geometry pass; ours are 32-bit,
//               so they never wrap as its 8-bit IDs do). The instance is the finest "object" a
//               scene has (a mesh has one material, so per-material-and-instance is the same;
//               per-mesh IDs would merge the copies of a column or arch): on `atrium` the floor,
//               the walls, the gallery slabs, every column, arch and banner are instances of their
//               own; one instance's differently oriented faces (the four walls, a slab's sides) are
//               told apart by the normal test, which stands in for the technique's normal-group
//               IDs. DSF per full-res pixel: the 4 nearest low-res samples with bilinear weights,
//               each weight zeroed when the sample is background, its ID differs from the pixel's,
//               its view depth differs from the pixel's by more than depth * pixel depth, or the
//               cosine between the normals is below `normal`; the weights are renormalised.
//               Fallbacks, in order: when the ID test rejected every sample that depth and normal
//               accept, those samples are used (counted in dsf_id_fallbacks: usually a thin object,
//               or an object no sample lands on, bordered by a coplanar one; its own samples, which
//               failed depth or normal, would light it worse -- measured on `atrium`); when all
//               four fail depth or normal, the nearest covered one of the four is used (zero
//               light if none is covered; counted in dsf_fallbacks). With ids=0 the ID test and
//               its fallback are skipped: the filter without object IDs.
// Options:
//   scale=2      lighting resolution divisor per axis, 1..8
//   depth=0.1    DSF relative view-depth threshold, > 0
//   normal=0.9   DSF minimum normal cosine, -1..1
//   tile=16      culling tile size in low-res samples, 4..128
//   ids=1        DSF object-ID test, 1/0 (on/off)
// G-buffer: depth, normal and specular (only the specular power is read from it; the layout has
// no power-only channel). Parameters record the options, the L-buffer size, dsf_fallbacks and
// dsf_id_fallbacks.
// lightsEvaluated: the tile list size at the full-res pixel each low-res sample reads, zero
// elsewhere, so its sum is the number of light evaluations actually done. lightingSamples marks
// those pixels, so that the oracle is counted over the same samples (culling efficiency at most 1,
// no negative waste); the full-res oracle would count pixels this stage never lights itself.
// Cost note (CPU): the kernel evaluates range, direction and attenuation once per light for both
// sums (before the kernel: two evaluateLight calls per contributing light).
// Blended (glTF BLEND) surfaces: stippled into the L-buffer, lit by the light pass, found again
// through the DSF in the material pass, at most 3 layers (InferredStipple.h); timed as "blend",
// with stipple_fragments, stipple_fallbacks and stipple_unlit among the parameters.
// Multisampling (--msaa N; MultisampleShading.h runs the stage once per fragment layer), as
// Kircher & Lawrance describe it: the L-buffer is the frame's, lit once from layer 0's G-buffer
// (its samples read main fragments); the material pass rasterizes the scene at N samples once
// per frame (MaterialPass.h) and runs the DSF for every fragment of every layer, with that
// fragment's own depth, normal and object ID, centred at the centroid of the samples it covers
// (MaterialPass::coverageCentroid; the pixel centre for a fragment covering the pixel), so an edge
// pixel's far fragment takes the light of its own surface's samples on its own side of the edge
// (at the pixel centre their bilinear weights can all be zero, e.g. at scale=1). On the layers
// above 0 only the material pass and the blended composite run (lightsEvaluated zero there: no
// light is evaluated again). Blended surfaces are stippled against layer 0's depth: a blended
// fragment behind a pixel's main fragment but in front of another of its fragments finds no
// stippled sample of its own and falls back (stipple_fallbacks, stipple_unlit), an approximation
// its error against the reference measures. Threads: tiles in parallel for culling, warp rows of
// samples for lighting, rows for the material pass; every sample and pixel written by one task
// only, light sums in ascending order: deterministic. The stippled samples' light (InferredStipple)
// stays per sample and scalar.
#include "lighting/StageRegistry.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "lighting/culling/LightBounds.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/lists/LightListShading.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/DsfFilter.h"
#include "lighting/passes/InferredStipple.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/MaterialPass.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

struct InferredOptions {
    int scale = 2;
    float depthThreshold = 0.1f;
    float normalThreshold = 0.9f;
    int tileSizeSamples = 16;
    bool objectIds = true;
};

// Object ID of background (no triangle): never equal to a surface's ID.
constexpr uint32_t kNoObject = MaterialPass::kNoInstance;

// One L-buffer sample: the full-res pixel it reads, its surface for DSF, and its light.
struct LightSample {
    bool covered = false;
    float depthMetres = 0.0f;
    glm::vec3 normalView{0.0f, 0.0f, 1.0f};
    SplitLighting light; // diffuse, specular, metallic-roughness Fresnel edge
};

class InferredStage final : public ShadingStage {
public:
    explicit InferredStage(const InferredOptions& options) : mOptions(options) {}

    std::string name() const override { return "inferred"; }
    StageRequirements requirements() const override { return MaterialPass::gbufferRequirements(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const int width = gb.width(), height = gb.height();
        const int scale = mOptions.scale;
        const int lowWidth = (width + scale - 1) / scale, lowHeight = (height + scale - 1) / scale;
        result.resize(width, height, false);
        auto sampleX = [&](int i) { return std::min(i * scale + scale / 2, width - 1); };
        auto sampleY = [&](int j) { return std::min(j * scale + scale / 2, height - 1); };
        // The pixels whose lights this stage evaluates (before any timed pass): the runner counts
        // evaluated and contributing lights there only (StageResult::lightingSamples).
        result.lightingSamples.assign(size_t(width) * height, 0);
        // A multisampled frame's layers above 0 are lit from layer 0's L-buffer (the file comment).
        const bool upperLayer = inputs.fragmentLayer > 0;
        if (upperLayer) {
            if (mSamples.size() != size_t(lowWidth) * lowHeight)
                throw std::logic_error("inferred shades a multisampled frame's layer 0 first");
            PassTimer blendPass(result, pass::kBlend); // the composite only, after "material"
            blendPass.pause();
            if (mFrameBlended)
                mBlended.switchRun(inputs); // this layer's samples
            materialPassOverLBuffer(inputs, lowWidth, lowHeight, mFrameBlended, blendPass, result,
                                    [] {});
            return;
        }
        for (int j = 0; j < lowHeight; ++j)
            for (int i = 0; i < lowWidth; ++i)
                result.lightingSamples[size_t(sampleY(j)) * width + sampleX(i)] = 1;

        // Cull on the full-res grid with tiles of tile*scale pixels: full-res tile (tx, ty) holds
        // exactly the samples of low-res tile (tx, ty), since sample i lies in block i.
        PassTimer cullPass(result, pass::kCull);
        const TileGrid grid = TileGrid::make(width, height, mOptions.tileSizeSamples * scale);
        const std::vector<LightSphere> spheres = boundingSpheresView(*inputs.lights);
        const std::vector<TileSurfaceBounds> bounds = computeTileSurfaceBounds(gb, grid, {});
        buildTileLightLists(gb.view(), grid, bounds, spheres, {}, mTileLights);
        cullPass.stop();

        // Blended surfaces: stippled into the L-buffer's samples (InferredStipple.h); all their
        // work is timed as the pass "blend".
        PassTimer blendPass(result, pass::kBlend); // three spans, recorded after "material"
        const bool blended = mBlended.prepare(inputs);
        if (blended)
            mStipple.stipple(inputs, mBlended, gb.depth(),
                             {width, height, scale, lowWidth, lowHeight});
        blendPass.pause();

        // L-buffer at low resolution.
        PassTimer lightingPass(result, pass::kLighting);
        mSamples.assign(size_t(lowWidth) * lowHeight, LightSample{});
        // Samples holding a stippled blended surface are lit by the stipple's own pass.
        mExcluded.clear();
        if (blended) {
            mExcluded.resize(size_t(lowWidth) * lowHeight);
            for (size_t index = 0; index < mExcluded.size(); ++index)
                mExcluded[index] = mStipple.holds(index) ? 1 : 0;
        }
        const SplitLightSinkOf sink(
            [&](const kernel::ShadingPacket& packet, const kernel::SplitPacketAccumulator& sums) {
                for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
                    const int lane = __builtin_ctz(lanes);
                    LightSample& sample =
                        mSamples[size_t(packet.y0 + kernel::laneY(lane)) * size_t(lowWidth) +
                                 size_t(packet.x0 + kernel::laneX(lane))];
                    sample.covered = true;
                    sample.depthMetres = -packet.positionView[2][lane];
                    for (int c = 0; c < 3; ++c) {
                        sample.normalView[c] = packet.normalView[c][lane];
                        sample.light.diffuse[c] = sums.diffuse[c][lane];
                        sample.light.specular[c] = sums.specular[c][lane];
                        sample.light.specularEdge[c] = sums.specularEdge[c][lane];
                    }
                }
            });
        // Low-res tile (tx, ty) is full-res tile (tx, ty) of the culling grid (see "cull").
        SplitLightingOptions lightOptions;
        lightOptions.scale = scale;
        lightOptions.excludedSamples = mExcluded;
        accumulateSplitLights(
            inputs, lightOptions,
            TileListSource(mOptions.tileSizeSamples, grid.tileCountX, mTileLights), sink, result);
        lightingPass.stop();
        if (blended) {
            blendPass.resume();
            mStipple.light(inputs, gb.depth(), mOptions.tileSizeSamples, result);
            for (size_t index = 0; index < mSamples.size(); ++index) {
                if (!mStipple.holds(index))
                    continue;
                const InferredStipple::Sample& stippled = mStipple.sample(index);
                mSamples[index] = {true, -stippled.surface.positionView.z,
                                   stippled.surface.normalView, stippled.light};
            }
            blendPass.pause();
        }

        // Object IDs of the low-res samples: the scene instance at the pixel each sample read in
        // "lighting" (or its stippled surface's), from the material pass's draw, which the
        // material pass below makes first.
        mFrameBlended = blended;
        materialPassOverLBuffer(inputs, lowWidth, lowHeight, blended, blendPass, result, [&] {
            mSampleObjects.assign(size_t(lowWidth) * lowHeight, kNoObject);
            if (mOptions.objectIds)
                for (int j = 0; j < lowHeight; ++j)
                    for (int i = 0; i < lowWidth; ++i)
                        mSampleObjects[size_t(j) * lowWidth + i] =
                            blended && mStipple.holds(size_t(j) * lowWidth + i)
                                ? mStipple.sample(size_t(j) * lowWidth + i).instance
                                : mMaterials.instanceAt(size_t(sampleY(j)) * width + sampleX(i));
        });
        result.parameters["tile_light_pairs"] = std::to_string(mTileLights.pairCount());
    }

    // The material pass over the frame's L-buffer (mSamples, mSampleObjects): the second geometry
    // pass, the DSF upsampling and the combine at every fragment the material pass gives for
    // inputs' layer, then the blended surfaces' composite (added to the paused `blendPass`, which
    // is recorded after "material", or discarded without blended surfaces). afterDraw runs after
    // the draw, inside the timed pass.
    template <class AfterDraw>
    void materialPassOverLBuffer(const StageInputs& inputs, int lowWidth, int lowHeight,
                                 bool blended, PassTimer& blendPass, StageResult& result,
                                 const AfterDraw& afterDraw) {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const int width = gb.width(), height = gb.height();
        const int scale = mOptions.scale;
        // Material pass: second geometry pass, DSF upsampling, combine.
        PassTimer materialPass(result, pass::kMaterial);
        mMaterials.draw(inputs);
        afterDraw();
        // Per row, so that each task counts into its own slot.
        std::vector<uint32_t> rowFallbacks(size_t(height), 0), rowIdFallbacks(size_t(height), 0);
        const float halfScale = float(scale / 2);
        mMaterials.forEachSurface(gb, [&](int x, int y, size_t pixel, const gbuffer::Surface& s) {
            // The filter's position: the pixel centre, or multisampled, the fragment's centroid
            // (the same for a fragment that covers the pixel).
            const glm::vec2 centroid = mMaterials.coverageCentroid(pixel);
            const float v = (float(y) + centroid.y - halfScale) / float(scale);
            const int j0 = int(std::floor(v));
            const float fy = v - float(j0);
            const int ja = std::clamp(j0, 0, lowHeight - 1),
                      jb = std::clamp(j0 + 1, 0, lowHeight - 1);
            uint32_t& fallbacks = rowFallbacks[size_t(y)];
            uint32_t& idFallbacks = rowIdFallbacks[size_t(y)];
            const gbuffer::Surface here = gb.decode(x, y);
            const float depth = -here.positionView.z;
            const uint32_t object = mOptions.objectIds ? mMaterials.instanceAt(pixel) : kNoObject;

            const float u = (float(x) + centroid.x - halfScale) / float(scale);
            const int i0 = int(std::floor(u));
            const float fx = u - float(i0);
            const int ia = std::clamp(i0, 0, lowWidth - 1),
                      ib = std::clamp(i0 + 1, 0, lowWidth - 1);
            const size_t tapIndex[4] = {size_t(ja) * lowWidth + ia, size_t(ja) * lowWidth + ib,
                                        size_t(jb) * lowWidth + ia, size_t(jb) * lowWidth + ib};
            const float bilinear[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
            // The DSF (DsfFilter.h): `same` applies the ID, depth and normal tests, `surface` the
            // depth and normal tests only (with ids=0 they coincide).
            DsfFilter filter;
            for (int k = 0; k < 4; ++k) {
                const LightSample& t = mSamples[tapIndex[k]];
                if (!t.covered)
                    continue;
                const bool passesSurface =
                    !(std::abs(t.depthMetres - depth) > mOptions.depthThreshold * depth ||
                      glm::dot(t.normalView, here.normalView) < mOptions.normalThreshold);
                filter.add(bilinear[k], t.light, passesSurface,
                           mSampleObjects[tapIndex[k]] == object);
            }
            SplitLighting light;
            switch (filter.resolve(light)) {
            case DsfFilter::Source::Same:
                break;
            case DsfFilter::Source::Surface:
                ++idFallbacks;
                break;
            case DsfFilter::Source::Nearest:
            case DsfFilter::Source::None:
                ++fallbacks;
                break;
            }
            const glm::vec3 radiance =
                combineSplitLighting(s, light.diffuse, light.specular, light.specularEdge) +
                s.emissive;
            result.radiance[0][pixel] = radiance.r;
            result.radiance[1][pixel] = radiance.g;
            result.radiance[2][pixel] = radiance.b;
        });
        materialPass.stop();

        uint64_t fallbacks = 0, idFallbacks = 0;
        for (uint32_t f : rowFallbacks)
            fallbacks += f;
        for (uint32_t f : rowIdFallbacks)
            idFallbacks += f;
        if (blended) {
            blendPass.resume();
            const InferredStipple::Counts counts = mStipple.composite(
                mBlended, gb.depth(),
                {mOptions.depthThreshold, mOptions.normalThreshold, mOptions.objectIds}, result);
            blendPass.stop();
            result.parameters["stipple_fragments"] = std::to_string(counts.fragments);
            result.parameters["stipple_fallbacks"] = std::to_string(counts.fallbacks);
            result.parameters["stipple_unlit"] = std::to_string(counts.unlit);
        } else {
            blendPass.discard(); // no blended surface: no "blend" pass
        }
        result.parameters["scale"] = std::to_string(scale);
        result.parameters["depth"] = std::to_string(mOptions.depthThreshold);
        result.parameters["normal"] = std::to_string(mOptions.normalThreshold);
        result.parameters["tile"] = std::to_string(mOptions.tileSizeSamples);
        result.parameters["ids"] = mOptions.objectIds ? "1" : "0";
        result.parameters["lbuffer"] = std::to_string(lowWidth) + "x" + std::to_string(lowHeight);
        result.parameters["dsf_fallbacks"] = std::to_string(fallbacks);
        result.parameters["dsf_id_fallbacks"] = std::to_string(idFallbacks);
    }

private:
    BlendedPass mBlended;     // blended surfaces after the opaque pass (BlendedPass.h)
    InferredStipple mStipple; // ... lit through the stipple pattern (InferredStipple.h)
    InferredOptions mOptions;
    // Per-frame scratch, kept to avoid reallocation between repetitions.
    std::vector<LightSample> mSamples;
    std::vector<uint8_t> mExcluded; // per low-res sample: 1 = stippled (not lit by "lighting")
    std::vector<uint32_t> mSampleObjects; // object ID per low-res sample; all kNoObject with ids=0
    bool mFrameBlended = false; // the frame has blended surfaces (stippled on its layer 0)
    MaterialPass mMaterials;
    LightIndexLists mTileLights; // per tile, ascending (buildTileLightLists)
};

const StageRegistrar kRegistrar(
    {.name = "inferred",
     .description = "inferred lighting: L-buffer at 1/scale resolution, DSF upsampling in the "
                    "material pass",
     .kind = StageKind::Approximate,
     .options = {StageOption::integer("scale", 2, 1, 8, "lighting resolution divisor per axis"),
                 StageOption::number("depth", 0.1f, 0.0f, 1e30f, true,
                                     "DSF: relative view-depth difference a sample may have"),
                 StageOption::number("normal", 0.9f, -1.0f, 1.0f, false,
                                     "DSF: minimum cosine between sample and pixel normals"),
                 StageOption::integer("tile", 16, 4, 128, "culling tile size in low-res samples"),
                 StageOption::boolean("ids", true, "DSF object-ID test")},
     .listOrder = 110,
     .msaaNote = "Kircher & Lawrance: one L-buffer per frame (layer 0's); the material pass "
                 "rasterized at the sample count and the DSF run per fragment, resolved by "
                 "coverage"},
    [](const StageOptions& table) {
        InferredOptions options;
        options.scale = table.integer("scale");
        options.depthThreshold = table.number("depth");
        options.normalThreshold = table.number("normal");
        options.tileSizeSamples = table.integer("tile");
        options.objectIds = table.boolean("ids");
        return std::make_unique<InferredStage>(options);
    });

} // namespace

} // namespace lighting
