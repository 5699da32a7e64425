// The two pre-scans of NestingDepth.h. They follow each format's lexical rules only as far as
// needed to tell brackets and dots that nest from those inside strings and comments; anything
// they do not understand is left to the real parser, which will report it.
#include "scenes/input/NestingDepth.h"

#include <algorithm>
#include <vector>

namespace scenes {

namespace {

bool violated(std::string_view text, size_t offset, NestingViolation* violation) {
    if (violation) {
        violation->offset = offset;
        violation->line = 1 + size_t(std::count(text.begin(), text.begin() + offset, '\n'));
    }
    return true;
}

// Skips the TOML string starting at text[i] (a quote): basic "..." with backslash escapes,
// literal '...', and their multi-line forms """...""" and '''...''' (which may end with up to
// two extra quotes). Returns the offset just past it, or the end of the line (single-line) or of
// the text when it is unterminated.
size_t skipTomlString(std::string_view text, size_t i) {
    const size_t n = text.size();
    const char quote = text[i];
    const bool multiLine = i + 2 < n && text[i + 1] == quote && text[i + 2] == quote;
    i += multiLine ? 3 : 1;
    while (i < n) {
        const char c = text[i];
        if (c == '\n' && !multiLine)
            return i;
        if (quote == '"' && c == '\\') {
            i += 2;
            continue;
        }
        if (c == quote) {
            if (!multiLine)
                return i + 1;
            if (i + 2 < n && text[i + 1] == quote && text[i + 2] == quote) {
                i += 3;
                for (int extra = 0; extra < 2 && i < n && text[i] == quote; ++extra)
                    ++i;
                return i;
            }
        }
        ++i;
    }
    return n;
}

} // namespace

bool jsonNestsDeeperThan(std::string_view text, int maxDepth, NestingViolation* violation) {
    int depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i; // the escaped character cannot end the string
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > maxDepth)
                return violated(text, i, violation);
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return false;
}

bool tomlNestsDeeperThan(std::string_view text, int maxDepth, NestingViolation* violation) {
    // An open array or inline table: the level to return to when it closes, the level of its
    // elements, and whether its elements are key = value pairs (inline table).
    struct Frame {
        int outerLevel;
        int elementLevel;
        bool inlineTable;
    };
    std::vector<Frame> frames; // never deeper than maxDepth: the scan stops first
    enum class Mode { StatementStart, Key, Value } mode = Mode::StatementStart;
    int tableLevel = 0; // levels opened by the last [table] or [[array of tables]] header
    int level = 0;      // Key: levels the dotted key reached; Value: levels around the value
    const size_t n = text.size();
    size_t i = 0;
    while (i < n) {
        const char c = text[i];
        if (c == '#') {
            while (i < n && text[i] != '\n')
                ++i;
            continue;
        }
        if (c == '\n') {
            if (frames.empty())
                mode = Mode::StatementStart;
            ++i;
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\r') {
            ++i;
            continue;
        }
        if (mode == Mode::StatementStart) {
            if (c == '[') {
                const size_t start = i;
                const bool arrayOfTables = i + 1 < n && text[i + 1] == '[';
                int headerLevel = arrayOfTables ? 2 : 1;
                i += arrayOfTables ? 2 : 1;
                while (i < n && text[i] != ']' && text[i] != '\n') {
                    if (text[i] == '"' || text[i] == '\'') {
                        i = skipTomlString(text, i);
                        continue;
                    }
                    if (text[i] == '.' && ++headerLevel > maxDepth)
                        return violated(text, i, violation);
                    ++i;
                }
                if (headerLevel > maxDepth)
                    return violated(text, start, violation);
                tableLevel = headerLevel;
                // The rest of the header line may only hold ']' and a comment; Value mode with
                // no open frame returns to a statement start at the newline.
                mode = Mode::Value;
                level = tableLevel;
                while (i < n && text[i] == ']')
                    ++i;
                continue;
            }
            mode = Mode::Key;
            level = tableLevel + 1;
            if (level > maxDepth)
                return violated(text, i, violation);
            continue; // the same character, now as part of a key
        }
        if (c == '"' || c == '\'') {
            i = skipTomlString(text, i);
            continue;
        }
        if (c == '}' || c == ']') {
            if (!frames.empty()) {
                level = frames.back().outerLevel;
                frames.pop_back();
                mode = Mode::Value;
            }
            ++i;
            continue;
        }
        if (mode == Mode::Key) {
            if (c == '.' && ++level > maxDepth)
                return violated(text, i, violation);
            if (c == '=')
                mode = Mode::Value;
            ++i;
            continue;
        }
        // Value mode.
        if (c == '[' || c == '{') {
            if (level + 1 > maxDepth)
                return violated(text, i, violation);
            frames.push_back({level, level + 1, c == '{'});
            level += 1;
            if (c == '{')
                mode = Mode::Key;
        } else if (c == ',' && !frames.empty()) {
            level = frames.back().elementLevel;
            if (frames.back().inlineTable)
                mode = Mode::Key;
        }
        ++i;
    }
    return false;
}

} // namespace scenes
