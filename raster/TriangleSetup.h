// TriangleSetup: the floating-point half of triangle set-up, the depth plane and the barycentric
// planes of SetupTriangle / SetupBarycentrics (Rasterizer.h), for a packet of triangles at once.
// The integer half (outcodes, clipping, snapped area, culling, pixel bounds) stays one triangle
// at a time in Rasterizer.cpp: it decides which triangles need planes at all, so the packet holds
// only survivors and its lanes stay full. What remains per survivor is four double divisions (1/w
// of each vertex, 1/area) and about sixty multiplies and adds, which the packet runs on SIMD lanes
// through Google Highway with run-time dispatch (TriangleSetup.cpp, one copy per instruction set);
// the scalar function stays as its oracle (RasterState::scalarSetup selects it for a whole draw).
//
// Exactness: both evaluate the same IEEE double operations in the same order (no FMA:
// -ffp-contract=off; the snapped coordinates and the clip positions are exact doubles), select the
// snapped positions for a triangle that is degenerate before snapping by the same comparison, and
// round to float the same way, so the planes are bitwise equal and so is every image drawn with
// them (tests/raster/triangle_setup_test.cpp).
#pragma once

#include <cstdint>

namespace raster {

// Lanes in one packet: a multiple of every double vector width Highway builds (2, 4, 8).
inline constexpr int kSetupPacketSize = 16;

// Structure of arrays, one lane per triangle; vertices in set-up order (the order that makes the
// snapped area positive, Rasterizer.cpp). Lanes at or past `count` are ignored.
struct SetupPacket {
    // In: clip positions (float inputs widened exactly), the snapped fixed-point coordinates as
    // doubles (exact: below 2^23), and the pixel bounds' corner the barycentrics are relative to.
    double clipX[3][kSetupPacketSize], clipY[3][kSetupPacketSize];
    double clipZ[3][kSetupPacketSize], clipW[3][kSetupPacketSize];
    double snappedX[3][kSetupPacketSize], snappedY[3][kSetupPacketSize];
    double minX[kSetupPacketSize], minY[kSetupPacketSize];
    // Out: z(px, py) = z[0] + z[1] px + z[2] py (pixel centres folded in); the screen-space
    // barycentrics l1, l2 relative to (minX, minY), rounded to float (only with barycentrics).
    double z[3][kSetupPacketSize];
    float l1[3][kSetupPacketSize], l2[3][kSetupPacketSize];
    int count = 0;
};

// The viewport the clip positions are mapped to, and whether l1 / l2 are wanted.
struct SetupViewport {
    int width = 0;
    int height = 0;
    bool barycentrics = true;
};

// The planes of lanes [0, packet.count) on the widest SIMD lanes this CPU runs.
void setUpPlanes(SetupPacket& packet, const SetupViewport& viewport);
// The same, one lane at a time: the oracle.
void setUpPlanesScalar(SetupPacket& packet, const SetupViewport& viewport);

} // namespace raster
