#include "lighting/culling/LightBvh.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

namespace lighting {

namespace {

// Ranges of more sorted positions than this build their two children as parallel tasks: large
// enough that a task outweighs its spawn, small enough to balance 10^3 lights over a few cores.
constexpr uint32_t kParallelLeaves = 2048;
// Morton cells per axis: 2^21, so three axes fill 63 bits of the code.
constexpr int kMortonBits = 21;

// Spreads the low 21 bits of v so that bit k lands at bit 3k.
uint64_t spreadBits(uint64_t v) {
    v &= 0x1FFFFF;
    v = (v | v << 32) & 0x1F00000000FFFFull;
    v = (v | v << 16) & 0x1F0000FF0000FFull;
    v = (v | v << 8) & 0x100F00F00F00F00Full;
    v = (v | v << 4) & 0x10C30C30C30C30C3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

bool boxesOverlap(const glm::vec3& lo, const glm::vec3& hi, const ViewBox& box) {
    return lo.x <= box.hi.x && lo.y <= box.hi.y && lo.z <= box.hi.z && hi.x >= box.lo.x &&
           hi.y >= box.lo.y && hi.z >= box.lo.z;
}

// The tree fits a sphere that is finite (a non-finite one is returned by every query instead).
bool boundable(const LightSphere& s) {
    return !s.unbounded && std::isfinite(s.centreView.x) && std::isfinite(s.centreView.y) &&
           std::isfinite(s.centreView.z) && std::isfinite(s.radius) && s.radius >= 0.0f;
}

} // namespace

int LightBvh::delta(uint32_t i, uint32_t j) const {
    const uint64_t a = mKeys[i].code, b = mKeys[j].code;
    return a != b ? std::countl_zero(a ^ b) : 64 + std::countl_zero(i ^ j);
}

ViewBox LightBvh::buildRange(uint32_t first, uint32_t last, uint32_t node) {
    // Karras' split: the last position whose key shares more than the range's common prefix with
    // the first key (binary search; the range's keys are sorted).
    const int common = delta(first, last);
    uint32_t split = first, step = last - first;
    do {
        step = (step + 1) >> 1;
        const uint32_t candidate = split + step;
        if (candidate < last && delta(first, candidate) > common)
            split = candidate;
    } while (step > 1);

    Node& n = mNodes[node];
    auto child = [&](int side, uint32_t from, uint32_t to, uint32_t index) {
        if (from == to) {
            const ViewBox& leaf = mLightBoxes[mKeys[from].light];
            n.lo[side] = leaf.lo;
            n.hi[side] = leaf.hi;
            n.child[side] = kLeafBit | from;
        } else {
            const ViewBox box = buildRange(from, to, index);
            n.lo[side] = box.lo;
            n.hi[side] = box.hi;
            n.child[side] = index;
        }
    };
    if (last - first > kParallelLeaves)
        tbb::parallel_invoke([&] { child(0, first, split, split); },
                             [&] { child(1, split + 1, last, split + 1); });
    else {
        child(0, first, split, split);
        child(1, split + 1, last, split + 1);
    }
    return {glm::min(n.lo[0], n.lo[1]), glm::max(n.hi[0], n.hi[1])};
}

void LightBvh::build(std::span<const LightSphere> spheres) {
    mLightCount = spheres.size();
    mUnbounded.clear();
    mLightBoxes.resize(spheres.size());
    // Leaf boxes (parallel, each light its own slot) and the box of the bounded centres.
    using CentreBox = std::pair<glm::vec3, glm::vec3>;
    const CentreBox centres = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, spheres.size(), 4096),
        CentreBox{glm::vec3(INFINITY), glm::vec3(-INFINITY)},
        [&](const tbb::blocked_range<size_t>& range, CentreBox box) {
            for (size_t i = range.begin(); i != range.end(); ++i) {
                const LightSphere& s = spheres[i];
                if (!boundable(s))
                    continue;
                // Rule 3 of the slack policy, magnitude |centre| + radius (header).
                const float reach =
                    s.radius + boundSlackMetres(glm::length(s.centreView) + s.radius);
                mLightBoxes[i] = {s.centreView - glm::vec3(reach), s.centreView + glm::vec3(reach)};
                box.first = glm::min(box.first, s.centreView);
                box.second = glm::max(box.second, s.centreView);
            }
            return box;
        },
        [](const CentreBox& a, const CentreBox& b) {
            return CentreBox{glm::min(a.first, b.first), glm::max(a.second, b.second)};
        });

    // Keys of the bounded lights, in light order (serial: a copy, cheaper than a parallel pack).
    mKeys.clear();
    for (uint32_t i = 0; i < uint32_t(spheres.size()); ++i) {
        if (boundable(spheres[i]))
            mKeys.push_back({0, i});
        else
            mUnbounded.push_back(i);
    }
    const glm::dvec3 origin(centres.first);
    const glm::dvec3 extent = glm::dvec3(centres.second) - origin;
    const double cells = double(1 << kMortonBits);
    glm::dvec3 scale(0.0);
    for (int axis = 0; axis < 3; ++axis)
        scale[axis] = extent[axis] > 0.0 ? (cells - 1.0) / extent[axis] : 0.0;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mKeys.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t k = range.begin(); k != range.end(); ++k) {
                              const glm::dvec3 cell =
                                  (glm::dvec3(spheres[mKeys[k].light].centreView) - origin) * scale;
                              mKeys[k].code = spreadBits(uint64_t(cell.x)) << 2 |
                                              spreadBits(uint64_t(cell.y)) << 1 |
                                              spreadBits(uint64_t(cell.z));
                          }
                      });
    // (code, light) pairs are unique: the sorted order is the same for any thread count.
    tbb::parallel_sort(mKeys.begin(), mKeys.end(), [](const Key& a, const Key& b) {
        return a.code != b.code ? a.code < b.code : a.light < b.light;
    });
    const uint32_t count = uint32_t(mKeys.size());
    mLeafLights.resize(count);
    for (uint32_t p = 0; p < count; ++p)
        mLeafLights[p] = mKeys[p].light;

    mNodes.resize(count > 1 ? count - 1 : 0);
    if (count == 0) {
        mRoot = kLeafBit;
        mRootBox = {glm::vec3(INFINITY), glm::vec3(-INFINITY)};
    } else if (count == 1) {
        mRoot = kLeafBit | 0u;
        mRootBox = mLightBoxes[mKeys[0].light];
    } else {
        mRoot = 0;
        mRootBox = buildRange(0, count - 1, 0);
    }
}

void LightBvh::candidates(const ViewBox& box, std::vector<uint32_t>& out) const {
    const size_t begin = out.size();
    if (!mLeafLights.empty() && boxesOverlap(mRootBox.lo, mRootBox.hi, box)) {
        if (mRoot & kLeafBit) {
            out.push_back(mLeafLights[mRoot & ~kLeafBit]);
        } else {
            // Depth <= 96 (header): one pending sibling per level at most.
            uint32_t stack[128];
            int top = 0;
            stack[top++] = mRoot;
            while (top > 0) {
                const Node& n = mNodes[stack[--top]];
                for (int side = 0; side < 2; ++side) {
                    if (!boxesOverlap(n.lo[side], n.hi[side], box))
                        continue;
                    if (n.child[side] & kLeafBit)
                        out.push_back(mLeafLights[n.child[side] & ~kLeafBit]);
                    else
                        stack[top++] = n.child[side];
                }
            }
        }
    }
    out.insert(out.end(), mUnbounded.begin(), mUnbounded.end());
    std::sort(out.begin() + std::ptrdiff_t(begin), out.end());
}

void LightBvh::lightsTouching(std::span<const LightSphere> spheres, const ViewBox& box,
                              std::vector<uint32_t>& out) const {
    const size_t begin = out.size();
    candidates(box, out);
    const auto kept =
        std::remove_if(out.begin() + std::ptrdiff_t(begin), out.end(),
                       [&](uint32_t light) { return !sphereTouchesBox(spheres[light], box); });
    out.erase(kept, out.end());
}

} // namespace lighting
