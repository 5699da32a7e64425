// MessageText: makes a message safe to print when parts of it come from an input file (a field
// value, a light type, a key, a file name). Unescaped, a newline in such a string prints a second
// "testbed: error:" line that the file wrote, and an ESC sequence recolours or rewrites the
// user's terminal (issue 32, class 7). The printers of errors and warnings (experiments'
// reportError, the scene loaders' and commands' warning lines) pass their whole message through
// escapeControlCharacters, so no message needs to remember which of its parts are hostile.
//
// What is escaped: C0 control characters and DEL (\n, \r, \t, other as \x1b), invalid UTF-8
// bytes (\xff, one per byte), C1 controls U+0080..U+009F (some terminals read U+009B as the
// start of an escape sequence) and the Unicode bidirectional overrides and isolates
// (U+202A..U+202E, U+2066..U+2069, which can reorder what is shown) as \u009b. Everything else,
// including valid UTF-8 and backslashes, passes unchanged: a message that already spells "\n"
// stays readable, and cannot forge more than those two visible characters. Thread-safe.
#pragma once

#include <string>
#include <string_view>

namespace scenes {

// Whether newlines, carriage returns and tabs are escaped too: always in a terminal line; HTML
// text may keep them, where they are only white space and cannot forge anything.
enum class LineBreaks { Escape, Keep };

std::string escapeControlCharacters(std::string_view text,
                                    LineBreaks lineBreaks = LineBreaks::Escape);

} // namespace scenes
