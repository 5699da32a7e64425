// Factory functions of the stages under lighting/stages/, one per file; StageRegistry.cpp maps
// names to them. Adding a stage = one new file + one line here + one registry row.
#pragma once

#include <initializer_list>
#include <memory>

#include "lighting/StageRegistry.h"

namespace lighting {

// Throws StageError naming the stage and the first option key not in `known`.
void rejectUnknownOptions(const StageSpec& spec, std::initializer_list<const char*> known);

std::unique_ptr<ShadingStage> makeBruteStage(const StageSpec& spec);
std::unique_ptr<ShadingStage> makeReferenceStage(const StageSpec& spec);

}  // namespace lighting
