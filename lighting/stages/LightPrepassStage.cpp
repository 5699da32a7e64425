// `light-prepass`: Light Pre-Pass / deferred lighting (Engel 2008; Ishmukhametov 2013, section
// 2.1). An APPROXIMATE stage: its error against `reference` is measured, not required to vanish.
//
// Passes:
//   "cull"      tiled light culling on the thin G-buffer, exactly as `tiled` does it (per-tile
//               depth-bounded frusta of culling/TileFrusta.h against the widened spheres of
//               LightBounds.h, lists in ascending light index; unbounded lights in every list).
//   "lighting"  light accumulation into the light buffer, per pixel:
//                 diffuse RGB  = sum_i radiance_i * att_i * (n.l_i) / pi  (+ ambient radiance)
//                 specular     = lum(sum_i radiance_i * att_i * (n.l_i) * blinnPhong_i)
//               i.e. the BRDF's diffuse part without albedo and ONE monochromatic specular scalar
//               without the specular intensity, as the technique stores it (RGB + alpha).
//               Both terms are the one BRDF's (lighting/brdf/SplitLighting.h, addSplitLight):
//               albedo 1 and specular intensity 0 for the diffuse part, albedo 0 and intensity 1
//               for the specular part (only for lights whose diffuse part is non-zero: a light with
//               zero diffuse there has zero att * n.l, so zero specular too); metallic-roughness
//               surfaces split exactly into diffuse, F0 lobe and Fresnel edge sums.
//               On the shading kernel: accumulateSplitLights (lighting/passes/LightAccumulation.h)
//               decodes 4x4-pixel packets, groups their lanes by tile and shades each group with
//               kernel::shadePacketSplit on --isa (one evaluation per light for all the sums).
//               `--isa scalar` gives the per-pixel splitLighting sums bitwise; a vector ISA the
//               same diffuse and metallic-roughness sums bitwise and Blinn-Phong specular sums
//               within pow's error (kernel/SplitLightKernel.h); a layout the packet decoder
//               refuses takes the per-pixel path (stage_parameters.isa = scalar).
//   "material"  the second geometry pass (lighting/passes/MaterialPass.h): the scene is rasterized
//               again with the G-buffer pass's visibility draw, and each visible pixel's material
//               comes from its triangle's surface -- albedo and specular intensity are never read
//               from the G-buffer. Then radiance = albedo * diffuse + intensity * specular *
//               colour.
// Options:
//   spec=grey   colour of the monochromatic specular: `grey` (white: the classic approximation,
//               coloured specular turns grey) or `chroma` (Engel's variant: the chromaticity of the
//               accumulated diffuse light, diffuse / lum(diffuse), white where diffuse is zero)
//   tile=16     culling tile size in pixels, 4..128
// Luminance is Rec. 709: 0.2126 R + 0.7152 G + 0.0722 B (weights sum to 1, so with all-white
// lights the monochromatic specular loses nothing and the image equals brute's up to rounding).
// G-buffer: depth, normal and specular (the layout has no power-only channel; only the specular
// power is read from it). Position is reconstructed from depth (GBuffer::decode).
// lightsEvaluated: the tile list size per covered pixel (lights accumulated in "lighting").
// Cost note (CPU): the kernel evaluates range, direction and attenuation once per light for both
// sums (before the kernel: two evaluateLight calls per contributing light, twice `tiled`'s work);
// the specular part still adds a second lobe evaluation beside the diffuse one.
// SIMT counters (simt_lane_slots, packet_*): warps of 8x4 pixels over the light pass, as
// accumulateLights counts them (lighting/README.md, "SIMT cost model").
// Multisampling (--msaa N; MultisampleShading.h runs the stage once per fragment layer): the
// light buffer is the stage's per fragment layer, i.e. per sample at complex pixels only and once
// per pixel elsewhere (the seeds' "light buffer per sample at edges": the samples of one fragment
// have one surface, so one light); the material pass rasterizes the scene at N samples once per
// frame, as hardware MSAA would, and combines each of its fragments with the light its layer
// holds (MaterialPass.h: its fragments are the G-buffer's, bitwise); the resolve weights them
// by coverage. Cost beyond 1x: the complex pixels' light, one multisampled draw and the fragment
// split. With all-white lights the resolved image is brute's resolve up to rounding (tested).
// Threads: tiles in parallel for culling, warp rows for lighting, rows for the material pass; every
// pixel written by one task only, light sums in ascending light order: deterministic.
#include "lighting/StageRegistry.h"

#include <algorithm>
#include <span>

#include "lighting/culling/LightBounds.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/lists/LightListShading.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/MaterialPass.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

inline float luminance(const glm::vec3& c) {
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

class LightPrepassStage final : public ShadingStage {
public:
    LightPrepassStage(bool chroma, int tileSizePixels)
        : mChroma(chroma), mTileSizePixels(tileSizePixels) {}

    std::string name() const override { return "light-prepass"; }
    StageRequirements requirements() const override { return MaterialPass::gbufferRequirements(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const int width = gb.width(), height = gb.height();
        result.resize(width, height, false);

        PassTimer cullPass(result, pass::kCull);
        const TileGrid grid = TileGrid::make(width, height, mTileSizePixels);
        const std::vector<TileSurfaceBounds> bounds = computeTileSurfaceBounds(gb, grid, {});
        buildTileLightLists(gb.view(), grid, bounds, boundingSpheresView(*inputs.lights), {},
                            mTileLights);
        cullPass.stop();

        // Light buffer: diffuse RGB + monochromatic specular, per pixel.
        PassTimer lightingPass(result, pass::kLighting);
        mDiffuse.assign(gb.pixelCount(), glm::vec3(0.0f));
        mSpecular.assign(gb.pixelCount(), 0.0f);
        mSpecularEdge.assign(gb.pixelCount(), 0.0f);
        const SplitLightSinkOf sink(
            [&](const kernel::ShadingPacket& packet, const kernel::SplitPacketAccumulator& sums) {
                for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
                    const int lane = __builtin_ctz(lanes);
                    const size_t pixel = size_t(packet.y0 + kernel::laneY(lane)) * size_t(width) +
                                         size_t(packet.x0 + kernel::laneX(lane));
                    const glm::vec3 specular(sums.specular[0][lane], sums.specular[1][lane],
                                             sums.specular[2][lane]);
                    const glm::vec3 edge(sums.specularEdge[0][lane], sums.specularEdge[1][lane],
                                         sums.specularEdge[2][lane]);
                    mDiffuse[pixel] = {sums.diffuse[0][lane], sums.diffuse[1][lane],
                                       sums.diffuse[2][lane]};
                    mSpecular[pixel] = luminance(specular); // one monochrome scalar
                    mSpecularEdge[pixel] = luminance(edge);
                }
            });
        accumulateSplitLights(inputs, {},
                              TileListSource(grid.tileSizePixels, grid.tileCountX, mTileLights),
                              sink, result);
        lightingPass.stop();

        // Material pass: second geometry pass into a visibility buffer, then combine.
        PassTimer materialPass(result, pass::kMaterial);
        mMaterials.draw(inputs);
        mMaterials.forEachSurface(gb, [&](int, int, size_t pixel, const gbuffer::Surface& s) {
            const glm::vec3& diffuse = mDiffuse[pixel];
            glm::vec3 specularColour(1.0f);
            if (mChroma) {
                const float lum = luminance(diffuse);
                if (lum > 0.0f)
                    specularColour = diffuse / lum;
            }
            glm::vec3 radiance;
            if (s.model == scenes::MaterialModel::MetallicRoughness)
                radiance = combineSplitLighting(s, diffuse, mSpecular[pixel] * specularColour,
                                                mSpecularEdge[pixel] * specularColour);
            else // Blinn-Phong, in the order the stage has always summed it
                radiance =
                    s.albedo * diffuse + (s.specularIntensity * mSpecular[pixel]) * specularColour;
            radiance += s.emissive;
            result.radiance[0][pixel] = radiance.r;
            result.radiance[1][pixel] = radiance.g;
            result.radiance[2][pixel] = radiance.b;
        });
        materialPass.stop();

        // Blended surfaces: a forward pass with the whole BRDF over near-to-opaque tile lists.
        if (mBlended.prepare(inputs))
            mBlended.shadeWithTileLists(gb.depth(), mTileSizePixels, true, result);
        const uint64_t pairs = mTileLights.pairCount();
        result.parameters["spec"] = mChroma ? "chroma" : "grey";
        result.parameters["tile"] = std::to_string(mTileSizePixels);
        result.parameters["tile_light_pairs"] = std::to_string(pairs);
    }

private:
    bool mChroma;
    int mTileSizePixels;
    // Per-frame scratch, kept to avoid reallocation between repetitions.
    std::vector<glm::vec3> mDiffuse;
    std::vector<float> mSpecular;
    std::vector<float> mSpecularEdge; // metallic-roughness: the Fresnel edge's monochrome sum
    MaterialPass mMaterials;
    LightIndexLists mTileLights; // per tile, ascending (buildTileLightLists)
    BlendedPass mBlended;        // blended surfaces after the opaque pass (BlendedPass.h)
};

const StageRegistrar kRegistrar(
    {.name = "light-prepass",
     .description = "Light Pre-Pass: thin G-buffer, diffuse RGB + monochrome specular light "
                    "buffer, material pass",
     .kind = StageKind::Approximate,
     .options = {StageOption::choice("spec", {"grey", "chroma"},
                                     "colour of the monochrome specular: white, or the "
                                     "chromaticity of the diffuse light (Engel)"),
                 StageOption::integer("tile", 16, 4, 128, "culling tile size in pixels")},
     .listOrder = 100,
     .msaaNote = "light buffer per fragment layer: per sample at complex pixels only; the "
                 "material pass rasterized at the sample count, its fragments combined with "
                 "their own light and resolved by coverage"},
    [](const StageOptions& options) {
        return std::make_unique<LightPrepassStage>(options.text("spec") == "chroma",
                                                   options.integer("tile"));
    });

} // namespace

} // namespace lighting
