// DuplicateKeys: finds a key given twice in the same JSON object. JSON allows it and
// nlohmann::json (and tinygltf through it) silently keeps the last value, so a scene or sweep
// file with two `stage` axes would run a different experiment than the one written (issue 32,
// class 5). Every reader of JSON text (JSON scenes, sweep files, glTF and GLB JSON chunks,
// results.json) calls this before its parser and refuses the file with the key's path.
//
// One pass of nlohmann's SAX parser, which unescapes keys ("a" and "\u0061" are the same key);
// memory grows with the keys of the objects open at once, never with the nesting beyond what
// NestingDepth already bounds. Malformed text is left to the real parser: this only reports
// duplicates it saw before the text went wrong. Thread-safe: a pure function.
#pragma once

#include <string>
#include <string_view>

namespace scenes {

// The path of the first key that repeats within its object ("axes.stage", "objects[1].name";
// a repeated top-level key is its bare name), or "" when no object repeats a key.
std::string jsonDuplicateKey(std::string_view text);

// The same as a sentence for an error message ("key 'axes.stage' is given twice in the same
// object"), or "" when there is none: every reader words it the same way.
std::string jsonDuplicateKeyProblem(std::string_view text);

} // namespace scenes
