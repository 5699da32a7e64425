// Coverage: see Coverage.h.
#include "experiments/render/Coverage.h"

namespace experiments {

nlohmann::json Coverage::toJson() const {
    nlohmann::json json = {{"covered_pixels", coveredPixels},
                           {"pixels", pixels},
                           {"triangles", triangles},
                           {"triangles_in_front", trianglesInFront >= 0
                                                      ? nlohmann::json(trianglesInFront)
                                                      : nlohmann::json(nullptr)}};
    json["warning"] = warning.empty() ? nlohmann::json(nullptr) : nlohmann::json(warning);
    return json;
}

Coverage measureCoverage(const lighting::PreparedScene& prepared) {
    Coverage coverage;
    const gbuffer::GBuffer& gbuffer = *prepared.gbuffer;
    coverage.pixels = gbuffer.pixelCount();
    for (size_t pixel = 0; pixel < gbuffer.pixelCount(); ++pixel)
        coverage.coveredPixels += gbuffer.covered(pixel);
    const gbuffer::SceneGeometry& geometry = prepared.geometry;
    coverage.triangles = geometry.triangleCount();
    if (coverage.coveredPixels > 0 || coverage.triangles == 0)
        return coverage;

    const glm::dmat4& viewFromWorld = prepared.view.viewFromWorldExact;
    const double nearMetres = double(prepared.view.nearMetres);
    coverage.trianglesInFront = 0;
    for (size_t t = 0; t < geometry.triangleCount(); ++t) {
        bool inFront = false;
        for (int corner = 0; corner < 3 && !inFront; ++corner) {
            const glm::dvec3& p = geometry.positionWorldExact[geometry.indices[3 * t + corner]];
            inFront = (viewFromWorld * glm::dvec4(p, 1.0)).z < -nearMetres;
        }
        coverage.trianglesInFront += inFront;
    }
    const std::string camera = "camera '" + prepared.scene.cameras.front().name + "'";
    const std::string triangles = std::to_string(coverage.triangles);
    if (coverage.trianglesInFront > 0)
        coverage.warning =
            "no pixel is covered, although " + std::to_string(coverage.trianglesInFront) +
            " of the scene's " + triangles + " triangles lie in front of the " + camera +
            ": the image is background only (outside the field of view, beyond the far plane, " +
            "or smaller than a pixel?); its figures describe no surface";
    else
        coverage.warning = "no pixel is covered: none of the scene's " + triangles +
                           " triangles lies in front of the " + camera +
                           " (beyond its near plane); the image is background only and its "
                           "figures describe no surface";
    return coverage;
}

} // namespace experiments
