// FlipMetric: HDR-ꟻLIP (NVIDIA's perceptual image difference; Andersson et al., "Visualizing
// Errors in Rendered High Dynamic Range Images", Eurographics 2021) of a render against its
// reference, beside RMSE and PSNR in `render --compare-reference`, `diff` and every sweep row.
//
// The testbed does not implement ꟻLIP: it runs NVIDIA's official implementation, the Python
// package flip-evaluator, through experiments/plots/flip.py (which says why HDR-ꟻLIP: our images
// are linear radiance). The package lives in the project's virtual environment, made by
// ./run.sh: .venv/bin/python3 of the source tree (a venv that sees Debian's numpy), or the Python
// named by the environment variable TESTBED_FLIP_PYTHON. When that Python or the package is
// missing (e.g. the machine cannot reach the Python package index), ꟻLIP is UNAVAILABLE: the
// figure is empty (null) and every output says why (FlipResult::unavailableReason, written as
// "flip_unavailable"); nothing fails because of it.
//
// Conventions: images are StageResult planes (linear R, G, B, row 0 at the top); the reference
// is the second argument; the error map holds one value per pixel in [0, 1] (0 = no visible
// difference); the mean is over all pixels. The parameters are the package's defaults (67 pixels
// per degree, ACES tone mapper, exposures from the reference), recorded with the result so that a
// reader sees what was assumed; jobs sharing a reference share them.
//
// Cost: one Python process per comparison (about 0.2-0.5 s plus the metric itself); the check
// that the package imports runs once per process and Python. Thread-safe (the check is guarded;
// each comparison uses its own temporary folder).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/output/ImageOutput.h"
#include "lighting/ShadingStage.h"

namespace experiments {

// The environment variable that names the Python with flip-evaluator (overrides .venv).
inline constexpr const char* kFlipPythonVariable = "TESTBED_FLIP_PYTHON";
// The version ./run.sh installs (flip-evaluator on the Python package index).
inline constexpr const char* kFlipEvaluatorVersion = "1.6.0.1";

struct FlipResult {
    std::optional<double> mean;    // mean ꟻLIP error, 0..1; nullopt when unavailable
    std::string unavailableReason; // why mean is missing; "" when computed
    std::vector<float> errorMap;   // width * height values in [0, 1]; empty when unavailable
    nlohmann::json parameters;     // the package's: ppd, tonemapper, exposures, ... and
                                   // "version", "mode" ("HDR"); null when unavailable
};

// The Python that runs flip.py: $TESTBED_FLIP_PYTHON, else <source>/.venv/bin/python3.
std::string flipPython();

// "" when flip-evaluator imports in flipPython(), else the reason (no such Python, package not
// installed, ...), naming what to run to get it. Checked once per Python per process.
std::string flipUnavailableReason();

// HDR-ꟻLIP of `test` against `reference` (same size). Never throws for the metric's sake: an
// unavailable package, non-finite pixels or a failing script give a result without a mean and
// with the reason.
FlipResult computeFlip(const lighting::StageResult& test, const lighting::StageResult& reference);

// The style of flip.png: magma, linear from 0 to 1 (ꟻLIP's range), the same for every image.
ScalarMapStyle flipMapStyle();

} // namespace experiments
