#include "experiments/studies/DepthStudy.h"

#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "experiments/CommandErrors.h"
#include "experiments/output/AtomicFile.h"
#include "experiments/output/PlotScript.h"
#include "experiments/studies/DepthSampler.h"
#include "experiments/studies/DepthStudyOutputs.h"
#include "experiments/studies/StudyPlots.h"
#include "experiments/sweep/CsvTable.h"

namespace experiments {

namespace {

using gbuffer::DepthFormatSpec;

constexpr double kOnePerMille = 1e-3;
// The first and last distances sit this far (relative) inside the near and far planes: a surface
// exactly on a plane is clipped or equal to the clear value by the float matrix's rounding in
// every format, which says nothing about the format. 1e-6 is ~10 float ulps, well inside.
constexpr double kPlaneInsetRelative = 1e-6;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr size_t kMethodCount = std::size(kDepthStudyMethods);

void validate(const DepthStudyOptions& o) {
    if (o.cameras.empty() || o.formats.empty())
        throw std::invalid_argument("depth study: no cameras or no formats");
    if (o.distanceCount < 2 || o.pixelColumns < 2 || o.pixelRows < 2)
        throw std::invalid_argument(
            "depth study: distanceCount, pixelColumns and pixelRows must be >= 2");
    if (o.width < 2 || o.height < 2 || o.pixelColumns > o.width || o.pixelRows > o.height)
        throw std::invalid_argument(
            "depth study: the pixel grid must fit a screen of at least 2x2");
    if (!(o.verticalFovDegrees > 0.0 && o.verticalFovDegrees < 180.0))
        throw std::invalid_argument("depth study: verticalFovDegrees must be in (0, 180)");
    for (const DepthStudyCamera& c : o.cameras)
        if (!(c.nearMetres > 0.0 && c.farMetres > c.nearMetres && std::isfinite(c.farMetres)))
            throw std::invalid_argument("depth study: a camera needs 0 < near < far (finite)");
}

// Grid coordinate i of count over [0, size - 1], ends included.
int gridPixel(int i, int count, int size) {
    return int(std::lround(double(i) * double(size - 1) / double(count - 1)));
}

// The pixel grid over the screen, corners included, row by row.
std::vector<glm::ivec2> pixelGrid(const DepthStudyOptions& options) {
    std::vector<glm::ivec2> pixels;
    for (int j = 0; j < options.pixelRows; ++j)
        for (int i = 0; i < options.pixelColumns; ++i)
            pixels.emplace_back(gridPixel(i, options.pixelColumns, options.width),
                                gridPixel(j, options.pixelRows, options.height));
    return pixels;
}

// The errors of one (format, method, camera) at distance d over the pixel grid.
DepthErrorRow measureDistance(const DepthSampler& sampler, DepthFormatSpec format,
                              gbuffer::PositionMethod method, DepthStudyCamera camera, double d,
                              const std::vector<glm::ivec2>& pixels) {
    DepthErrorRow row = {format, method, camera, d};
    double relativeSum = 0.0;
    for (const glm::ivec2& pixel : pixels) {
        ++row.sampleCount;
        const glm::dvec3 exact = sampler.exactPointView(pixel.x, pixel.y, d);
        const float depthNdc = sampler.rasterDepthNdc(exact);
        if (sampler.lost(depthNdc)) {
            ++row.lostCount;
            continue;
        }
        const glm::dvec3 got(sampler.reconstruct(method, pixel.x, pixel.y, depthNdc));
        const double error = glm::length(got - exact);
        relativeSum += error / d;
        row.maxRelativeError = std::max(row.maxRelativeError, error / d);
        row.maxAbsoluteErrorMetres = std::max(row.maxAbsoluteErrorMetres, error);
    }
    const int measured = row.sampleCount - row.lostCount;
    row.meanRelativeError = measured > 0 ? relativeSum / measured : kNaN;
    if (measured == 0)
        row.maxRelativeError = row.maxAbsoluteErrorMetres = kNaN;
    return row;
}

// Series s = (camera, format) fills its own fixed slice of rows and steps, so the series run in
// parallel with a result independent of the thread count.
void measureSeries(const DepthStudyOptions& options, size_t s,
                   const std::vector<glm::ivec2>& pixels, DepthStudyResult& result) {
    const size_t formatCount = options.formats.size();
    const size_t distanceCount = size_t(options.distanceCount);
    const DepthStudyCamera camera = options.cameras[s / formatCount];
    const DepthFormatSpec format = options.formats[s % formatCount];
    const DepthSampler sampler(options, camera, format);
    const std::vector<double> distances = depthStudyDistances(options, camera);
    for (size_t di = 0; di < distanceCount; ++di) {
        const double d = distances[di];
        result.steps[s * distanceCount + di] = {format, camera, d, sampler.depthStepMetres(d)};
        for (size_t m = 0; m < kMethodCount; ++m)
            result.rows[(s * kMethodCount + m) * distanceCount + di] =
                measureDistance(sampler, format, kDepthStudyMethods[m], camera, d, pixels);
    }
}

// The figures of the printed table for the rows [first, first + distanceCount) of one series.
DepthSeriesSummary summarise(const DepthErrorRow* rows, size_t distanceCount) {
    DepthSeriesSummary summary;
    summary.format = rows[0].format;
    summary.method = rows[0].method;
    summary.camera = rows[0].camera;
    int farSamples = 0, farLost = 0;
    for (size_t di = 0; di < distanceCount; ++di) {
        const DepthErrorRow& row = rows[di];
        if (row.distanceMetres >= row.camera.farMetres / 2.0) {
            farSamples += row.sampleCount;
            farLost += row.lostCount;
            if (!std::isnan(row.maxRelativeError))
                summary.farEndMaxRelativeError =
                    std::max(summary.farEndMaxRelativeError, row.maxRelativeError);
        }
        const bool fails = row.lostCount > 0 || row.maxRelativeError > kOnePerMille;
        if (fails && !summary.firstDistanceAboveOnePerMille)
            summary.firstDistanceAboveOnePerMille = row.distanceMetres;
    }
    summary.farEndLostFraction = farSamples > 0 ? double(farLost) / farSamples : 0.0;
    return summary;
}

} // namespace

DepthStudyOptions DepthStudyOptions::quick() {
    DepthStudyOptions options;
    options.distanceCount = 40;
    options.pixelColumns = 16;
    options.pixelRows = 9;
    return options;
}

std::vector<double> depthStudyDistances(const DepthStudyOptions& options, DepthStudyCamera camera) {
    const double first = camera.nearMetres * (1.0 + kPlaneInsetRelative);
    const double last = camera.farMetres * (1.0 - kPlaneInsetRelative);
    std::vector<double> distances(size_t(options.distanceCount));
    for (int i = 0; i < options.distanceCount; ++i)
        distances[size_t(i)] =
            first * std::pow(last / first, double(i) / double(options.distanceCount - 1));
    distances.back() = last; // exactly, not pow's rounding of it
    return distances;
}

DepthStudyResult runDepthStudy(const DepthStudyOptions& options) {
    validate(options);
    const auto start = std::chrono::steady_clock::now();
    DepthStudyResult result;
    result.options = options;
    const std::vector<glm::ivec2> pixels = pixelGrid(options);
    const size_t seriesCount = options.cameras.size() * options.formats.size();
    const size_t distanceCount = size_t(options.distanceCount);
    result.rows.resize(seriesCount * kMethodCount * distanceCount);
    result.steps.resize(seriesCount * distanceCount);
    tbb::parallel_for(size_t(0), seriesCount,
                      [&](size_t s) { measureSeries(options, s, pixels, result); });
    for (size_t series = 0; series < seriesCount * kMethodCount; ++series)
        result.summaries.push_back(summarise(&result.rows[series * distanceCount], distanceCount));
    result.studySeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

int runDepthCommand(const DepthCommandOptions& options) {
    try {
        const std::filesystem::path script = requirePlotScript(options.plotsScript, "depth.py");
        ensureWritableDirectory(options.out);
        const DepthStudyResult result =
            runDepthStudy(options.quick ? DepthStudyOptions::quick() : DepthStudyOptions{});
        writeTextAtomically(options.out / "depth.csv", depthStudyCsv(result));
        writeTextAtomically(options.out / "depth_steps.csv", depthStepsCsv(result));
        writeTextAtomically(options.out / "depth.json", depthStudyJson(result).dump(1) + "\n");
        std::cout << depthSummaryTable(result) << "\n";
        runStudyPlots(options.python, script,
                      {(options.out / "depth.json").string(), options.out.string()},
                      "depth.csv and depth.json are in " + options.out.string());
        std::cout << "study " << csvNumber(result.studySeconds) << " s; outputs in "
                  << options.out.string() << "\n";
        return 0;
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

} // namespace experiments
