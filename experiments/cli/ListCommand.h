// ListCommand: `testbed list`: what this build knows, each with the values and defaults the
// render options take: built-in scenes and their --scene-option tables, stages, normal encodings,
// G-buffer layout presets, depth formats, position methods and normal spaces. Every list comes
// from the registry or table that the options are checked against, so it cannot drift from them.
// `testbed list --views SCENE` lists one scene's named views instead.
#pragma once

#include <iosfwd>
#include <string>

namespace experiments {

// Writes the listing to `out`.
void printList(std::ostream& out);

// `testbed list [--views SCENE]`: returns the exit code (errors: one "testbed: error:" line).
int runListCommand(const std::string& viewsOfScene);

} // namespace experiments
