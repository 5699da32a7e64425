#include "experiments/studies/DepthStudyOutputs.h"
#include "experiments/BuildCommit.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <thread>

#include "experiments/sweep/CsvTable.h"

namespace experiments {

namespace {

using gbuffer::DepthFormatSpec;

std::string cameraText(DepthStudyCamera c) {
    char text[64];
    std::snprintf(text, sizeof text, "%g/%g", c.nearMetres, c.farMetres);
    return text;
}

nlohmann::json jsonNumber(double value) {
    return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

} // namespace

std::string depthStudyCsv(const DepthStudyResult& result) {
    CsvTable table({"format", "infinite", "method", "near", "far", "distance", "mean_rel_error",
                    "max_rel_error", "max_abs_error_m", "samples", "lost_samples"});
    for (const DepthErrorRow& r : result.rows)
        table.addRow({gbuffer::depthFormatName(r.format.kind), r.format.infiniteFar ? "1" : "0",
                      gbuffer::positionMethodName(r.method), csvNumber(r.camera.nearMetres),
                      csvNumber(r.camera.farMetres), csvNumber(r.distanceMetres),
                      csvNumber(r.meanRelativeError), csvNumber(r.maxRelativeError),
                      csvNumber(r.maxAbsoluteErrorMetres), std::to_string(r.sampleCount),
                      std::to_string(r.lostCount)});
    return table.text();
}

std::string depthStepsCsv(const DepthStudyResult& result) {
    CsvTable table(
        {"format", "infinite", "near", "far", "distance", "depth_step_m", "codes_per_metre"});
    for (const DepthStepRow& r : result.steps)
        table.addRow({gbuffer::depthFormatName(r.format.kind), r.format.infiniteFar ? "1" : "0",
                      csvNumber(r.camera.nearMetres), csvNumber(r.camera.farMetres),
                      csvNumber(r.distanceMetres), csvNumber(r.stepMetres),
                      csvNumber(1.0 / r.stepMetres)});
    return table.text();
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
    const size_t methodCount = std::size(kDepthStudyMethods);
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
            return s.firstDistanceAboveOnePerMille ? csvNumber(*s.firstDistanceAboveOnePerMille)
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

} // namespace experiments
