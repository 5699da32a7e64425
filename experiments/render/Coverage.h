// Coverage: whether a render shows any of its scene (issue 32, class 2). A render in which no
// pixel is covered is an image of the background only; with geometry in front of the camera that
// is nearly always a mistake (a degenerate camera, a far plane nearer than the geometry, a scene
// placed far outside the view), and it must not pass as a result. measureCoverage counts the
// covered pixels and, only when there are none, the triangles with a vertex in front of the
// camera's near plane (view-space z < -near, in double); the warning goes to the render summary,
// stderr and stats.json ("coverage" and "warnings").
//
// Cost: one pass over the pixels; the triangle count only for an uncovered frame (one pass over
// the flattened geometry). Thread safety: reads the prepared scene only.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "lighting/PreparedScene.h"

namespace experiments {

struct Coverage {
    uint64_t coveredPixels = 0; // pixels where the G-buffer holds a surface
    uint64_t pixels = 0;
    uint64_t triangles = 0; // drawn (over instances)
    // Triangles with a vertex in front of the near plane; counted only when no pixel is covered
    // (else unset, -1 in JSON terms: null).
    int64_t trianglesInFront = -1;
    std::string warning; // "" when a pixel is covered or the scene draws no triangle

    nlohmann::json toJson() const;
};

Coverage measureCoverage(const lighting::PreparedScene& prepared);

} // namespace experiments
