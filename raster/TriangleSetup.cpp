// Triangle set-up's planes per instruction set: hwy/foreach_target.h compiles this file once per
// target Highway builds (the policy of DepthSpan.cpp), and HWY_DYNAMIC_DISPATCH calls the best one
// this CPU runs. See TriangleSetup.h for the contract; every step below is written in the scalar
// oracle's order, operation for operation.
#include "raster/TriangleSetup.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/TriangleSetup.cpp"
#include <hwy/foreach_target.h> // must come before highway.h

#include <hwy/highway.h>

// The snapped fixed point's scale (Rasterizer.h, kSubpixelScale), restated here so that this file
// needs nothing but the packet.
#ifndef RASTER_TRIANGLE_SETUP_SCALE
#define RASTER_TRIANGLE_SETUP_SCALE
namespace raster::setup_detail {
inline constexpr double kSubpixelScale = 256.0;
// Below this fraction of the snapped area, the unsnapped triangle is taken as degenerate and the
// snapped positions, then the only consistent description, give the planes.
inline constexpr double kDegenerateAreaRatio = 1e-6;
} // namespace raster::setup_detail
#endif

HWY_BEFORE_NAMESPACE();
namespace raster::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

void setUpPlanesVector(SetupPacket& p, const SetupViewport& viewport) {
    using setup_detail::kSubpixelScale;
    const hn::ScalableTag<double> d;
    const hn::Rebind<float, decltype(d)> df;
    const size_t lanes = hn::Lanes(d);
    const auto one = hn::Set(d, 1.0);
    const auto half = hn::Set(d, 0.5);
    const auto zero = hn::Zero(d);
    const auto halfWidth = hn::Set(d, 0.5 * viewport.width);
    const auto halfHeight = hn::Set(d, 0.5 * viewport.height);
    const auto scale = hn::Set(d, kSubpixelScale);
    const auto scaleSquared = hn::Set(d, kSubpixelScale * kSubpixelScale);
    const auto degenerateRatio = hn::Set(d, setup_detail::kDegenerateAreaRatio);
    for (size_t lane = 0; lane < size_t(p.count); lane += lanes) {
        // Unsnapped screen positions and depths, one division per vertex.
        hn::Vec<decltype(d)> x[3], y[3], depth[3], sx[3], sy[3];
        for (int i = 0; i < 3; ++i) {
            const auto inverseW = hn::Div(one, hn::LoadU(d, p.clipW[i] + lane));
            x[i] = hn::Mul(hn::Add(hn::Mul(hn::LoadU(d, p.clipX[i] + lane), inverseW), one),
                           halfWidth);
            y[i] = hn::Mul(hn::Sub(one, hn::Mul(hn::LoadU(d, p.clipY[i] + lane), inverseW)),
                           halfHeight);
            depth[i] = hn::Mul(hn::LoadU(d, p.clipZ[i] + lane), inverseW);
            sx[i] = hn::LoadU(d, p.snappedX[i] + lane);
            sy[i] = hn::LoadU(d, p.snappedY[i] + lane);
        }
        auto area = hn::Sub(hn::Mul(hn::Sub(x[1], x[0]), hn::Sub(y[2], y[0])),
                            hn::Mul(hn::Sub(y[1], y[0]), hn::Sub(x[2], x[0])));
        const auto snappedArea =
            hn::Div(hn::Sub(hn::Mul(hn::Sub(sx[1], sx[0]), hn::Sub(sy[2], sy[0])),
                            hn::Mul(hn::Sub(sy[1], sy[0]), hn::Sub(sx[2], sx[0]))),
                    scaleSquared);
        // !(area > ratio * snapped): NaN areas take the snapped positions too.
        const auto degenerate = hn::Not(hn::Gt(area, hn::Mul(degenerateRatio, snappedArea)));
        for (int i = 0; i < 3; ++i) {
            x[i] = hn::IfThenElse(degenerate, hn::Div(sx[i], scale), x[i]);
            y[i] = hn::IfThenElse(degenerate, hn::Div(sy[i], scale), y[i]);
        }
        area = hn::IfThenElse(degenerate, snappedArea, area);
        const auto inverseArea = hn::Div(one, area);
        // E_ab at pixel (px, py), sampled at (px + 0.5, py + 0.5), over the area.
        auto plane = [&](int a, int b, hn::Vec<decltype(d)> out[3]) {
            const auto dx = hn::Sub(x[b], x[a]), dy = hn::Sub(y[b], y[a]);
            out[1] = hn::Mul(hn::Neg(dy), inverseArea);
            out[2] = hn::Mul(dx, inverseArea);
            out[0] =
                hn::Mul(hn::Sub(hn::Mul(dx, hn::Sub(half, y[a])), hn::Mul(dy, hn::Sub(half, x[a]))),
                        inverseArea);
        };
        hn::Vec<decltype(d)> l1[3], l2[3];
        plane(2, 0, l1);
        plane(0, 1, l2);
        const auto depth10 = hn::Sub(depth[1], depth[0]);
        const auto depth20 = hn::Sub(depth[2], depth[0]);
        for (int k = 0; k < 3; ++k)
            hn::StoreU(hn::Add(hn::Add(k == 0 ? depth[0] : zero, hn::Mul(l1[k], depth10)),
                               hn::Mul(l2[k], depth20)),
                       d, p.z[k] + lane);
        if (!viewport.barycentrics)
            continue;
        const auto minX = hn::LoadU(d, p.minX + lane), minY = hn::LoadU(d, p.minY + lane);
        auto corner = [&](const hn::Vec<decltype(d)> l[3]) {
            return hn::Add(hn::Add(l[0], hn::Mul(l[1], minX)), hn::Mul(l[2], minY));
        };
        hn::StoreU(hn::DemoteTo(df, corner(l1)), df, p.l1[0] + lane);
        hn::StoreU(hn::DemoteTo(df, corner(l2)), df, p.l2[0] + lane);
        for (int k = 1; k < 3; ++k) {
            hn::StoreU(hn::DemoteTo(df, l1[k]), df, p.l1[k] + lane);
            hn::StoreU(hn::DemoteTo(df, l2[k]), df, p.l2[k] + lane);
        }
    }
}

} // namespace raster::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace raster {

HWY_EXPORT(setUpPlanesVector);

void setUpPlanes(SetupPacket& packet, const SetupViewport& viewport) {
    HWY_DYNAMIC_DISPATCH(setUpPlanesVector)(packet, viewport);
}

// With the edge function E_ab(p) = (bx-ax)(py-ay) - (by-ay)(px-ax) of the unsnapped screen
// positions, the screen-space barycentrics are l1 = E_20 / area and l2 = E_01 / area, and depth is
// interpolated linearly with them. A triangle that is degenerate before snapping but not after
// takes the snapped positions, then the only consistent description of it.
void setUpPlanesScalar(SetupPacket& p, const SetupViewport& viewport) {
    using setup_detail::kSubpixelScale;
    for (int lane = 0; lane < p.count; ++lane) {
        double x[3], y[3], depth[3];
        for (int i = 0; i < 3; ++i) {
            const double inverseW = 1.0 / p.clipW[i][lane];
            x[i] = (p.clipX[i][lane] * inverseW + 1.0) * (0.5 * viewport.width);
            y[i] = (1.0 - p.clipY[i][lane] * inverseW) * (0.5 * viewport.height);
            depth[i] = p.clipZ[i][lane] * inverseW;
        }
        const double(&sx)[3][kSetupPacketSize] = p.snappedX;
        const double(&sy)[3][kSetupPacketSize] = p.snappedY;
        double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
        const double snappedArea = ((sx[1][lane] - sx[0][lane]) * (sy[2][lane] - sy[0][lane]) -
                                    (sy[1][lane] - sy[0][lane]) * (sx[2][lane] - sx[0][lane])) /
                                   (kSubpixelScale * kSubpixelScale);
        if (!(area > setup_detail::kDegenerateAreaRatio * snappedArea)) {
            for (int i = 0; i < 3; ++i) {
                x[i] = sx[i][lane] / kSubpixelScale;
                y[i] = sy[i][lane] / kSubpixelScale;
            }
            area = snappedArea;
        }
        const double inverseArea = 1.0 / area; // one division per triangle, not six
        double l1[3], l2[3];
        auto plane = [&](int a, int b, double out[3]) {
            const double dx = x[b] - x[a], dy = y[b] - y[a];
            out[1] = -dy * inverseArea;
            out[2] = dx * inverseArea;
            out[0] = (dx * (0.5 - y[a]) - dy * (0.5 - x[a])) * inverseArea;
        };
        plane(2, 0, l1);
        plane(0, 1, l2);
        for (int k = 0; k < 3; ++k)
            p.z[k][lane] = (k == 0 ? depth[0] : 0.0) + l1[k] * (depth[1] - depth[0]) +
                           l2[k] * (depth[2] - depth[0]);
        if (!viewport.barycentrics)
            continue;
        p.l1[0][lane] = float(l1[0] + l1[1] * p.minX[lane] + l1[2] * p.minY[lane]);
        p.l2[0][lane] = float(l2[0] + l2[1] * p.minX[lane] + l2[2] * p.minY[lane]);
        for (int k = 1; k < 3; ++k) {
            p.l1[k][lane] = float(l1[k]);
            p.l2[k][lane] = float(l2[k]);
        }
    }
}

} // namespace raster
#endif // HWY_ONCE
