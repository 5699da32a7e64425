// NestingDepth: cheap, iterative pre-scans that bound how deeply a JSON or TOML text nests,
// before any parser sees it. tinygltf converts parsed JSON recursively and toml++ builds and
// destroys dotted-key tables recursively, so a file nested 10^5 levels deep would overflow the
// stack inside those libraries (a crash no exception can catch); the readers call these first
// and refuse the file with one error instead (cap: limits::kMaxNestingDepth).
//
// Both scans are linear in the input, allocate nothing that grows with it, and accept any bytes
// (malformed text is the parser's business: a scan only has to never under-count the depth a
// parser could build). Thread-safe: pure functions.
#pragma once

#include <cstddef>
#include <string_view>

namespace scenes {

// Where a text first nests deeper than maxDepth: the byte offset of the bracket (or key) that
// opens level maxDepth + 1, and the 1-based line of that byte.
struct NestingViolation {
    size_t offset = 0;
    size_t line = 0;
};

// JSON: every '[' or '{' outside a string opens a level, ']' and '}' close one; strings (with
// backslash escapes) are skipped. Returns true and fills *violation when a level > maxDepth
// opens.
bool jsonNestsDeeperThan(std::string_view text, int maxDepth, NestingViolation* violation);

// TOML: levels are opened by each segment of a table header ([a.b.c] is 3, [[a.b]] is 3: the
// array and its table), each segment of a dotted key (relative to the current table, or to the
// inline table it is in), each array '[' and each inline table '{'. Basic, literal and
// multi-line strings and comments are skipped. Same contract as jsonNestsDeeperThan.
bool tomlNestsDeeperThan(std::string_view text, int maxDepth, NestingViolation* violation);

} // namespace scenes
