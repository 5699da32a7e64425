// Factory functions of the stages under lighting/stages/, one per file; StageRegistry.cpp maps
// names to them. Adding a stage = one new file + one line here + one registry row.
#pragma once

#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "lighting/StageRegistry.h"

namespace lighting {

// Throws StageError naming the stage and the first option key not in `known`.
void rejectUnknownOptions(const StageSpec& spec, std::initializer_list<const char*> known);

// Typed option readers: the default when absent, a StageError naming the stage, key and the
// accepted values when malformed. The first choice is the default.
int intOption(const StageSpec& spec, const char* key, int defaultValue, int minValue, int maxValue);
bool boolOption(const StageSpec& spec, const char* key, bool defaultValue);
std::string choiceOption(const StageSpec& spec, const char* key,
                         const std::vector<std::string>& choices);

std::unique_ptr<ShadingStage> makeBruteStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeReferenceStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeDeferredStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeLightIndexedStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeClusteredStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeTiledStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeTiledBackfaceStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeForwardStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeForwardMultipassStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeLightPrepassStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeInferredStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeTiledForwardStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeIdealStage(const StageSpec& spec);

} // namespace lighting
