#include "experiments/compare/FlipMetric.h"

#include <stdexcept>

#include "experiments/compare/Flip.h"

namespace experiments {

namespace {

compare::FlipImage view(const lighting::StageResult& image) {
    return {image.width, image.height, image.radiance[0].data(), image.radiance[1].data(),
            image.radiance[2].data()};
}

} // namespace

FlipComparison computeFlip(const lighting::StageResult& test,
                           const lighting::StageResult& reference) {
    FlipComparison comparison;
    compare::FlipResult flip;
    try {
        flip = compare::computeFlip(view(test), view(reference));
    } catch (const std::invalid_argument& error) {
        comparison.unavailableReason = error.what();
        return comparison;
    }
    comparison.mean = flip.mean;
    comparison.weightedMedian = flip.weightedMedian;
    comparison.p95 = flip.p95;
    comparison.p99 = flip.p99;
    comparison.errorMap = std::move(flip.errorMap);
    comparison.parameters = {{"mode", "HDR"},
                             {"implementation", "testbed (experiments/compare/Flip.h)"},
                             {"pixels_per_degree", flip.pixelsPerDegree},
                             {"tone_mapper", "ACES"},
                             {"start_exposure", flip.startExposure},
                             {"stop_exposure", flip.stopExposure},
                             {"exposure_count", flip.exposureCount},
                             {"non_finite_test_pixels", flip.nonFiniteTest},
                             {"non_finite_reference_pixels", flip.nonFiniteReference},
                             {"warnings", flip.warnings}};
    return comparison;
}

ScalarMapStyle flipMapStyle() {
    ScalarMapStyle style;
    style.max = 1.0f;
    style.colourMap = "magma";
    style.title = "HDR-FLIP error, 0..1";
    return style;
}

} // namespace experiments
