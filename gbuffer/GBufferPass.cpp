#include "gbuffer/GBufferPass.h"

#include <chrono>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gbuffer {

namespace {
double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}
// Whether a G-buffer made for view `a` decodes like one made for `b` (an upper layer kept from the
// last frame is reused only then: a jittered or moved camera makes a new one).
bool sameView(const CameraView& a, const CameraView& b) {
    return a.width == b.width && a.height == b.height && a.nearMetres == b.nearMetres &&
           a.farMetres == b.farMetres && a.depthConvention == b.depthConvention &&
           a.infiniteFar == b.infiniteFar && a.pixelOffset == b.pixelOffset &&
           a.viewFromWorld == b.viewFromWorld && a.clipFromView == b.clipFromView &&
           a.viewFromClip == b.viewFromClip;
}

} // namespace

GBufferPass::GBufferPass(const scenes::Scene& scene, const SceneGeometry& geometry)
    : mScene(scene), mGeometry(geometry) {
    VisibilityPass::checkTriangleCount(scene, geometry);
}

void GBufferPass::resolve(std::span<const uint32_t> codeSpan, GBuffer& target, ExactSurface* exact,
                          const UpperLayers* upper) const {
    if (target.layout().visibilityBuffer) {
        storeCodes(codeSpan, target);
        if (!exact)
            return;
    }
    const int width = target.width();
    const GBuffer::Writer sharedWriter = target.writer();
    const uint32_t* codes = codeSpan.data();
    tbb::parallel_for(0, target.height(), [&](int y) {
        // A copy whose address does not escape, so the plane pointers stay in registers (the
        // encoded planes' out-of-line call could otherwise change the shared one).
        const GBuffer::Writer writer = sharedWriter;
        VisibilityPass::RowSurfaces row(mVisibility, y);
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            const uint32_t code = codes[pixel];
            if (code == VisibilityPass::kNoTriangle) {
                writer.writeBackground(pixel);
                continue;
            }
            const Surface& surface = row.at(code, x);
            writer.write(pixel, surface); // no plane to write for the visibility buffer
            if (exact) {
                exact->triangle[pixel] = VisibilityPass::triangleOf(code);
                exact->backFacing[pixel] = VisibilityPass::backFaceOf(code) ? 1 : 0;
                exact->albedo[pixel] = surface.albedo;
                exact->specular[pixel] = {surface.specularIntensity, surface.specularPower};
                exact->roughnessMetallic[pixel] = {surface.roughness, surface.metallic};
                exact->model[pixel] = surface.model;
                exact->occlusion[pixel] = surface.occlusion;
                exact->emissive[pixel] = surface.emissive;
            }
        }
        if (upper)
            resolveUpperRow(*upper, y);
    });
}

void GBufferPass::resolveUpperRow(const UpperLayers& upper, int y) const {
    const FragmentLayers& layers = upper.layers;
    const size_t rowStart = size_t(y) * size_t(layers.width());
    const float clear = upper.targets[0]->view().clearDepth(); // targets is not empty
    // Layer k (1 .. targets.size()) exists in this frame's layers and G-buffers; a layer the last
    // frame had beyond those was dropped with its G-buffer (resolveLayers), so nothing to reset.
    const int layerCount = int(upper.targets.size()) + 1;
    std::vector<MultisampleTarget::WrittenColumn>& written = upper.written[size_t(y)];
    for (const MultisampleTarget::WrittenColumn& column : written) {
        const size_t pixel = rowStart + column.x;
        for (int k = 1; k <= int(column.layers) && k < layerCount; ++k)
            if (layers.codes(k)[pixel] == VisibilityPass::kNoTriangle) {
                upper.writers[size_t(k - 1)].writeBackground(pixel);
                upper.targets[size_t(k - 1)]->depthPlane()[pixel] = clear;
            }
    }
    written.clear();
    const DepthDecoder& decoder = upper.targets[0]->depthDecoder(); // every layer's layout
    const bool lossless = decoder.lossless();
    VisibilityPass::RowSurfaces surfaces(mVisibility, y);
    for (const uint32_t x : layers.upperColumns(y)) {
        const size_t pixel = rowStart + x;
        // A pixel's fragments fill layers 1, 2, ... in order: the first without one ends them.
        int k = 1;
        for (; k < layers.layerCount(); ++k) {
            const uint32_t code = layers.codes(k)[pixel];
            if (code == VisibilityPass::kNoTriangle)
                break;
            // As GBuffer::quantiseDepth (a fragment's depth is never the clear value).
            const float z = layers.depths(k)[pixel];
            upper.targets[size_t(k - 1)]->depthPlane()[pixel] =
                lossless ? z : decoder.storedDepthNdc(z);
            upper.writers[size_t(k - 1)].write(pixel, surfaces.at(code, int(x)));
        }
        written.push_back({x, uint32_t(k - 1)});
    }
}

void GBufferPass::storeCodes(std::span<const uint32_t> codes, GBuffer& target) const {
    const std::span<uint32_t> stored = target.visibilityCodePlane();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, codes.size(), 65536), [&](const auto& range) {
        std::copy(codes.begin() + range.begin(), codes.begin() + range.end(),
                  stored.begin() + range.begin());
    });
    target.fetchSurfacesFrom(mVisibility);
}

void GBufferPass::resolveLayers(std::span<const uint32_t> codes, GBuffer& target,
                                ExactSurface* exact, MultisampleTarget& multisample) const {
    const FragmentLayers& layers = multisample.layers;
    const CameraView& view = target.view();
    std::vector<std::vector<MultisampleTarget::WrittenColumn>>& written =
        multisample.upperWrittenColumns;
    if (written.size() != size_t(view.height) || multisample.upperWrittenWidth != view.width) {
        multisample.upperLayers.clear(); // another size: every layer is new
        written.assign(size_t(view.height), {});
        multisample.upperWrittenWidth = view.width;
    }
    multisample.upperLayers.resize(size_t(layers.layerCount() - 1));
    std::vector<GBuffer*> targets;
    std::vector<GBuffer::Writer> writers;
    for (std::unique_ptr<GBuffer>& layer : multisample.upperLayers) {
        if (!layer || !sameView(layer->view(), view)) {
            // A new layer: background everywhere (a moved or jittered view makes a new one).
            layer = std::make_unique<GBuffer>(target.layout(), view);
            const std::span<float> depth = layer->depthPlane();
            const GBuffer::Writer writer = layer->writer();
            const float clear = view.clearDepth();
            tbb::parallel_for(
                tbb::blocked_range<size_t>(0, layer->pixelCount(), 16384), [&](const auto& range) {
                    for (size_t pixel = range.begin(); pixel != range.end(); ++pixel) {
                        writer.writeBackground(pixel);
                        depth[pixel] = clear;
                    }
                });
        }
        targets.push_back(layer.get());
        writers.push_back(layer->writer());
    }
    if (targets.empty() || target.layout().visibilityBuffer) {
        // No upper G-buffer is kept, or each is copied whole: nothing to reset next frame.
        for (std::vector<MultisampleTarget::WrittenColumn>& row : written)
            row.clear();
    }
    if (targets.empty()) {
        resolve(codes, target, exact);
    } else if (target.layout().visibilityBuffer) {
        // The codes and depths are a visibility-buffer layout's G-buffer: copied whole.
        resolve(codes, target, exact);
        for (int k = 1; k < layers.layerCount(); ++k) {
            GBuffer& layer = *targets[size_t(k - 1)];
            const std::span<const float> depths = layers.depths(k);
            std::copy(depths.begin(), depths.end(), layer.depthPlane().begin());
            layer.quantiseDepth();
            storeCodes(layers.codes(k), layer);
        }
    } else {
        const UpperLayers upper{layers, targets, writers, written};
        resolve(codes, target, exact, &upper);
    }
}

GBufferPassTimings GBufferPass::render(raster::Rasterizer& rasterizer, GBuffer& target,
                                       ExactSurface* exact, MultisampleTarget* multisample) {
    GBufferPassTimings timings;
    const CameraView& view = target.view();
    auto start = std::chrono::steady_clock::now();
    mVisibility.transform(mScene, mGeometry, view, multisample && multisample->alphaToCoverage);
    timings.transformMs = millisecondsSince(start);

    start = std::chrono::steady_clock::now();
    if (multisample) {
        multisample->sampleDepth.resize(target.pixelCount() * size_t(multisample->samples));
        mVisibility.draw(rasterizer, multisample->sampleDepth, multisample->samples);
    } else {
        mVisibility.draw(rasterizer, target.depthPlane());
    }
    timings.rasterMs = millisecondsSince(start);
    timings.rasterPhases = rasterizer.lastPhaseTimes();

    std::span<const uint32_t> codes = mVisibility.codes();
    if (multisample) {
        start = std::chrono::steady_clock::now();
        FragmentLayers& layers = multisample->layers;
        layers.build(mVisibility, multisample->options);
        timings.layersMs = millisecondsSince(start);
        codes = layers.codes(0);
        std::span<const float> depths = layers.depths(0);
        std::copy(depths.begin(), depths.end(), target.depthPlane().begin());
    }

    start = std::chrono::steady_clock::now();
    target.quantiseDepth();
    if (exact)
        exact->resize(view.width, view.height);
    if (multisample)
        resolveLayers(codes, target, exact, *multisample);
    else
        resolve(codes, target, exact);
    timings.resolveMs = millisecondsSince(start);

    if (exact) {
        start = std::chrono::steady_clock::now();
        exact->computeGeometry(mScene, mGeometry, view);
        timings.exactMs = millisecondsSince(start);
    }
    return timings;
}

} // namespace gbuffer
