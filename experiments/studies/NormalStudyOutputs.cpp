#include "experiments/studies/NormalStudyOutputs.h"
#include "experiments/BuildCommit.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "experiments/output/AtomicFile.h"
#include "experiments/sweep/CsvTable.h"

namespace experiments::normal_study {

namespace {

using Field = std::pair<const char*, nlohmann::json>;

// The columns of normals.csv and the keys of normals.json's rows, in CSV order.
std::vector<Field> rowFields(const NormalStudyRow& r) {
    return {{"codec", r.codec},
            {"name", r.name},
            {"bits", r.bits},
            {"dataset", r.dataset},
            {"samples", r.samples},
            {"nan_inf_outputs", r.nanInfOutputs},
            {"mean_deg", r.meanDegrees},
            {"rms_deg", r.rmsDegrees},
            {"p999_deg", r.p999Degrees},
            {"max_deg", r.maxDegrees},
            {"bound_deg", r.boundDegrees},
            {"bound_region_samples", r.boundRegionSamples},
            {"max_in_bound_region_deg", r.maxInBoundRegionDegrees},
            {"within_bound", r.withinBound()},
            {"negative_z_samples", r.negativeZSamples},
            {"mean_negative_z_deg", r.meanNegativeZDegrees},
            {"max_negative_z_deg", r.maxNegativeZDegrees},
            {"worse_than_octahedral", r.worseThanOctahedral},
            {"zero_vector_decodes_to", r.zeroVectorDecodesTo},
            {"occupancy", r.occupancy},
            {"occupancy_codes_tested", r.occupancyCodesTested},
            {"encode_per_s_1thread_study", r.encodePerSecond},
            {"decode_per_s_1thread_study", r.decodePerSecond}};
}

// A row value as CSV text: strings as they are, floating point with csvNumber, the rest as JSON.
std::string cellText(const nlohmann::json& value) {
    if (value.is_string())
        return value.get<std::string>();
    if (value.is_number_float())
        return csvNumber(value.get<double>());
    return value.dump();
}

nlohmann::json scenesJson(const std::vector<NormalStudyScene>& scenes) {
    nlohmann::json list = nlohmann::json::array();
    for (const NormalStudyScene& scene : scenes)
        list.push_back({{"dataset", scene.dataset},
                        {"source", scene.source},
                        {"width", scene.width},
                        {"height", scene.height},
                        {"covered_pixels", scene.coveredPixels},
                        {"negative_z_fraction", scene.negativeZFraction},
                        {"back_facing_fraction", scene.backFacingFraction},
                        {"normal_mapped_fraction", scene.normalMappedFraction},
                        {"geometric", scene.geometric}});
    return list;
}

nlohmann::json negativeZJson(const std::vector<NegativeZFraction>& fractions,
                             std::uint64_t samples) {
    nlohmann::json list = nlohmann::json::array();
    for (const NegativeZFraction& f : fractions)
        list.push_back({{"vertical_fov_deg", f.verticalFovDegrees},
                        {"aspect", f.aspect},
                        {"uniform_fraction", f.uniformFraction},
                        {"area_weighted_fraction", f.areaWeightedFraction},
                        {"uniform_exact", f.uniformExact},
                        {"area_weighted_exact", f.areaWeightedExact},
                        {"samples", samples}});
    return list;
}

const nlohmann::json kDatasetDescriptions = {
    {"sphere", "directions uniform on the sphere, central view ray"},
    {"visible-60",
     "front-facing normals weighted by projected area (cosine around -ray) for a "
     "uniformly random pixel of a 60 deg vertical FOV 16:9 camera; pixel-view gets the ray"},
    {"scene:NAME", "view-space normals of the covered pixels of a render of NAME (first camera), "
                   "with each pixel's view ray"},
    {"hard", "hardNormalCases(): axes, -Z and poles, octahedral edges, one zero component, back "
             "faces, near-unit, subnormal, huge, zero and non-finite inputs, off-axis and "
             "degenerate rays"}};

const NormalStudyRow* findRow(const NormalStudyResult& result, const std::string& codec,
                              const std::string& dataset) {
    for (const NormalStudyRow& row : result.rows)
        if (row.codec == codec && row.dataset == dataset)
            return &row;
    return nullptr;
}

void printCodecTable(const NormalStudyResult& result, std::ostream& out) {
    auto find = [&](const std::string& codec, const std::string& dataset) {
        return findRow(result, codec, dataset);
    };
    char line[400];
    out << "angular error in degrees; sphere = uniform directions, visible-60 = normals a 60 deg "
           "FOV "
           "camera sees\n";
    std::snprintf(line, sizeof line,
                  "%-24s | %9s %9s %9s | %9s %9s | %9s %5s | %8s | %7s %7s | %s\n", "codec", "mean",
                  "p99.9", "max", "vis.mean", "vis.max", "bound", "ok", "occupied", "enc M/s",
                  "dec M/s", "hard: NaN, max finite");
    out << line;
    std::vector<std::string> seen;
    for (const NormalStudyRow& row : result.rows) {
        if (std::find(seen.begin(), seen.end(), row.codec) != seen.end())
            continue;
        seen.push_back(row.codec);
        const NormalStudyRow* sphere = find(row.codec, "sphere");
        const NormalStudyRow* visible = find(row.codec, "visible-60");
        const NormalStudyRow* hard = find(row.codec, "hard");
        if (!sphere || !visible || !hard)
            continue;
        // "ok": the measured max inside the bound region is within the derived bound on sphere
        // and visible-60.
        const bool ok = sphere->withinBound() && visible->withinBound();
        std::snprintf(line, sizeof line,
                      "%-24s | %9.5f %9.5f %9.5f | %9.5f %9.5f | %9.5f %5s | %7.3f%% | %7.1f %7.1f "
                      "| %llu, %.3g\n",
                      row.codec.c_str(), sphere->meanDegrees, sphere->p999Degrees,
                      sphere->maxDegrees, visible->meanDegrees, visible->maxDegrees,
                      sphere->boundDegrees, ok ? "yes" : "NO", 100.0 * sphere->occupancy,
                      sphere->encodePerSecond * 1e-6, sphere->decodePerSecond * 1e-6,
                      static_cast<unsigned long long>(hard->nanInfOutputs), hard->maxDegrees);
        out << line;
    }
    out << "(bound = derived max error incl. float slack, checked inside each codec's bound "
           "region; "
           "enc/dec M/s = one thread, wall clock of this run)\n\n";
}

void printScenes(const NormalStudyResult& result, std::ostream& out) {
    char line[400];
    out << "rendered scenes: visible normals with view-space z < 0 and what xy-z does there\n";
    for (const NormalStudyScene& scene : result.scenes) {
        std::snprintf(line, sizeof line, "  %-22s %8llu px  z<0: %6.3f%%  back-facing: %6.3f%%",
                      scene.dataset.c_str(), static_cast<unsigned long long>(scene.coveredPixels),
                      100.0 * scene.negativeZFraction, 100.0 * scene.backFacingFraction);
        out << line;
        if (scene.normalMappedFraction > 0.0) {
            std::snprintf(line, sizeof line, "  normal-mapped: %6.3f%%",
                          100.0 * scene.normalMappedFraction);
            out << line;
        }
        for (const char* codec : {"xy-z:32", "pixel-view:32"})
            if (const NormalStudyRow* row = findRow(result, codec, scene.dataset)) {
                std::snprintf(line, sizeof line, "  %s on z<0: mean %.3f max %.3f deg", codec,
                              row->meanNegativeZDegrees, row->maxNegativeZDegrees);
                out << line;
            }
        out << "\n";
    }
}

void printNegativeZFractions(const NormalStudyResult& result, std::ostream& out) {
    char line[400];
    out << "\nfraction of visible surface orientations with view-space z < 0 (random pixel, "
           "front-facing orientation)\n";
    for (const NegativeZFraction& f : result.negativeZ) {
        std::snprintf(
            line, sizeof line,
            "  vertical FOV %4.0f deg, aspect %5.3f: area-weighted %6.3f%% (exact %6.3f%%), "
            "uniform %6.3f%% (exact %6.3f%%)\n",
            f.verticalFovDegrees, f.aspect, 100.0 * f.areaWeightedFraction,
            100.0 * f.areaWeightedExact, 100.0 * f.uniformFraction, 100.0 * f.uniformExact);
        out << line;
    }
}

} // namespace

std::string normalStudyCsv(const std::vector<NormalStudyRow>& rows) {
    std::vector<std::string> header;
    for (const auto& [name, value] : rowFields(NormalStudyRow{}))
        header.push_back(name);
    CsvTable table(header);
    for (const NormalStudyRow& row : rows) {
        std::vector<std::string> cells;
        for (const auto& [name, value] : rowFields(row))
            cells.push_back(cellText(value));
        table.addRow(std::move(cells));
    }
    return table.text();
}

nlohmann::json normalStudyJson(const NormalStudyResult& result, const StudyRecord& record) {
    nlohmann::json json;
    json["study"] = "normals";
    json["commit"] = kBuildCommit;
    json["hardware_threads"] = std::thread::hardware_concurrency();
    json["config"] = record.config;
    json["datasets"] = kDatasetDescriptions;
    json["rows"] = nlohmann::json::array();
    for (const NormalStudyRow& row : result.rows) {
        nlohmann::json object;
        for (const auto& [name, value] : rowFields(row))
            object[name] = value;
        json["rows"].push_back(std::move(object));
    }
    json["scenes"] = scenesJson(result.scenes);
    json["negative_z_fractions"] = negativeZJson(result.negativeZ, record.directions);
    json["maps"] = record.maps;
    json["hard_case_count"] = hardNormalCases().size();
    json["warnings"] = result.warnings;
    json["timings_s"] = record.timings;
    return json;
}

void writeFloats(const std::filesystem::path& path, const std::vector<float>& values) {
    writeFileAtomically(path, [&](const std::filesystem::path& temp) {
        std::ofstream file(temp, std::ios::binary);
        file.write(reinterpret_cast<const char*>(values.data()),
                   static_cast<std::streamsize>(values.size() * sizeof(float)));
        file.close(); // flushes: a full disk may only show here
        if (!file)
            throw std::runtime_error("cannot write " + temp.string());
    });
}

void printSummary(const NormalStudyResult& result, std::ostream& out) {
    printCodecTable(result, out);
    printScenes(result, out);
    printNegativeZFractions(result, out);
}

} // namespace experiments::normal_study
