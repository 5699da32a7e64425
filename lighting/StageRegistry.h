// StageRegistry: shading stages by name. A spec is NAME or NAME:key=value,key=value, checked
// against the stage's option table (StageOptions.h). Unknown names are errors that list the valid
// ones.
//
// Self-registration: each stage file under lighting/stages/ defines a StageRegistrar at namespace
// scope with the stage's StageInfo (name, description, kind, option table, list position) and its
// factory; nothing else names the stage. The registry is a function-local static, so registrars
// in any translation unit may run in any order during static initialisation; it is read only
// after (from main() on). The stage objects sit in a static library linked whole-archive
// (lighting/CMakeLists.txt): no symbol of theirs is referenced, and a plain static link would drop
// them with their registrars.
//
// Order: stageInfos() lists the stages by StageInfo::listOrder (then name), not by registration
// order, which depends on the link: `testbed list`, the tests and the sweeps see one stable order.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "lighting/ShadingStage.h"
#include "lighting/StageOptions.h"

namespace lighting {

struct StageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct StageSpec {
    std::string name;
    std::map<std::string, std::string> options;
    static StageSpec parse(const std::string& spec); // throws StageError on malformed text
};

// What a stage promises about its image, which decides how tests check it:
//   Reference  the double-precision truth
//   Exact      the same image as `brute` up to float summation order, and at every pixel at
//              least as many lights evaluated as contribute (culling never drops a light)
//   Approximate an approximation by design (e.g. lower-resolution lighting); its error against
//              the reference is measured and bounded, not required to vanish
enum class StageKind { Reference, Exact, Approximate };

struct StageInfo {
    std::string name;
    std::string description; // one line; the options are listed from `options`, not here
    StageKind kind = StageKind::Exact;
    // Exact stages: every pixel sums its lights in ascending light index, starting from zero, so
    // the image is BITWISE `brute`'s (skipped lights add exactly +0) and the tests compare it so.
    // A stage that reorders the sum (e.g. per-light partial sums merged later) sets false and is
    // compared within 1e-5 of the image's peak instead.
    bool ascendingLightOrder = true;
    std::vector<StageOption> options; // the option table (StageOptions.h), in listing order
    // Position in stageInfos() (ascending; unique among stages): today's order is reference 0,
    // brute 10, ideal 20, deferred 30, light-indexed 40, clustered 50, clustered-explicit 55, tiled
    // 60, tiled-backface 70, forward 80, forward-multipass 90, light-prepass 100, inferred 110,
    // tiled-forward 120.
    int listOrder = 0;
    // Multisampled frames (--msaa 2|4|8, MultisampleShading.h): empty when the stage shades them
    // through the fragment layers or natively; otherwise why it refuses them (`testbed list` shows
    // it and the runner's error quotes it).
    std::string msaaRefusal;
    // How the stage takes multisampled frames, when the generic description (per-sample shading
    // at complex pixels through the fragment layers, or natively) does not say it all: `testbed
    // list` shows it instead.
    std::string msaaNote;
    // True when the stage multisamples natively (ShadingStage::multisamplesNatively: rasterized
    // at the frame's sample count, shaded once per pixel and triangle, per-sample colour resolved
    // by the stage), so MultisampleShading runs it once on the full frame, not per layer.
    bool msaaNative = false;
};

// Builds a stage from its checked options (defaults filled in). May throw StageError for a rule
// between options that the table cannot state (StageOptions::given names what the spec set).
using StageFactory = std::function<std::unique_ptr<ShadingStage>(const StageOptions&)>;

// Registers a stage at static initialisation: one namespace-scope object per stage, in the
// stage's file. A name registered twice is a programming error (std::terminate with a message).
struct StageRegistrar {
    StageRegistrar(StageInfo info, StageFactory make);
};

// Every registered stage, in listOrder.
std::vector<StageInfo> stageInfos();
// Throws StageError for an unknown name or option.
std::unique_ptr<ShadingStage> makeStage(const std::string& spec);
// The options `spec` gives its stage, checked and with defaults filled in: key -> canonical text,
// what stats.json records as `stage_options`. Throws StageError for an unknown name or option as
// makeStage does (not for the factory's rules between options: call it on a spec makeStage took).
std::map<std::string, std::string> resolvedStageOptions(const std::string& spec);

} // namespace lighting
