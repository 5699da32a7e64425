#include "experiments/cli/ListCommand.h"

#include <iostream>
#include <vector>

#include "experiments/CommandErrors.h"
#include "experiments/render/RenderOptions.h"
#include "experiments/render/RenderPlan.h"
#include "gbuffer/GBufferLayout.h"
#include "gbuffer/LayoutDerivation.h"
#include "gbuffer/codecs/DepthFormat.h"
#include "gbuffer/codecs/NormalCodec.h"
#include "lighting/StageRegistry.h"
#include "lighting/postaa/PostAa.h"
#include "scenes/Viewpoints.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace experiments {

namespace {

std::string joined(const std::vector<std::string>& names, const char* separator = ", ") {
    std::string text;
    for (const std::string& name : names)
        text += (text.empty() ? "" : separator) + name;
    return text;
}

void printScenes(std::ostream& out) {
    out << "scenes (--scene; default " << scenes::kDefaultSceneName
        << "), with their --scene-option KEY=VALUE:\n";
    for (const std::string& name : scenes::proceduralSceneNames()) {
        out << "  " << name << "\n";
        // Wall's `behind` is bounded by the light count: listed for the most lights allowed.
        for (const scenes::SceneOption& option : scenes::proceduralSceneOptions(name, kMaxLights)) {
            const std::string values =
                option.minValue == 0 && option.maxValue == 1
                    ? "0|1"
                    : std::to_string(option.minValue) + ".." +
                          (option.maxValue == kMaxLights ? std::string("the light count")
                                                         : std::to_string(option.maxValue));
            out << "    " << option.key << "=" << values << "  default " << option.defaultValue
                << ": " << option.meaning << "\n";
        }
    }
    out << "  <file>.gltf | <file>.glb | <file>.json  (no scene options; JSON scenes: "
           "scenes/README.md)\n";
}

void printStages(std::ostream& out) {
    out << "stages (--stage NAME or NAME:key=value,...; default " << RenderOptions{}.stage
        << "), with their options (key=accepted values, type, default: what it does):\n";
    for (const lighting::StageInfo& info : lighting::stageInfos()) {
        out << "  " << info.name << "  - " << info.description << "\n";
        out << "    msaa: "
            << (!info.msaaRefusal.empty() ? "refused: " + info.msaaRefusal
                : !info.msaaNote.empty()  ? "yes (" + info.msaaNote + ")"
                : info.msaaNative
                    ? std::string("yes, natively (rasterized at the sample count, shaded once per "
                                  "pixel and triangle, per-sample colour resolved)")
                    : std::string("yes (per-sample shading at complex pixels only, through the "
                                  "fragment layers)"))
            << "\n";
        for (const lighting::StageOption& option : info.options)
            out << "    " << option.key << "=" << option.range() << "  " << option.typeName()
                << ", default " << option.defaultText << ": " << option.doc << "\n";
    }
}

void printNormalCodecs(std::ostream& out) {
    out << "normal encodings (--normals NAME:BITS, total bits; gbuffer/codecs/NormalCodec.h):\n";
    const std::vector<gbuffer::NormalCodecSpec> specs = gbuffer::allNormalCodecSpecs();
    for (size_t i = 0; i < specs.size(); ++i) { // grouped by codec, in registry order
        const bool first = i == 0 || specs[i - 1].kind != specs[i].kind;
        const bool last = i + 1 == specs.size() || specs[i + 1].kind != specs[i].kind;
        if (first)
            out << "  " << gbuffer::normalCodecName(specs[i].kind) << ":";
        out << (first ? "" : "|") << specs[i].bits << (last ? "\n" : "");
    }
}

void printLayoutChoices(std::ostream& out) {
    out << "layout presets (--layout; default: derived from the scene's materials and the "
           "stage; --explain-layout says why each plane is there):\n  "
        << joined(gbuffer::layoutPresetNames()) << "\n";
    out << "depth formats (--depth NAME or NAME:infinite; default "
        << gbuffer::DepthFormatSpec{}.text() << "):\n  " << joined(gbuffer::depthFormatNames())
        << "\n";
    out << "position methods (--position; default "
        << gbuffer::positionMethodName(gbuffer::GBufferLayout{}.position) << "):\n  "
        << gbuffer::positionMethodName(gbuffer::PositionMethod::InverseProjection) << ", "
        << gbuffer::positionMethodName(gbuffer::PositionMethod::ViewRay) << "\n";
    out << "normal spaces (--normal-space; default "
        << gbuffer::normalSpaceName(gbuffer::GBufferLayout{}.normalSpace) << "):\n  "
        << gbuffer::normalSpaceName(gbuffer::NormalSpace::View) << ", "
        << gbuffer::normalSpaceName(gbuffer::NormalSpace::World) << "\n";
    out << "post-process anti-aliasing (--post-aa; default " << experiments::RenderOptions{}.postAa
        << "):\n  " << joined(lighting::postaa::postAaNames()) << "\n";
}

} // namespace

void printList(std::ostream& out) {
    printScenes(out);
    printStages(out);
    printNormalCodecs(out);
    printLayoutChoices(out);
    out << "views of a scene: testbed list --views SCENE\n";
}

int runListCommand(const std::string& viewsOfScene) {
    try {
        if (viewsOfScene.empty()) {
            printList(std::cout);
            return 0;
        }
        RenderOptions options;
        options.scene = viewsOfScene;
        for (const std::string& view : scenes::viewNames(loadRequestedScene(options)))
            std::cout << view << "\n";
        return 0;
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

} // namespace experiments
