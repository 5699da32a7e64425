// DepthStudy: `testbed depth --out DIR [--quick]`, the depth-format and position-reconstruction
// study of issue #4. For every depth format (gbuffer/codecs/DepthFormat.h, finite and infinite far
// plane) x reconstruction method (inverse projection, view ray) x camera (near/far planes), it
// measures the view-space position the G-buffer gives back against the exact position, as a
// function of distance, and the depth step (metres between neighbouring codes) of each format.
//
// The model of one sample, as the G-buffer pass does it (gbuffer/GBufferPass.cpp, raster/):
//   1. the exact view-space point p (double) at view depth d on the ray through a pixel centre of
//      a width x height screen (vertical field of view fovY), camera at the origin looking down -Z;
//   2. NDC depth as the rasterizer computes it: the FLOAT projection matrix of
//      CameraView::fromCamera(camera, width, height, format.convention(), format.infiniteFar)
//      applied to p, z / w evaluated in double and rounded once to float (the rasterizer
//      interpolates a double depth plane through float clip-space vertices and rounds to float;
//      the float rounding of the vertex transform itself, at most ~1 ulp more, is not modelled);
//   3. a sample whose float NDC depth is outside [0, 1] (clipped) or equal to the clear value (it
//      fails the Less / Greater depth test against the cleared buffer) is lost: the pixel reads as
//      background. Lost samples are counted, not measured;
//   4. encodeDepth, then decodeDepthNdc + positionByInverseProjection or decodeViewDepth +
//      positionByViewRay, all in float with the float matrices, as GBuffer would;
//   5. errors |p' - p| (metres) and |p' - p| / d (relative to the view depth d).
// Distances are log-spaced from near to far, the two ends 1e-6 (relative) inside the planes (a
// surface exactly on a plane is clipped or reads as background in every format: the float
// matrix's rounding decides, not the format); an infinite-far format uses the camera's far value
// only as the end of the measured range. Relative errors are per view depth d, so a pixel in a
// screen corner, whose ray is up to |(x, y, -1)| = 1.55 times longer at 60 degrees and 16:9,
// shows up to 1.55 times the relative depth error. Pixels are a grid over the whole screen that
// includes the four corners.
//
// Outputs (runDepthCommand): DIR/depth.csv and DIR/depth.json (one row per format x infinite x
// method x camera x distance: mean/max relative error, max absolute error, sample and lost
// counts), DIR/depth_steps.csv (depth step per format x camera x distance), and two matplotlib
// plots drawn by experiments/plots/depth.py: position_error_vs_distance.png and
// depth_step_vs_distance.png. depth.json also holds the steps, a per-series summary, the options,
// the commit, the machine's thread count and the study's time. Every file is written under a
// temporary name and renamed.
//
// Pieces (experiments/studies/): DepthSampler.h (the sample model, steps 1-4), DepthStudy.cpp
// (the statistics over the pixel grid and the per-series summary, the command),
// DepthStudyOutputs.h (CSV through CsvTable, JSON, the printed table), StudyPlots.h (the plots).
//
// Thread safety: runDepthStudy runs the (format, camera) series in parallel (TBB), each writing
// only its own rows, so the result is identical for any thread count. All functions share no
// state.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "gbuffer/codecs/DepthFormat.h"

namespace experiments {

// The reconstruction methods the study compares, in row order.
inline constexpr gbuffer::PositionMethod kDepthStudyMethods[] = {
    gbuffer::PositionMethod::InverseProjection, gbuffer::PositionMethod::ViewRay};

struct DepthStudyCamera {
    double nearMetres = 0.1;
    double farMetres = 1000.0;
};

struct DepthStudyOptions {
    // The range "0.01/100 to 0.1/10000", plus a near plane pushed out to 1 m.
    std::vector<DepthStudyCamera> cameras{
        {0.01, 100.0}, {0.1, 1000.0}, {0.1, 10000.0}, {1.0, 10000.0}};
    std::vector<gbuffer::DepthFormatSpec> formats = gbuffer::allDepthFormatSpecs();
    int distanceCount = 200; // log-spaced, near..far (just inside both)
    int pixelColumns = 64;   // pixel grid over the screen, corners included
    int pixelRows = 36;
    int width = 1280;
    int height = 720;
    double verticalFovDegrees = 60.0;

    // A few seconds' worth: 40 distances, a 16 x 9 pixel grid, every format and camera.
    static DepthStudyOptions quick();
};

// Errors of one (format, method, camera) at one distance, over the pixel grid.
struct DepthErrorRow {
    gbuffer::DepthFormatSpec format;
    gbuffer::PositionMethod method = gbuffer::PositionMethod::InverseProjection;
    DepthStudyCamera camera;
    double distanceMetres = 0.0;
    double meanRelativeError = 0.0; // over measured (not lost) samples; NaN when all are lost
    double maxRelativeError = 0.0;
    double maxAbsoluteErrorMetres = 0.0;
    int sampleCount = 0; // pixels in the grid
    int lostCount = 0;   // samples read as background (see the model above)
};

// Metres between the code a surface at `distanceMetres` encodes to and its farther neighbour
// (the nearer one when there is no farther code), each code's value taken exactly (double).
struct DepthStepRow {
    gbuffer::DepthFormatSpec format;
    DepthStudyCamera camera;
    double distanceMetres = 0.0;
    double stepMetres = 0.0; // NaN when the surface is lost (its NDC depth is the clear value)
};

// Per (format, method, camera): the figures of the printed table.
struct DepthSeriesSummary {
    gbuffer::DepthFormatSpec format;
    gbuffer::PositionMethod method = gbuffer::PositionMethod::InverseProjection;
    DepthStudyCamera camera;
    // Over distances in [far / 2, far]: max relative error of measured samples, lost fraction.
    double farEndMaxRelativeError = 0.0;
    double farEndLostFraction = 0.0;
    // First distance whose max relative error exceeds 1e-3 or that loses a sample; nullopt if
    // none does.
    std::optional<double> firstDistanceAboveOnePerMille;
};

struct DepthStudyResult {
    DepthStudyOptions options;
    std::vector<DepthErrorRow> rows;
    std::vector<DepthStepRow> steps;
    std::vector<DepthSeriesSummary> summaries;
    double studySeconds = 0.0;
};

// The distances the study measures: log-spaced from just inside near to just inside far.
std::vector<double> depthStudyDistances(const DepthStudyOptions& options, DepthStudyCamera camera);

// Runs the study. Throws std::invalid_argument for empty lists, counts < 2, sizes < 1, a field of
// view outside (0, 180) degrees, or a camera without 0 < near < far.
DepthStudyResult runDepthStudy(const DepthStudyOptions& options);

struct DepthCommandOptions {
    std::filesystem::path out = "depth";
    bool quick = false;
    // Empty = experiments/plots/depth.py of the source tree this binary was built from.
    std::filesystem::path plotsScript;
    // Empty = found by findPythonWithMatplotlib (experiments/output/PlotScript.h).
    std::string python;
};

// Runs the study, writes the outputs, draws the plots, prints the summary and "outputs in DIR";
// returns the exit code. Errors (unwritable folder, missing python3/matplotlib or script, failing
// script) are one line "testbed: error: ..." on stderr and exit code 1; the CSV and JSON files
// are written before the plots are attempted.
int runDepthCommand(const DepthCommandOptions& options);

} // namespace experiments
