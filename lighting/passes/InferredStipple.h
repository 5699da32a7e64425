// InferredStipple: how `inferred` lights blended (glTF BLEND) surfaces, after Kircher & Lawrance
// (2009) as the survey describes it (Ishmukhametov 2013, section 2.2): "Transparent surfaces are
// rendered during geometry pass using a stipple pattern so that their G-buffer samples are
// interleaved with opaque polygon samples. The light pass will automatically light those
// stippled pixels. [...] In the material pass the DSF for opaque polygons will automatically
// reject stippled transparent pixels, and transparent polygons are handled by finding the four
// closest L-buffer samples in the same stipple pattern, again using DSF to make sure the samples
// were not overwritten by some other geometry." At most 3 layers of transparency.
//
// Here:
// - Patterns. The L-buffer's samples form 2x2 blocks; sample (i, j) has pattern
//   (i mod 2) + 2 (j mod 2): patterns 0, 1, 2 are the three transparent layers, pattern 3 is left
//   to opaque surfaces alone. Each blended instance (scene instance with a BLEND material) takes
//   one pattern: instances ranked front to back by the view depth of their bounding box centre,
//   rank mod 3.
// - Geometry pass (stipple()): a sample of pattern k < 3 holds, instead of the opaque surface at
//   its pixel, the nearest blended fragment in front of it whose instance has pattern k (if any).
//   Opaque surfaces thereby lose those samples (the technique's cost: the opaque lighting
//   resolution drops where transparent surfaces cover it).
// - Light pass (light()): those samples are lit like any other (diffuse and specular split, the
//   stage's L-buffer), with the near-to-opaque tile lists (BlendedTileLists.h) of the stage's
//   culling tiles, since the stage's own lists are bounded by the opaque depth: on the shared
//   light kernel, by the stage's own loop (accumulateSplitLights over the held surfaces,
//   LightAccumulation.h), which also counts their warps (8x4 or 8x8 samples) in the SIMT model.
// - Material pass (composite()): every blended fragment (BlendedPass's per-triangle back-to-front
//   order) takes the 4 nearest samples of its instance's pattern (a lattice of spacing 2 in
//   samples) with bilinear weights, zeroed by the stage's DSF tests: the sample holds no
//   stippled surface, another instance (with ids=1), a view depth off by more than `depth` times
//   the fragment's, or a normal cosine below `normal`; then, as the opaque filter does, the
//   samples passing depth and normal only, then the nearest stippled sample of the pattern
//   (counted in stipple_fallbacks), else no light (stipple_unlit). lit = the material's half of
//   the split (combineSplitLighting, SplitLighting.h: albedo x diffuse + specular intensity x
//   specular, or for metallic-roughness c_diff x diffuse + f0 x specular + the Fresnel edge
//   term, which the samples carry too) + the fragment's emission, composited with "over".
// - Beyond 3 layers: instances whose ranks differ by a multiple of 3 share a pattern; where they
//   overlap, the nearer one holds the samples, and the farther one finds none of its own (its DSF
//   rejects them by ID, or by depth) and falls back as above: wrong light, which its error
//   against the reference shows. No layer is ever dropped from the composite.
// Deterministic: per-sample nearest fragment with ties broken by draw order; samples in parallel
// each written by one task; the composite runs in BlendedPass's draw (one thread per pixel).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "gbuffer/Surface.h"
#include "lighting/ShadingStage.h"
#include "lighting/brdf/SplitLighting.h"
#include "lighting/passes/BlendedPass.h"

namespace lighting {

class InferredStipple {
public:
    static constexpr int kTransparentLayers = 3;
    static int patternOf(int i, int j) { return (i & 1) | ((j & 1) << 1); }

    // A blended surface stippled into one L-buffer sample, and its light.
    struct Sample {
        bool covered = false;
        uint32_t instance = 0;
        gbuffer::Surface surface; // positionView from the fragment's depth
        SplitLighting light;      // diffuse, specular, metallic-roughness Fresnel edge
    };

    // The L-buffer geometry of the stage: lowWidth x lowHeight samples, sample (i, j) reading
    // full-res pixel (min(i scale + scale/2, W-1), min(j scale + scale/2, H-1)).
    struct Lattice {
        int width = 0;
        int height = 0;
        int scale = 1;
        int lowWidth = 0;
        int lowHeight = 0;
        int sampleX(int i) const { return std::min(i * scale + scale / 2, width - 1); }
        int sampleY(int j) const { return std::min(j * scale + scale / 2, height - 1); }
    };

    // The geometry pass: assigns the patterns and stipples the blended fragments of `blended`
    // (prepared for this frame) into the samples. Cost: one draw of the blended triangles.
    void stipple(const StageInputs& inputs, BlendedPass& blended,
                 std::span<const float> opaqueDepth, const Lattice& lattice);
    bool holds(size_t sample) const { return mSamples[sample].covered; }
    const Sample& sample(size_t index) const { return mSamples[index]; }

    // The light pass for the stippled samples, on tiles of tileSizeSamples x tileSizeSamples
    // samples (the stage's culling tiles): writes result.lightsEvaluated at each held sample's
    // pixel (its list length) and adds its kernel work to the frame's (KernelWork.h).
    void light(const StageInputs& inputs, std::span<const float> opaqueDepth, int tileSizeSamples,
               StageResult& result);

    struct DsfOptions {
        float depthThreshold = 0.1f;
        float normalThreshold = 0.9f;
        bool objectIds = true;
    };
    struct Counts {
        uint64_t fragments = 0;
        uint64_t fallbacks = 0; // lit from the nearest stippled sample of the pattern
        uint64_t unlit = 0;     // no stippled sample among the 4
    };
    // The material pass for blended surfaces: composites every blended fragment over
    // result.radiance (see the file comment).
    Counts composite(BlendedPass& blended, std::span<const float> opaqueDepth,
                     const DsfOptions& options, StageResult& result) const;

private:
    Lattice mLattice;
    const gbuffer::SceneGeometry* mGeometry = nullptr;
    std::vector<int> mPatternOfInstance; // -1: not blended
    std::vector<Sample> mSamples;        // lowWidth x lowHeight
    std::vector<float> mSampleDepth;     // view depth of the held fragment (nearest wins)
};

} // namespace lighting
