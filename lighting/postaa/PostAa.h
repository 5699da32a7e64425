// PostAa: post-process anti-aliasing of a stage's image, chosen by name (`--post-aa`, a sweep's
// `post-aa`): none, edge-blur (EdgeBlur.h: G-buffer depth and normal edges, blurred, after
// S.T.A.L.K.E.R. and Tabula Rasa) or fxaa (Fxaa.h: luminance edges, after Lottes' FXAA 3.11).
//
// Declare, then run, as a stage: requiredChannels() says what the filter reads from the G-buffer
// (the runner adds it to the stage's requirements before deriving the layout, so edge-blur works
// after any stage, forward ones included), then PostAaPass::apply() filters each frame after the
// stage's shade().
//
// Thread safety: apply() runs inside the caller's tbb::task_arena and parallelises with TBB; one
// apply() at a time per PostAaPass object (it keeps scratch planes between calls). The result is
// bitwise the same for any thread count.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferLayout.h"
#include "lighting/postaa/EdgeBlur.h"
#include "lighting/postaa/Fxaa.h"

namespace lighting::postaa {

enum class PostAa { None, EdgeBlur, Fxaa };

const char* postAaName(PostAa mode); // "none", "edge-blur", "fxaa"
std::vector<std::string> postAaNames();
// Throws std::invalid_argument naming the value, the valid names and the closest one.
PostAa parsePostAa(const std::string& text);
// The G-buffer channels the filter reads: Depth and Normal for edge-blur, none otherwise.
std::vector<gbuffer::Channel> requiredChannels(PostAa mode);

// One mode with its parameters and scratch planes, applied to frame after frame.
class PostAaPass {
public:
    explicit PostAaPass(PostAa mode, const EdgeBlurParameters& edgeBlur = {},
                        const FxaaParameters& fxaa = {})
        : mMode(mode), mEdgeBlur(edgeBlur), mFxaa(fxaa) {}

    PostAa mode() const { return mMode; }
    // The mode's parameters as text (empty for none), for stats.json.
    std::map<std::string, std::string> describe() const;

    // Filters `radiance` (3 planes of the G-buffer's size, linear HDR) and sets `edges` to the
    // filter's edge plane in [0, 1] (EdgeBlur.h, Fxaa.h say what it holds). For none, radiance is
    // untouched and edges is cleared. Each output pixel is computed from the unfiltered planes
    // (written to scratch planes, then swapped in). Throws std::invalid_argument when the planes
    // have another size than the G-buffer. Without normals in the layout, edge-blur tests depth
    // only.
    void apply(const gbuffer::GBuffer& gbuffer, std::vector<float> (&radiance)[3],
               std::vector<float>& edges);

private:
    PostAa mMode;
    EdgeBlurParameters mEdgeBlur;
    FxaaParameters mFxaa;
    SurfacePlanes mSurface;
    std::vector<float> mLuma;
    std::vector<float> mOut[3];
};

} // namespace lighting::postaa
