// NormalStudy: `testbed normals`, the precision study of the G-buffer normal encodings
// (gbuffer/codecs/NormalCodec.h). For every codec x supported bit count it measures the angular
// error on
//   sphere        N directions uniform on the sphere (Archimedes: z and azimuth uniform);
//   visible-60    N normals as a pinhole camera sees them: a uniformly random pixel of a 16:9
//                 image with a 60 degree vertical field of view, and a surface orientation facing
//                 that pixel's ray, weighted by the area it covers on screen (cosine-weighted
//                 around -ray). This is where hemisphere codecs (xy-z, pixel-view, stereographic)
//                 are meant to work; pixel-view is given each sample's ray;
//   scene:NAME    the view-space normals of every covered pixel of a rendered scene (its first
//                 camera, float32 G-buffer), with the pixel's view ray;
//   hard          the hard-case set (hardNormalCases()): axes, each map's singularities, back
//                 faces, non-unit, subnormal, zero, huge and non-finite inputs;
// and per codec the code occupancy, a single-threaded encode/decode throughput and an
// equirectangular error map. Outputs: DIR/normals.csv, DIR/normals.json, DIR/maps/*.f32 (error
// grids) and, through experiments/plots/normals.py (matplotlib), DIR/error_vs_bits.png and
// DIR/maps/<codec>-<bits>.png. Definitions of every column are in gbuffer/README.md.
//
// Conventions: errors are gbuffer::normalAngleRadians between the input and the decoded vector,
// reported in degrees; percentiles are nearest-rank on the exact per-sample errors. Samples are
// generated per index from a counter-based SplitMix64 stream of the seed, work is split into
// fixed chunks whose statistics merge in chunk order, so every figure except the throughput is
// bit-identical for any thread count. Throughput is a wall-clock measurement of the study run
// (one thread, SoA arrays), labelled as such; the Google Benchmark figures are in
// tests/bench/normal_codec_bench.cpp.
// Memory: one dataset at a time, 32 bytes per sample (N = 10^7: ~320 MB).
//
// Pieces (experiments/studies/): NormalSampling.h (random streams and data sets),
// HardNormalCases.cpp (the hard set), NormalStatistics.h (errors, occupancy, throughput, maps,
// negative-z fractions), NormalStudyOutputs.h (CSV through CsvTable, JSON, the printed table),
// StudyPlots.h (the matplotlib script); NormalStudy.cpp runs the steps in order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace experiments {

inline constexpr std::uint64_t kNormalStudyDirections = 10'000'000;
inline constexpr std::uint64_t kNormalStudyQuickDirections = 100'000;
inline constexpr const char* kNormalStudyModelsDir = "../shared/scenes/gltf";

// Every option of `testbed normals`, defaults in one place (--help prints them).
struct NormalStudyOptions {
    std::filesystem::path out;               // required
    std::optional<std::uint64_t> directions; // unset: kNormalStudyDirections (quick: 10^5)
    std::uint64_t seed = 1;
    std::vector<std::string> scenes = {"atrium"}; // built-in names or scene files
    std::optional<std::string> modelsDir;         // unset: kNormalStudyModelsDir (quick: no models)
    int sceneWidth = 1280;                        // quick: 160 x 90
    int sceneHeight = 720;
    int threads = 0;         // 0 = every hardware thread
    bool quick = false;      // small sizes for tests, see above
    bool plots = true;       // run the matplotlib script
    std::string plotsScript; // "" = <source dir>/experiments/plots/normals.py
    std::string python; // "" = found by findPythonWithMatplotlib (experiments/output/PlotScript.h)
};

// One hard input: a normal, the view ray it is seen along (pixel-view reads it) and its group.
struct HardNormalCase {
    glm::vec3 normalView;
    glm::vec3 viewRayView;
    std::string group;
};
// The hard-case set; deterministic, a few hundred cases.
std::vector<HardNormalCase> hardNormalCases();

// Summary statistics of one codec x bits x dataset.
struct NormalStudyRow {
    std::string codec; // spec text "NAME:BITS"
    std::string name;
    int bits = 0;
    std::string dataset;
    std::uint64_t samples = 0;       // inputs with a direction (finite, non-zero)
    std::uint64_t nanInfOutputs = 0; // decoded vectors with a NaN/Inf component, over all inputs
    double meanDegrees = 0.0, rmsDegrees = 0.0, p999Degrees = 0.0, maxDegrees = 0.0;
    double boundDegrees = 0.0;            // normalErrorBoundRadians + float slack
    std::uint64_t boundRegionSamples = 0; // samples inside inNormalErrorBoundRegion
    double maxInBoundRegionDegrees = 0.0;
    std::uint64_t negativeZSamples = 0; // samples with view-space z < 0
    double meanNegativeZDegrees = 0.0, maxNegativeZDegrees = 0.0;
    std::int64_t worseThanOctahedral = -1; // octahedral-precise: inputs where plain wins
    std::string zeroVectorDecodesTo;       // hard: what (0,0,0) decodes to
    // Per codec x bits (the same on each of its rows):
    double occupancy = 0.0;                 // fraction of codes c with encode(decode(c)) == c
    std::uint64_t occupancyCodesTested = 0; // 2^bits when exhaustive, else a random sample
    double encodePerSecond = 0.0, decodePerSecond = 0.0; // study run, one thread
    bool withinBound() const { return maxInBoundRegionDegrees <= boundDegrees; }
};

// Per rendered scene: how many visible normals xy-z gets wrong.
struct NormalStudyScene {
    std::string dataset; // "scene:NAME"
    std::string source;  // name or file
    int width = 0, height = 0;
    std::uint64_t coveredPixels = 0;
    double negativeZFraction = 0.0;  // view-space z < 0 (xy-z's failure case)
    double backFacingFraction = 0.0; // dot(normal, view ray) > 0 (interpolated normals at edges)
    // Normal maps: the dataset holds the shading normals the G-buffer stores, after the normal
    // maps of the scene's materials. normalMappedFraction is the share of covered pixels whose
    // normal the maps changed (against the same render without them); "scene:NAME:geometric" is
    // that render without normal maps, a dataset of its own for comparison (geometric = true).
    double normalMappedFraction = 0.0;
    bool geometric = false;
};

// Fraction of visible surface orientations with view-space z < 0 at one field of view.
struct NegativeZFraction {
    double verticalFovDegrees = 0.0;
    double aspect = 0.0;               // width / height
    double uniformFraction = 0.0;      // orientation uniform over the front-facing hemisphere
    double areaWeightedFraction = 0.0; // weighted by projected area (what pixels see)
    // The same from closed forms: for a ray at angle a from the view axis the fraction is a / pi
    // (uniform) and (1 - cos a) / 2 (area-weighted); averaged over the image by the midpoint rule
    // on a 1024 x 1024 grid. The Monte Carlo figures above must agree within their noise.
    double uniformExact = 0.0;
    double areaWeightedExact = 0.0;
};

struct NormalStudyResult {
    std::vector<NormalStudyRow> rows;
    std::vector<NormalStudyScene> scenes;
    std::vector<NegativeZFraction> negativeZ;
    std::vector<std::string> warnings; // skipped model folder, scene loader warnings
    nlohmann::json json;               // what normals.json holds
};

// Runs the study and writes DIR/normals.csv, DIR/normals.json and the error grids; then the
// plots unless options.plots is false. Throws std::invalid_argument for bad options and a missing
// plot script (before any work) and std::runtime_error when a step fails (e.g. no python3 with
// matplotlib: the message says so; csv/json are written first). `progress` receives one line
// per step.
NormalStudyResult runNormalStudy(const NormalStudyOptions& options,
                                 const std::function<void(const std::string&)>& progress = {});

// The CLI entry point: runs the study, prints the summary table and "outputs in DIR"; returns
// the process exit code (errors printed to stderr).
int runNormalStudyCommand(const NormalStudyOptions& options);

} // namespace experiments
