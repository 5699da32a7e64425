// DepthSampler: the sampling model of the depth study (DepthStudy.h, steps 1-4 of its model) for
// one camera and one depth format: the exact point on a pixel's ray, the float NDC depth the
// rasterizer would store, whether the sample is lost, the position the G-buffer reconstructs,
// and the depth step between neighbouring codes.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "experiments/studies/DepthStudy.h"
#include "gbuffer/codecs/DepthFormat.h"
#include "gbuffer/visibility/CameraView.h"

namespace experiments {

// One camera and one format: the CameraView and DepthProjection the G-buffer would use, and the
// sample model above. Cheap to copy; const methods are thread-safe.
class DepthSampler {
public:
    DepthSampler(const DepthStudyOptions& options, DepthStudyCamera camera,
                 gbuffer::DepthFormatSpec format);

    const gbuffer::CameraView& view() const { return mView; }
    const gbuffer::DepthProjection& projection() const { return mProjection; }
    // Exact view-space point at view depth d on the ray through pixel (x, y)'s centre.
    glm::dvec3 exactPointView(int x, int y, double viewDepthMetres) const;
    // Step 2 of the model: float NDC depth of an exact view-space point.
    float rasterDepthNdc(const glm::dvec3& pointView) const;
    // Step 3: whether a float NDC depth is lost (clipped or equal to the clear value).
    bool lost(float depthNdc) const;
    // Steps 4: the position GBuffer reconstructs at pixel (x, y) from NDC depth `depthNdc`.
    glm::vec3 reconstruct(gbuffer::PositionMethod method, int x, int y, float depthNdc) const;
    double depthStepMetres(double viewDepthMetres) const;

private:
    double codeViewDepthExact(uint32_t code) const;
    bool validCode(uint64_t code) const;

    gbuffer::DepthFormatSpec mFormat;
    gbuffer::CameraView mView;
    gbuffer::DepthProjection mProjection;
    glm::dmat4 mRasterClipFromView; // the float matrix, widened: what the rasterizer applies
    double mViewXPerNdc = 1.0;      // exact: x_view = ndc.x * d * mViewXPerNdc
    double mViewYPerNdc = 1.0;
};

} // namespace experiments
