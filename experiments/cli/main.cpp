// testbed: the command-line front end. Subcommands:
//   render  one scene, one stage -> render.exr, preview.png, heatmap.png, stats.json
//   list    scenes (with their options), stages, normal encodings, layout presets, depth
//           formats, position methods and normal spaces known to this build (ListCommand.h)
//   report  a sweep's results folder -> DIR/report.html (tables, plots, thumbnails)
//   diff    two EXRs -> an image-diff report (metrics, side by side, |A-B|, per-channel stats)
//   sweep   a sweep file -> one job folder per job, results.csv/json (resumable, shardable)
//   merge   shard outputs of one sweep -> one results set
//   normals normal-encoding precision study -> normals.csv, normals.json, plots
//   depth   depth-format / position-reconstruction study -> depth.csv, depth.json, plots
// Every option's default is stated by --help; unknown options are errors.
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <iostream>
#include <limits>
#include <string>

#include <CLI/CLI.hpp>

#include "experiments/CommandErrors.h"
#include "experiments/advise/Advisor.h"
#include "experiments/cli/ListCommand.h"
#include "experiments/compare/DiffCommand.h"
#include "experiments/render/MemoryEstimate.h"
#include "experiments/render/RenderCommand.h"
#include "experiments/render/RenderPlan.h"
#include "experiments/report/ReportCommand.h"
#include "experiments/studies/DepthStudy.h"
#include "experiments/studies/NormalStudy.h"
#include "experiments/sweep/JobProcess.h"
#include "experiments/sweep/SweepFile.h"
#include "experiments/sweep/SweepRunner.h"
#include "gbuffer/LayoutDerivation.h"
#include "lighting/shadows/ShadowSettings.h"
#include "scenes/input/ClosestName.h"

namespace {

// CLI11 converts an unsigned option with strtoull's rules, under which "-1" is 2^64 - 1, so a
// seed is checked as text first: decimal digits only, at most 2^64 - 1.
std::string checkSeed(std::string& text) {
    uint64_t value = 0;
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, value);
    if (text.empty() || error != std::errc() || stop != end)
        return "seed '" + text + "' is not an integer in 0.." +
               std::to_string(std::numeric_limits<uint64_t>::max());
    return "";
}
const CLI::Validator kSeedValidator(checkSeed, "UINT64");

void addRenderOptions(CLI::App& render, experiments::RenderCommandOptions& options,
                      std::vector<std::string>& sceneOptionTexts, int& lights) {
    experiments::RenderOptions& r = options.render;
    render.add_option("--scene", r.scene, "built-in scene name or .gltf/.glb/.json file")
        ->capture_default_str();
    render
        .add_option("--scene-option", sceneOptionTexts,
                    "scene-specific key=value (repeatable), e.g. behind=1000 for wall")
        ->allow_extra_args(false);
    render.add_option("--stage", r.stage, "shading stage, NAME or NAME:key=value,...")
        ->capture_default_str();
    render.add_option("--view", r.view,
                      "the scene's named view (camera) to render, or `all` for one render per "
                      "view in OUT/views/NAME/ (default: the scene's first view; `testbed list "
                      "--views SCENE` lists them)");
    render.add_option("--lights", lights,
                      "generated point lights (default: a JSON scene's own lightGenerator, else " +
                          std::to_string(experiments::kDefaultLights) +
                          "); given, it replaces a JSON scene's generator count and seed");
    render.add_option("--seed", r.seed, "seed of the light generator")
        ->check(kSeedValidator)
        ->capture_default_str();
    render
        .add_option_function<std::string>(
            "--light-density",
            [&r](const std::string& text) {
                experiments::setRenderOption(r, "light-density", text);
            },
            "generated lights: fixed (radii from the scene, overlap grows with the count) or "
            "constant-overlap (radii shrink as the count grows; scenes/SceneRequest.h)")
        ->default_str("fixed")
        ->check(CLI::IsMember({"fixed", "constant-overlap"}));
    render.add_option("--width", r.width, "image width in pixels")->capture_default_str();
    render.add_option("--height", r.height, "image height in pixels")->capture_default_str();
    render.add_option("--threads", r.threads, "worker threads, 0 = all hardware threads")
        ->capture_default_str();
    render
        .add_option("--isa", r.isa,
                    "shading kernel: auto (widest this CPU runs), scalar, or sse4|avx2|avx3...")
        ->capture_default_str();
    render
        .add_option("--simt-warp", r.simtWarp,
                    "SIMT cost model warp: 32 (8x4 pixels) or 64 (8x8) lanes")
        ->capture_default_str();
    render
        .add_option("--msaa", r.msaa,
                    "samples per pixel: 1, 2, 4 or 8 (Direct3D positions); complex pixels are "
                    "shaded per fragment, simple ones once (gbuffer/msaa/FragmentLayers.h)")
        ->capture_default_str();
    render
        .add_option("--complex-detect", r.complexDetect,
                    "complex pixels by primitive (samples show different triangles) or "
                    "discontinuity (depth + normal + material differ)")
        ->capture_default_str();
    render
        .add_option("--alpha-to-coverage", r.alphaToCoverage,
                    "on: alpha-masked materials keep round(alpha x samples) of each fragment's "
                    "samples (fixed 2x2-dithered pattern) instead of the alpha test; needs "
                    "--msaa 2, 4 or 8 (refused at 1)")
        ->capture_default_str();
    render.add_option("--out", options.out, "output folder")->capture_default_str();
    render
        .add_option("--heatmap-max", options.scales.heatmapMax,
                    "light count at the top of the heatmap scale, 0 = the image's maximum")
        ->capture_default_str();
    render
        .add_option_function<std::string>(
            "--error-scale",
            [&options](const std::string& text) {
                options.scales.errorScale = experiments::parseMapScale(text);
            },
            "scale of error.png: linear (0 to the maximum) or log (4 decades below the maximum, "
            "so that one outlier does not darken the rest)")
        ->check(CLI::IsMember({"linear", "log"}))
        ->default_str("linear");
    render
        .add_option("--error-max", options.scales.errorMax,
                    "error at the top of error.png's scale, 0 = the image's largest error")
        ->capture_default_str();
    render.add_flag("--compare-reference", r.compareReference,
                    "also render the double-precision reference and record the error");
    render
        .add_option("--reference-spp", r.referenceSpp,
                    "samples per pixel of the reference compared with: a square 1..256 (1 = "
                    "the pixel centre, 16 = the D3D 16x pattern, other squares a stratified "
                    "grid), box filtered")
        ->capture_default_str();
    std::string presets; // from the presets themselves, so a new one is listed (ue4 was not)
    for (const std::string& name : gbuffer::layoutPresetNames())
        presets += (presets.empty() ? "" : ", ") + name;
    render.add_option("--layout", r.layout,
                      "G-buffer preset: " + presets +
                          " (default: derived from the scene's materials and the stage's needs)");
    render.add_option("--normals", r.normals,
                      "normal encoding NAME:BITS, e.g. octahedral:24 (testbed list)");
    render.add_option(
        "--depth", r.depth,
        "depth format: f32, f32-reversed, unorm24, unorm16, f16-linear, optionally :infinite");
    render.add_option("--position", r.position,
                      "position reconstruction: inverse-projection or view-ray");
    render
        .add_option("--brdf", r.brdf,
                    "material model: auto (each material's own), blinn-phong or "
                    "metallic-roughness (every material forced to it, for studies)")
        ->capture_default_str();
    render
        .add_option("--post-aa", r.postAa,
                    "post-process anti-aliasing after the stage: none, edge-blur (G-buffer depth "
                    "and normal edges blurred, S.T.A.L.K.E.R./Tabula Rasa; adds depth and "
                    "normals to the layout) or fxaa (luminance edges, FXAA 3.11)")
        ->capture_default_str();
    render
        .add_option("--oracle", r.oracle,
                    "light-count oracle for culling efficiency: unshadowed (radiance non-zero) "
                    "or visibility (also reaches the surface: one shadow ray per pair)")
        ->capture_default_str();
    render
        .add_option("--shadows", r.shadows,
                    "off, or maps: shadow maps (spot: perspective, point: cube or dual-paraboloid, "
                    "directional: "
                    "cascades) looked up in the shading kernel by every stage; the reference "
                    "ray-traces the same lights (Embree). Casters: the scene's castsShadows "
                    "lights, or every light when it marks none")
        ->capture_default_str();
    render.add_option("--shadow-map-size", r.shadowMapSize, "texels per shadow map face side")
        ->capture_default_str();
    render.add_option("--shadow-bias", r.shadowBias,
                      "CONSTANT,SLOPE depth bias (metres, texels); default 0.005,1.5");
    render.add_option("--shadow-filter", r.shadowFilter, "none, pcf3, pcf5 or poisson")
        ->capture_default_str();
    render
        .add_option("--shadow-point", r.shadowPoint,
                    "point lights' maps: cube (six faces) or dual-paraboloid (two faces, casters "
                    "split to " +
                        std::to_string(int(lighting::ShadowSettings{}.paraboloidMaxEdgeDegrees)) +
                        "-degree edges)")
        ->capture_default_str();
    render
        .add_option("--shadow-depth-format", r.shadowDepthFormat,
                    "float32 (the rasterizer's depth) or unorm16 (16-bit linear depth, half the "
                    "bytes, rounded towards the far plane)")
        ->capture_default_str();
    render
        .add_option("--shadow-lights", r.shadowLights,
                    "N or all: the casting lights that get maps (the N that matter most in view)")
        ->capture_default_str();
    render.add_option("--shadow-cascades", r.shadowCascades, "directional lights' cascades, 1..8")
        ->capture_default_str();
    render
        .add_option("--shadow-caster-sets", r.shadowCasterSets,
                    "on or off: draw into each light's maps only the objects that can cast onto a "
                    "visible receiver (shadow-casting sets), or every object in range")
        ->capture_default_str();
    render.add_option("--normal-space", r.normalSpace,
                      "space normals are encoded in: view (default) or world");
    render.add_flag(
        "--explain-layout", options.explainLayout,
        "print the G-buffer layout and why each plane is there, then exit without rendering");
    render
        .add_option_function<std::string>(
            "--max-memory",
            [&r](const std::string& text) {
                try {
                    experiments::setRenderOption(r, "max-memory", text);
                } catch (const experiments::UsageError& e) {
                    throw CLI::ValidationError(e.what()); // reported as every parse error
                }
            },
            "refuse a render whose estimated peak memory exceeds this many bytes (K, M, G, T "
            "suffixes, powers of 1024; --explain-layout prints the estimate)")
        ->default_str(std::to_string(int(experiments::kDefaultMaxMemoryFraction * 100)) +
                      "% of the machine's memory");
    render.add_option("--warmup", r.warmup, "untimed runs before the timed ones")
        ->capture_default_str();
    render.add_option("--repetitions", r.repetitions, "timed runs (median, min, max are recorded)")
        ->capture_default_str();
}

// A name of the command line that is not one: the closest valid one, if any is close (a
// subcommand for the first argument, else an option of the subcommand given).
std::string suggestionFor(CLI::App& app, int argc, char** argv) {
    std::vector<std::string> subcommands;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        if (!sub->get_group().empty())
            subcommands.push_back(sub->get_name());
    if (argc < 2)
        return "";
    const std::string first = argv[1];
    if (first.rfind("-", 0) != 0 &&
        std::find(subcommands.begin(), subcommands.end(), first) == subcommands.end())
        return scenes::didYouMean(first, subcommands);
    const CLI::App* sub = nullptr;
    for (const CLI::App* candidate : app.get_subcommands([](const CLI::App*) { return true; }))
        if (candidate->get_name() == first)
            sub = candidate;
    if (!sub)
        return "";
    std::vector<std::string> options;
    for (const CLI::Option* option : sub->get_options())
        for (const std::string& name : option->get_lnames())
            options.push_back("--" + name);
    for (int i = 2; i < argc; ++i) {
        std::string arg = argv[i];
        if (arg.rfind("--", 0) != 0)
            continue;
        arg = arg.substr(0, arg.find('='));
        if (std::find(options.begin(), options.end(), arg) == options.end())
            return scenes::didYouMean(arg, options);
    }
    return "";
}

// CLI11's message as one line (its messages may hold line breaks), with a suggestion for a typo.
std::string parseErrorMessage(CLI::App& app, const CLI::ParseError& error, int argc, char** argv) {
    std::string message = error.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    while (!message.empty() && message.back() == ' ')
        message.pop_back();
    return message + suggestionFor(app, argc, argv) + "; see testbed --help";
}

} // namespace

int main(int argc, char** argv) {
    // Before anything of ours starts a thread: sweep jobs fork only while none has
    // (experiments/sweep/JobProcess.h).
    experiments::noteStartupThreads();
    // Named, so that help texts say `testbed`, not the path the binary was started by.
    CLI::App app{"testbed: CPU rasterizer research testbed for deferred shading", "testbed"};
    app.require_subcommand(1);
    experiments::RenderCommandOptions renderOptions;
    std::vector<std::string> sceneOptionTexts;
    int renderLights = experiments::kDefaultLights;
    CLI::App* render = app.add_subcommand("render", "render one scene with one shading stage");
    addRenderOptions(*render, renderOptions, sceneOptionTexts, renderLights);
    CLI::App* list = app.add_subcommand(
        "list", "list scenes (with their options), stages, normal encodings, layout presets, "
                "depth formats, position methods and normal spaces");
    std::string listViewsScene;
    list->add_option("--views", listViewsScene, "list the named views (cameras) of this scene");
    experiments::ReportCommandOptions reportOptions;
    CLI::App* report =
        app.add_subcommand("report", "write DIR/report.html for a sweep's results folder DIR");
    report->add_option("dir", reportOptions.dir, "results folder (holds results.json)")->required();
    report->add_option(
        "--plots-script", reportOptions.plotsScript,
        "matplotlib script (default: experiments/plots/report.py of the source tree)");
    report->add_option("--python", reportOptions.python,
                       "Python with matplotlib (default: /usr/bin/python3, else python3 on PATH)");
    report
        ->add_option("--thumbnail-width", reportOptions.thumbnailWidth, "thumbnail width in pixels")
        ->capture_default_str();
    report
        ->add_option("--error-metric,--metric", reportOptions.errorMetric,
                     "y axis of the Pareto plots: relative_rmse, rmse, flip, psnr, max_abs, "
                     "relative_mean or p99_abs")
        ->capture_default_str();
    report
        ->add_option_function<std::string>(
            "--error-scale",
            [&reportOptions](const std::string& text) {
                reportOptions.errorScale = experiments::parseMapScale(text);
            },
            "scale of the error maps: linear or log (default: the sweep file's error-scale, else "
            "linear)")
        ->check(CLI::IsMember({"linear", "log"}));
    experiments::AdviseCommandOptions adviseOptions;
    std::vector<std::string> adviseGroups;
    CLI::App* advise = app.add_subcommand(
        "advise", "which stage and layout for a time and error budget, from a finished sweep");
    advise->add_option("dir", adviseOptions.dir, "results folder (holds results.json)")->required();
    advise
        ->add_option("--budget-ms", adviseOptions.criteria.budgetMs,
                     "frame-time budget in ms (median total time)")
        ->required();
    CLI::Option* maxFlip = advise->add_option("--max-flip", adviseOptions.criteria.maxFlip,
                                              "error budget: mean HDR-FLIP at most this (0..1)");
    CLI::Option* maxRmse = advise->add_option("--max-rmse", adviseOptions.criteria.maxRelativeRmse,
                                              "error budget: relative RMSE at most this");
    maxFlip->excludes(maxRmse);
    advise->add_option("--group", adviseGroups,
                       "only groups with this setting, KEY=VALUE (repeatable), e.g. lights=256");
    experiments::DiffCommandOptions diffOptions;
    CLI::App* diff =
        app.add_subcommand("diff", "image-diff report of two EXRs (B is the reference)");
    diff->add_option("a", diffOptions.a, "first image (EXR with R, G, B)")->required();
    diff->add_option("b", diffOptions.b, "second image, the reference")->required();
    diff->add_option("--out", diffOptions.out, "output folder (index.html, diff.json, PNGs)")
        ->capture_default_str();
    diff->add_option("--exposure", diffOptions.exposure, "linear exposure of the previews")
        ->capture_default_str();
    diff->add_option("--plots-script", diffOptions.plotsScript,
                     "matplotlib script (default: experiments/plots/report.py of the source tree)");
    diff->add_option("--python", diffOptions.python,
                     "Python with matplotlib (default: /usr/bin/python3, else python3 on PATH)");
    experiments::DepthCommandOptions depthOptions;
    CLI::App* depth = app.add_subcommand(
        "depth", "depth formats x position reconstruction: position error against distance");
    depth->add_option("--out", depthOptions.out, "output folder")->capture_default_str();
    depth->add_flag("--quick", depthOptions.quick, "40 distances and a 16x9 pixel grid (seconds)");
    depth->add_option("--plots-script", depthOptions.plotsScript,
                      "matplotlib script (default: experiments/plots/depth.py of the source tree)");
    depth->add_option("--python", depthOptions.python,
                      "Python with matplotlib (default: /usr/bin/python3, else python3 on PATH)");
    experiments::NormalStudyOptions normalsOptions;
    std::uint64_t normalsDirections = experiments::kNormalStudyDirections;
    std::string normalsModels = experiments::kNormalStudyModelsDir;
    CLI::App* normals = app.add_subcommand(
        "normals",
        "normal-encoding precision study: every codec x bits -> normals.csv/json, plots");
    normals->add_option("--out", normalsOptions.out, "output folder")->required();
    normals
        ->add_option("--directions", normalsDirections,
                     "uniform sphere directions (--quick: 100000)")
        ->capture_default_str();
    normals->add_option("--seed", normalsOptions.seed, "seed of every random set")
        ->check(kSeedValidator)
        ->capture_default_str();
    normals
        ->add_option("--scene", normalsOptions.scenes, "built-in scene or scene file (repeatable)")
        ->capture_default_str();
    normals
        ->add_option("--models", normalsModels,
                     "folder searched for .gltf/.glb models, skipped with a warning if missing "
                     "(--quick: none unless given)")
        ->capture_default_str();
    normals->add_option("--width", normalsOptions.sceneWidth, "scene render width (--quick: 160)")
        ->capture_default_str();
    normals->add_option("--height", normalsOptions.sceneHeight, "scene render height (--quick: 90)")
        ->capture_default_str();
    normals
        ->add_option("--threads", normalsOptions.threads,
                     "worker threads, 0 = all hardware threads")
        ->capture_default_str();
    normals->add_flag("--quick", normalsOptions.quick,
                      "10^5 directions, 160x90 atrium, no models, sampled occupancy (seconds)");
    normals->add_flag("!--no-plots", normalsOptions.plots, "skip the matplotlib plots");
    normals->add_option(
        "--plots-script", normalsOptions.plotsScript,
        "matplotlib script (default: experiments/plots/normals.py of the source tree)");
    normals->add_option("--python", normalsOptions.python,
                        "Python with matplotlib (default: /usr/bin/python3, else python3 on PATH)");
    experiments::SweepOptions sweepOptions;
    std::string shardText = "1/1";
    int sweepThreads = -1;
    CLI::App* sweep =
        app.add_subcommand("sweep", "run a sweep file (JSON or TOML; experiments/README.md)");
    sweep->add_option("file", sweepOptions.file, "sweep file")->required();
    sweep
        ->add_option("--out", sweepOptions.out,
                     "output folder (resumable: finished jobs are skipped)")
        ->capture_default_str();
    sweep
        ->add_option("--shard", shardText,
                     "run shard I of N (1-based): a deterministic 1/N of the jobs")
        ->capture_default_str();
    sweep->add_flag("--quick", sweepOptions.quick, "apply the file's \"quick\" block (CI size)");
    sweep->add_option(
        "--threads", sweepThreads,
        "worker threads of every job, 0 = all hardware threads (default: the file's)");
    double sweepJobTimeout = -1.0;
    sweep->add_option("--job-timeout", sweepJobTimeout,
                      "wall-time limit of one job in seconds: a job still running is killed and "
                      "recorded as failed, the sweep goes on, a rerun retries it; 0 = no limit "
                      "(default: the file's job-timeout, else no limit)");
    sweep->add_flag("--wait", sweepOptions.waitForLock,
                    "when another sweep is running the same jobs into --out, wait for it to end "
                    "(default: refuse, naming its process)");
    // The child process of one sweep job (experiments/sweep/JobProcess.h): not for users, not in
    // --help.
    std::string sweepJobText;
    long sweepJobParent = 0;
    int sweepJobReportFd = -1;
    CLI::App* sweepJob = app.add_subcommand("sweep-job", "")->group("");
    sweepJob->add_option("--parent", sweepJobParent)->required();
    sweepJob->add_option("--report-fd", sweepJobReportFd)->required();
    sweepJob->add_option("job", sweepJobText)->required();
    std::vector<std::filesystem::path> mergeInputs;
    std::filesystem::path mergeOut;
    CLI::App* merge = app.add_subcommand("merge", "combine the output folders of a sweep's shards");
    merge->add_option("dirs", mergeInputs, "sweep output folders")->required();
    merge->add_option("--out", mergeOut, "merged output folder (may be one of the inputs)")
        ->required();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success))
            return app.exit(e); // --help
        return experiments::reportError(parseErrorMessage(app, e, argc, argv));
    }
    if (render->parsed()) {
        if (render->count("--lights") > 0)
            renderOptions.render.lights = renderLights;
        for (const std::string& text : sceneOptionTexts) {
            const size_t equals = text.find('=');
            if (equals == std::string::npos || equals == 0)
                return experiments::reportError("--scene-option '" + text + "' is not key=value");
            renderOptions.render.sceneOptions[text.substr(0, equals)] = text.substr(equals + 1);
        }
        return experiments::runRenderCommand(renderOptions);
    }
    if (list->parsed())
        return experiments::runListCommand(listViewsScene);
    if (report->parsed())
        return experiments::runReportCommand(reportOptions);
    if (advise->parsed()) {
        for (const std::string& filter : adviseGroups) {
            const size_t equals = filter.find('=');
            if (equals == std::string::npos || equals == 0)
                return experiments::reportError("--group " + filter + ": expected KEY=VALUE");
            adviseOptions.criteria.groupFilters.emplace_back(filter.substr(0, equals),
                                                             filter.substr(equals + 1));
        }
        return experiments::runAdviseCommand(adviseOptions);
    }
    if (diff->parsed())
        return experiments::runDiffCommand(diffOptions);
    if (depth->parsed())
        return experiments::runDepthCommand(depthOptions);
    if (sweep->parsed()) {
        try {
            std::tie(sweepOptions.shardIndex, sweepOptions.shardCount) =
                experiments::parseShard(shardText);
        } catch (const std::exception& e) {
            return experiments::reportError(e);
        }
        if (sweepThreads >= 0)
            sweepOptions.threads = sweepThreads;
        if (sweep->count("--job-timeout") > 0) {
            if (const std::string error =
                    experiments::jobTimeoutError(sweepJobTimeout, "--job-timeout");
                !error.empty())
                return experiments::reportError(error);
            sweepOptions.jobTimeoutSeconds = sweepJobTimeout;
        }
        // Every job in a child process (experiments/sweep/JobProcess.h): forked, or this very
        // binary (even if the file is rebuilt meanwhile).
        sweepOptions.isolation = experiments::JobIsolation::Fork;
        sweepOptions.jobExecutable = "/proc/self/exe";
        return experiments::runSweepCommand(sweepOptions);
    }
    if (sweepJob->parsed()) {
        return experiments::runSweepJobCommand(sweepJobText, sweepJobParent, sweepJobReportFd);
    }
    if (merge->parsed())
        return experiments::runMergeCommand(mergeInputs, mergeOut);
    if (normals->parsed()) {
        if (normals->count("--directions") > 0)
            normalsOptions.directions = normalsDirections;
        if (normals->count("--models") > 0)
            normalsOptions.modelsDir = normalsModels;
        return experiments::runNormalStudyCommand(normalsOptions);
    }
    return 1;
}
