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

void GBufferPass::resolve(std::span<const uint32_t> codeSpan, GBuffer& target,
                          ExactSurface* exact) const {
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
    });
}

void GBufferPass::storeCodes(std::span<const uint32_t> codes, GBuffer& target) const {
    const std::span<uint32_t> stored = target.visibilityCodePlane();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, codes.size(), 65536), [&](const auto& range) {
        std::copy(codes.begin() + range.begin(), codes.begin() + range.end(),
                  stored.begin() + range.begin());
    });
    target.fetchSurfacesFrom(mVisibility);
}

void GBufferPass::resolveUpperLayer(const FragmentLayers& layers, int k, GBuffer& target,
                                    const std::vector<std::vector<uint32_t>>* lastColumns) const {
    const std::span<const uint32_t> codes = layers.codes(k);
    const std::span<const float> depths = layers.depths(k);
    const std::span<float> depth = target.depthPlane();
    if (target.layout().visibilityBuffer) {
        // The codes and depths are the G-buffer: copied whole.
        std::copy(depths.begin(), depths.end(), depth.begin());
        target.quantiseDepth();
        storeCodes(codes, target);
        return;
    }
    const int width = target.width();
    const float clear = target.view().clearDepth();
    const DepthDecoder& decoder = target.depthDecoder();
    const bool lossless = decoder.lossless();
    const GBuffer::Writer sharedWriter = target.writer();
    tbb::parallel_for(0, target.height(), [&](int y) {
        const GBuffer::Writer writer = sharedWriter;
        const size_t rowStart = size_t(y) * size_t(width);
        if (!lastColumns) {
            for (size_t pixel = rowStart; pixel < rowStart + size_t(width); ++pixel) {
                writer.writeBackground(pixel);
                depth[pixel] = clear;
            }
        } else {
            for (const uint32_t x : (*lastColumns)[size_t(y)]) {
                writer.writeBackground(rowStart + x);
                depth[rowStart + x] = clear;
            }
        }
        VisibilityPass::RowSurfaces row(mVisibility, y);
        for (const uint32_t x : layers.upperColumns(y)) {
            const size_t pixel = rowStart + x;
            const uint32_t code = codes[pixel];
            if (code == VisibilityPass::kNoTriangle)
                continue;
            // As GBuffer::quantiseDepth (a fragment's depth is never the clear value).
            depth[pixel] = lossless ? depths[pixel] : decoder.storedDepthNdc(depths[pixel]);
            writer.write(pixel, row.at(code, int(x)));
        }
    });
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
    resolve(codes, target, exact);
    if (multisample) {
        const FragmentLayers& layers = multisample->layers;
        std::vector<std::vector<uint32_t>>& lastColumns = multisample->upperWrittenColumns;
        if (lastColumns.size() != size_t(view.height))
            multisample->upperLayers.clear(); // another size: every layer is new
        multisample->upperLayers.resize(size_t(layers.layerCount() - 1));
        for (int k = 1; k < layers.layerCount(); ++k) {
            std::unique_ptr<GBuffer>& layer = multisample->upperLayers[size_t(k - 1)];
            const bool fresh = !layer || !sameView(layer->view(), view);
            if (fresh)
                layer = std::make_unique<GBuffer>(target.layout(), view);
            resolveUpperLayer(layers, k, *layer, fresh ? nullptr : &lastColumns);
        }
        lastColumns.resize(size_t(view.height));
        for (int y = 0; y < view.height; ++y) {
            const std::span<const uint32_t> columns = layers.upperColumns(y);
            lastColumns[size_t(y)].assign(columns.begin(), columns.end());
        }
    }
    timings.resolveMs = millisecondsSince(start);

    if (exact) {
        start = std::chrono::steady_clock::now();
        exact->computeGeometry(mScene, mGeometry, view);
        timings.exactMs = millisecondsSince(start);
    }
    return timings;
}

} // namespace gbuffer
