// FlipMetric: HDR-ꟻLIP of a render against its reference, as every command that compares reports
// it (render --compare-reference, diff, sweep rows, the report): the mean, the weighted median, the
// 95th and 99th percentiles, the per-pixel map and the parameters it assumed. The metric itself is
// the testbed's own implementation from the papers (experiments/compare/Flip.h; Andersson et al.,
// HPG 2020 and Eurographics 2021), checked against NVIDIA's figures in ../shared/flip/; this file
// only adapts StageResult planes and records what was assumed.
//
// Conventions: images are StageResult planes (linear R, G, B, row 0 at the top); the reference is
// the second argument; the map holds one value per pixel in [0, 1] (0 = no visible difference);
// the statistics are over all pixels. Parameters are ꟻLIP's defaults (67.02 pixels per degree:
// 0.7 m from a 0.7 m wide 3840-pixel display; ACES tone mapper; exposures from the reference).
// Non-finite pixels and a reference whose median luminance is 0 are handled as Flip.h documents
// and reported in the parameters' "warnings"; never a NaN, never a perfect score for images that
// differ.
//
// Cost: about 0.1-0.3 s for 1280x720 on 2 threads (tests/bench/flip_bench.cpp); never inside a
// stage's timed passes. Thread-safe (TBB inside).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/output/ImageOutput.h"
#include "lighting/ShadingStage.h"

namespace experiments {

struct FlipComparison {
    std::optional<double> mean;           // mean HDR-ꟻLIP, 0..1; nullopt when not computed
    std::optional<double> weightedMedian; // ꟻLIP's weighted median (Flip.h)
    std::optional<double> p95, p99;       // percentiles of the per-pixel values
    std::string unavailableReason;        // why mean is missing ("" when computed)
    std::vector<float> errorMap;          // width * height values in [0, 1]; empty when missing
    nlohmann::json parameters; // mode, implementation, pixels_per_degree, start/stop exposure and
                               // count, non-finite pixel counts, warnings; null when missing
};

// HDR-ꟻLIP of `test` against `reference`. Never throws for the metric's sake: images that cannot
// be compared (different sizes, empty) give a result without a mean and with the reason.
FlipComparison computeFlip(const lighting::StageResult& test,
                           const lighting::StageResult& reference);

// The style of flip.png: magma, linear from 0 to 1 (ꟻLIP's range), the same for every image.
ScalarMapStyle flipMapStyle();

} // namespace experiments
