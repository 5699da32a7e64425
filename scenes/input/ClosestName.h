// ClosestName: "did you mean ...?" for a mistyped name (a stage, a scene, a codec, a subcommand or
// an option of the CLI): the valid name at the smallest edit distance (Levenshtein, ASCII
// case-insensitive), offered only when that distance is small against the name's length (at most
// 1 for names up to 4 characters, 2 up to 8, else 3), so that a wholly different word gets no
// suggestion rather than a random one. Ties go to the first candidate in the list's order.
//
// Header-only (scenes is the library every other one links); pure functions, no shared state.
#pragma once

#include <algorithm>
#include <cctype>
#include <optional>
#include <string>
#include <vector>

namespace scenes {

inline size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<size_t> previous(b.size() + 1), current(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j)
        previous[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        current[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                              std::tolower(static_cast<unsigned char>(b[j - 1]));
            current[j] =
                std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (same ? 0 : 1)});
        }
        std::swap(previous, current);
    }
    return previous[b.size()];
}

// The candidate closest to name within the distance allowed for its length, or nullopt.
inline std::optional<std::string> closestName(const std::string& name,
                                              const std::vector<std::string>& candidates) {
    const size_t allowed = name.size() <= 4 ? 1 : name.size() <= 8 ? 2 : 3;
    std::optional<std::string> best;
    size_t bestDistance = allowed + 1;
    for (const std::string& candidate : candidates) {
        const size_t distance = editDistance(name, candidate);
        if (distance < bestDistance && candidate != name) {
            best = candidate;
            bestDistance = distance;
        }
    }
    return best;
}

// " (did you mean 'X'?)" for the closest candidate, or "" when none is close.
inline std::string didYouMean(const std::string& name, const std::vector<std::string>& candidates) {
    const std::optional<std::string> best = closestName(name, candidates);
    return best ? " (did you mean '" + *best + "'?)" : "";
}

} // namespace scenes
