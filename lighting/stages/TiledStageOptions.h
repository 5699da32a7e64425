// The options `tiled`, `tiled-backface` and `tiled-forward` share about how tiles find their
// lights (buildTileLightLists, culling/TileFrusta.h), declared in one place:
//   assign=loop|bvh  every light against every tile, or the lights a light BVH
//                    (culling/LightBvh.h) returns for the tile's box
//   hier=0|1         hierarchical tile culling: 4x4 groups of tiles get a list first
// Both change only the cost: the lists, and so the image, are the same for every choice (tested
// in tests/lighting/stages/light_bvh_stages_test.cpp).
#pragma once

#include "lighting/StageOptions.h"

namespace lighting {

inline StageOption tiledAssignOption() {
    return StageOption::choice("assign", {"loop", "bvh"},
                               "how a tile finds the lights to test: every light, or a light BVH "
                               "queried with the tile's box (same lists)");
}

inline StageOption tiledHierOption() {
    return StageOption::boolean("hier", false,
                                "hierarchical tile culling: 4x4 groups of tiles get a list first, "
                                "fine tiles test only their group's list (same lists)");
}

} // namespace lighting
