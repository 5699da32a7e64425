#include "experiments/DepthStudy.h"
#include "experiments/BuildCommit.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <Imath/half.h>
#include <tbb/parallel_for.h>

#include "experiments/AtomicFile.h"
#include "experiments/PlotScript.h"
#include "scenes/Scene.h"

#ifndef TESTBED_SOURCE_DIR
#define TESTBED_SOURCE_DIR "."
#endif

namespace experiments {

namespace {

using gbuffer::DepthFormatKind;
using gbuffer::DepthFormatSpec;
using gbuffer::PositionMethod;

constexpr double kPi = 3.14159265358979323846;
constexpr double kOnePerMille = 1e-3;
// The first and last distances sit this far (relative) inside the near and far planes: a surface
// exactly on a plane is clipped or equal to the clear value by the float matrix's rounding in
// every format, which says nothing about the format. 1e-6 is ~10 float ulps, well inside.
constexpr double kPlaneInsetRelative = 1e-6;
constexpr PositionMethod kMethods[] = {PositionMethod::InverseProjection, PositionMethod::ViewRay};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Largest finite half's bits; the bit patterns of non-negative halves are ordered like their
// values.
constexpr uint64_t kHalfMaxFiniteBits = 0x7BFF;
constexpr uint64_t kFloatOneBits = 0x3F800000; // NDC depth never exceeds 1

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

std::string cameraText(DepthStudyCamera c) {
    char text[64];
    std::snprintf(text, sizeof text, "%g/%g", c.nearMetres, c.farMetres);
    return text;
}

std::string number(double value) {
    if (std::isnan(value))
        return "nan";
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

nlohmann::json jsonNumber(double value) {
    return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

} // namespace

DepthStudyOptions DepthStudyOptions::quick() {
    DepthStudyOptions options;
    options.distanceCount = 40;
    options.pixelColumns = 16;
    options.pixelRows = 9;
    return options;
}

// ---- DepthSampler ----------------------------------------------------------------------------

DepthSampler::DepthSampler(const DepthStudyOptions& options, DepthStudyCamera camera,
                           DepthFormatSpec format)
    : mFormat(format) {
    scenes::Camera c; // at the origin, looking down -Z, +Y up: view space is world space
    c.verticalFovRadians = float(options.verticalFovDegrees * kPi / 180.0);
    c.nearMetres = float(camera.nearMetres);
    c.farMetres = float(camera.farMetres);
    mView = gbuffer::CameraView::fromCamera(c, options.width, options.height, format.convention(),
                                            format.infiniteFar);
    mProjection = gbuffer::DepthProjection::of(mView);
    mRasterClipFromView = glm::dmat4(mView.clipFromView);
    // glm::perspective: [1][1] = 1 / tan(fovY / 2), [0][0] = [1][1] / aspect, from the same
    // float field of view the CameraView was built from.
    const double tanHalf = std::tan(double(c.verticalFovRadians) / 2.0);
    mViewYPerNdc = tanHalf;
    mViewXPerNdc = tanHalf * double(options.width) / double(options.height);
}

glm::dvec3 DepthSampler::exactPointView(int x, int y, double d) const {
    const double ndcX = (double(x) + 0.5) / double(mView.width) * 2.0 - 1.0;
    const double ndcY = 1.0 - (double(y) + 0.5) / double(mView.height) * 2.0;
    return {ndcX * d * mViewXPerNdc, ndcY * d * mViewYPerNdc, -d};
}

float DepthSampler::rasterDepthNdc(const glm::dvec3& pointView) const {
    const glm::dvec4 clip = mRasterClipFromView * glm::dvec4(pointView, 1.0);
    return float(clip.z / clip.w);
}

bool DepthSampler::lost(float depthNdc) const {
    return !(depthNdc >= 0.0f && depthNdc <= 1.0f) || depthNdc == mProjection.clearDepthNdc();
}

glm::vec3 DepthSampler::reconstruct(PositionMethod method, int x, int y, float depthNdc) const {
    const uint32_t code = gbuffer::encodeDepth(mFormat, mProjection, depthNdc);
    const glm::vec2 ndc = mView.ndcOfPixel(x, y);
    if (method == PositionMethod::InverseProjection)
        return gbuffer::positionByInverseProjection(
            mView, ndc, gbuffer::decodeDepthNdc(mFormat, mProjection, code));
    return gbuffer::positionByViewRay(mView, ndc,
                                      gbuffer::decodeViewDepth(mFormat, mProjection, code));
}

bool DepthSampler::validCode(uint64_t code) const {
    if (code == gbuffer::clearDepthCode(mFormat, mProjection))
        return false;
    switch (mFormat.kind) {
    case DepthFormatKind::F32:
    case DepthFormatKind::F32Reversed:
        return code <= kFloatOneBits;
    case DepthFormatKind::Unorm24:
    case DepthFormatKind::Unorm16:
        return code < (uint64_t(1) << mFormat.bits());
    case DepthFormatKind::F16Linear:
        return code <= kHalfMaxFiniteBits;
    }
    return false;
}

double DepthSampler::codeViewDepthExact(uint32_t code) const {
    switch (mFormat.kind) {
    case DepthFormatKind::F32:
    case DepthFormatKind::F32Reversed:
        return mProjection.viewDepthFromNdc(double(std::bit_cast<float>(code)));
    case DepthFormatKind::Unorm24:
    case DepthFormatKind::Unorm16:
        return mProjection.viewDepthFromNdc(double(code) /
                                            double((uint64_t(1) << mFormat.bits()) - 1));
    case DepthFormatKind::F16Linear: {
        Imath::half h;
        h.setBits(uint16_t(code));
        return double(float(h));
    }
    }
    return kNaN;
}

double DepthSampler::depthStepMetres(double viewDepthMetres) const {
    const float depthNdc = rasterDepthNdc({0.0, 0.0, -viewDepthMetres});
    if (lost(depthNdc))
        return kNaN;
    const uint32_t code = gbuffer::encodeDepth(mFormat, mProjection, depthNdc);
    const double here = codeViewDepthExact(code);
    double farther = kNaN, nearer = kNaN;
    for (int64_t delta : {-1, 1}) {
        const int64_t neighbour = int64_t(code) + delta;
        if (neighbour < 0 || !validCode(uint64_t(neighbour)))
            continue;
        const double d = codeViewDepthExact(uint32_t(neighbour));
        if (!(std::isfinite(d) && d > 0.0))
            continue;
        (d > here ? farther : nearer) = d;
    }
    return !std::isnan(farther) ? farther - here : here - nearer;
}

// ---- the study -------------------------------------------------------------------------------

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

    std::vector<glm::ivec2> pixels;
    for (int j = 0; j < options.pixelRows; ++j)
        for (int i = 0; i < options.pixelColumns; ++i)
            pixels.emplace_back(gridPixel(i, options.pixelColumns, options.width),
                                gridPixel(j, options.pixelRows, options.height));

    // Series s = (camera, format); each owns a fixed slice of rows and steps.
    const size_t formatCount = options.formats.size(), cameraCount = options.cameras.size();
    const size_t distanceCount = size_t(options.distanceCount), methodCount = std::size(kMethods);
    const size_t seriesCount = cameraCount * formatCount;
    result.rows.resize(seriesCount * methodCount * distanceCount);
    result.steps.resize(seriesCount * distanceCount);
    tbb::parallel_for(size_t(0), seriesCount, [&](size_t s) {
        const DepthStudyCamera camera = options.cameras[s / formatCount];
        const DepthFormatSpec format = options.formats[s % formatCount];
        const DepthSampler sampler(options, camera, format);
        const std::vector<double> distances = depthStudyDistances(options, camera);
        for (size_t di = 0; di < distanceCount; ++di) {
            const double d = distances[di];
            result.steps[s * distanceCount + di] = {format, camera, d, sampler.depthStepMetres(d)};
            for (size_t m = 0; m < methodCount; ++m) {
                DepthErrorRow& row = result.rows[(s * methodCount + m) * distanceCount + di];
                row = {format, kMethods[m], camera, d};
                double relativeSum = 0.0;
                for (const glm::ivec2& pixel : pixels) {
                    ++row.sampleCount;
                    const glm::dvec3 exact = sampler.exactPointView(pixel.x, pixel.y, d);
                    const float depthNdc = sampler.rasterDepthNdc(exact);
                    if (sampler.lost(depthNdc)) {
                        ++row.lostCount;
                        continue;
                    }
                    const glm::dvec3 got(
                        sampler.reconstruct(kMethods[m], pixel.x, pixel.y, depthNdc));
                    const double error = glm::length(got - exact);
                    relativeSum += error / d;
                    row.maxRelativeError = std::max(row.maxRelativeError, error / d);
                    row.maxAbsoluteErrorMetres = std::max(row.maxAbsoluteErrorMetres, error);
                }
                const int measured = row.sampleCount - row.lostCount;
                row.meanRelativeError = measured > 0 ? relativeSum / measured : kNaN;
                if (measured == 0)
                    row.maxRelativeError = row.maxAbsoluteErrorMetres = kNaN;
            }
        }
    });

    for (size_t series = 0; series < seriesCount * methodCount; ++series) {
        const DepthErrorRow& first = result.rows[series * distanceCount];
        DepthSeriesSummary summary;
        summary.format = first.format;
        summary.method = first.method;
        summary.camera = first.camera;
        int farSamples = 0, farLost = 0;
        for (size_t di = 0; di < distanceCount; ++di) {
            const DepthErrorRow& row = result.rows[series * distanceCount + di];
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
        result.summaries.push_back(summary);
    }
    result.studySeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

// ---- outputs ---------------------------------------------------------------------------------

std::string depthStudyCsv(const DepthStudyResult& result) {
    std::ostringstream csv;
    csv << "format,infinite,method,near,far,distance,mean_rel_error,max_rel_error,max_abs_error_m,"
           "samples,lost_samples\n";
    for (const DepthErrorRow& r : result.rows)
        csv << gbuffer::depthFormatName(r.format.kind) << ',' << (r.format.infiniteFar ? 1 : 0)
            << ',' << gbuffer::positionMethodName(r.method) << ',' << number(r.camera.nearMetres)
            << ',' << number(r.camera.farMetres) << ',' << number(r.distanceMetres) << ','
            << number(r.meanRelativeError) << ',' << number(r.maxRelativeError) << ','
            << number(r.maxAbsoluteErrorMetres) << ',' << r.sampleCount << ',' << r.lostCount
            << '\n';
    return csv.str();
}

std::string depthStepsCsv(const DepthStudyResult& result) {
    std::ostringstream csv;
    csv << "format,infinite,near,far,distance,depth_step_m,codes_per_metre\n";
    for (const DepthStepRow& r : result.steps)
        csv << gbuffer::depthFormatName(r.format.kind) << ',' << (r.format.infiniteFar ? 1 : 0)
            << ',' << number(r.camera.nearMetres) << ',' << number(r.camera.farMetres) << ','
            << number(r.distanceMetres) << ',' << number(r.stepMetres) << ','
            << number(1.0 / r.stepMetres) << '\n';
    return csv.str();
}

nlohmann::json depthStudyJson(const DepthStudyResult& result) {
    const DepthStudyOptions& o = result.options;
    nlohmann::json json;
    json["command"] = "depth";
    json["commit"] = kBuildCommit;
    json["hardware_threads"] = std::thread::hardware_concurrency();
    json["study_seconds"] = result.studySeconds;
    nlohmann::json& options = json["options"];
    for (const DepthStudyCamera& c : o.cameras)
        options["cameras"].push_back({{"near", c.nearMetres}, {"far", c.farMetres}});
    for (const DepthFormatSpec& f : o.formats)
        options["formats"].push_back(f.text());
    options["distance_count"] = o.distanceCount;
    options["pixel_grid"] = {o.pixelColumns, o.pixelRows};
    options["width"] = o.width;
    options["height"] = o.height;
    options["vertical_fov_degrees"] = o.verticalFovDegrees;
    json["model"] =
        "float NDC depth of the exact point through the float projection (z/w in double, rounded "
        "once); NDC outside [0,1] or equal to the clear value is lost (background); reconstruction "
        "in float as GBuffer does; relative error = |p' - p| / view depth";
    nlohmann::json& rows = json["rows"];
    rows = nlohmann::json::array();
    for (const DepthErrorRow& r : result.rows)
        rows.push_back({{"format", gbuffer::depthFormatName(r.format.kind)},
                        {"infinite", r.format.infiniteFar},
                        {"method", gbuffer::positionMethodName(r.method)},
                        {"near", r.camera.nearMetres},
                        {"far", r.camera.farMetres},
                        {"distance", r.distanceMetres},
                        {"mean_rel_error", jsonNumber(r.meanRelativeError)},
                        {"max_rel_error", jsonNumber(r.maxRelativeError)},
                        {"max_abs_error_m", jsonNumber(r.maxAbsoluteErrorMetres)},
                        {"samples", r.sampleCount},
                        {"lost_samples", r.lostCount}});
    nlohmann::json& steps = json["steps"];
    steps = nlohmann::json::array();
    for (const DepthStepRow& r : result.steps)
        steps.push_back({{"format", gbuffer::depthFormatName(r.format.kind)},
                         {"infinite", r.format.infiniteFar},
                         {"near", r.camera.nearMetres},
                         {"far", r.camera.farMetres},
                         {"distance", r.distanceMetres},
                         {"depth_step_m", jsonNumber(r.stepMetres)}});
    nlohmann::json& summary = json["summary"];
    summary = nlohmann::json::array();
    for (const DepthSeriesSummary& s : result.summaries)
        summary.push_back(
            {{"format", gbuffer::depthFormatName(s.format.kind)},
             {"infinite", s.format.infiniteFar},
             {"method", gbuffer::positionMethodName(s.method)},
             {"near", s.camera.nearMetres},
             {"far", s.camera.farMetres},
             {"far_end_max_rel_error", jsonNumber(s.farEndMaxRelativeError)},
             {"far_end_lost_fraction", s.farEndLostFraction},
             {"first_distance_rel_error_above_1e-3",
              s.firstDistanceAboveOnePerMille ? nlohmann::json(*s.firstDistanceAboveOnePerMille)
                                              : nlohmann::json(nullptr)}});
    return json;
}

std::string depthSummaryTable(const DepthStudyResult& result) {
    std::ostringstream table;
    table
        << "max relative position error |p' - p| / d over d in [far/2, far]; lost = fraction of "
           "those samples read as background;\nfirst > 1e-3 = first distance (m) with error > 1e-3 "
           "or a lost sample\n";
    const size_t methodCount = std::size(kMethods);
    std::string lastCamera;
    char line[200];
    // Summaries are ordered camera, format, method: one line per (camera, format).
    for (size_t i = 0; i + methodCount <= result.summaries.size(); i += methodCount) {
        const DepthSeriesSummary& inverse = result.summaries[i];
        const DepthSeriesSummary& ray = result.summaries[i + 1];
        const std::string camera = cameraText(inverse.camera);
        if (camera != lastCamera) {
            table << "\ncamera near/far " << camera << " m\n";
            std::snprintf(line, sizeof line, "  %-22s %12s %12s %7s %14s %14s\n", "format",
                          "inv-proj", "view-ray", "lost", "first>1e-3 ip", "first>1e-3 vr");
            table << line;
            lastCamera = camera;
        }
        auto first = [](const DepthSeriesSummary& s) {
            return s.firstDistanceAboveOnePerMille ? number(*s.firstDistanceAboveOnePerMille)
                                                   : std::string("-");
        };
        std::snprintf(line, sizeof line, "  %-22s %12.3g %12.3g %6.1f%% %14s %14s\n",
                      inverse.format.text().c_str(), inverse.farEndMaxRelativeError,
                      ray.farEndMaxRelativeError, 100.0 * inverse.farEndLostFraction,
                      first(inverse).c_str(), first(ray).c_str());
        table << line;
    }
    return table.str();
}

// ---- the command -----------------------------------------------------------------------------

std::filesystem::path defaultDepthPlotsScript() {
    return plotScriptPath("depth.py");
}

int runDepthCommand(const DepthCommandOptions& options) {
    auto fail = [](const std::string& message) {
        std::cerr << "testbed: error: " << message << "\n";
        return 1;
    };
    const std::filesystem::path script =
        options.plotsScript.empty() ? defaultDepthPlotsScript() : options.plotsScript;
    try {
        ensureWritableDirectory(options.out);
        if (!std::filesystem::is_regular_file(script))
            return fail("plot script " + script.string() + " not found (--plots-script PATH)");
        const DepthStudyResult result =
            runDepthStudy(options.quick ? DepthStudyOptions::quick() : DepthStudyOptions{});
        writeTextAtomically(options.out / "depth.csv", depthStudyCsv(result));
        writeTextAtomically(options.out / "depth_steps.csv", depthStepsCsv(result));
        writeTextAtomically(options.out / "depth.json", depthStudyJson(result).dump(1) + "\n");
        std::cout << depthSummaryTable(result) << "\n";

        const std::string python = findPythonWithMatplotlib(options.python);
        if (python.empty())
            return fail("plots need python3 with matplotlib (Debian: apt-get install "
                        "python3-matplotlib; or --python PATH); depth.csv and depth.json are in " +
                        options.out.string());
        const int status = runProcess(
            {python, script.string(), (options.out / "depth.json").string(), options.out.string()});
        if (status != 0)
            return fail("plot script failed (" + python + " " + script.string() +
                        "), exit status " + std::to_string(status));
        std::cout << "study " << number(result.studySeconds) << " s; outputs in "
                  << options.out.string() << "\n";
        return 0;
    } catch (const std::exception& e) {
        return fail(e.what());
    }
}

} // namespace experiments
