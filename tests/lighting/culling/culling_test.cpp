// The shared culling pieces (lighting/culling/): the CSR light lists against their definition,
// and the one sphere/box test and the receiver slack against brute-force geometry.
#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightIndexLists.h"

namespace {

using lighting::LightIndexLists;

std::vector<std::vector<uint32_t>> randomLists(std::mt19937& random, size_t listCount,
                                               uint32_t indexCount) {
    std::bernoulli_distribution keep(0.3);
    std::vector<std::vector<uint32_t>> lists(listCount);
    for (auto& list : lists)
        for (uint32_t i = 0; i < indexCount; ++i)
            if (keep(random))
                list.push_back(i);
    return lists;
}

void expectEqual(const LightIndexLists& csr, const std::vector<std::vector<uint32_t>>& lists) {
    ASSERT_EQ(csr.listCount(), lists.size());
    size_t pairs = 0;
    for (size_t i = 0; i < lists.size(); ++i) {
        const auto span = csr[i];
        EXPECT_EQ(std::vector<uint32_t>(span.begin(), span.end()), lists[i]) << "list " << i;
        pairs += lists[i].size();
    }
    EXPECT_EQ(csr.pairCount(), pairs);
}

TEST(LightIndexLists, AssignHoldsEachListInOrder) {
    std::mt19937 random(3);
    const auto lists = randomLists(random, 37, 50);
    LightIndexLists csr;
    csr.assign(lists);
    expectEqual(csr, lists);
    // Reassigning reuses the object: fewer lists, then none.
    const auto fewer = randomLists(random, 5, 9);
    csr.assign(fewer);
    expectEqual(csr, fewer);
    csr.assign(std::span<const std::vector<uint32_t>>());
    EXPECT_EQ(csr.listCount(), 0u);
    EXPECT_EQ(csr.pairCount(), 0u);
}

TEST(LightIndexLists, ChunksOfSeveralListsGiveTheSameLists) {
    std::mt19937 random(4);
    const auto lists = randomLists(random, 40, 30);
    // Chunks of 8 lists each (like the rows of per-pixel lists).
    std::vector<uint32_t> counts;
    std::vector<std::vector<uint32_t>> chunks;
    for (size_t i = 0; i < lists.size(); ++i) {
        if (i % 8 == 0)
            chunks.emplace_back();
        counts.push_back(uint32_t(lists[i].size()));
        chunks.back().insert(chunks.back().end(), lists[i].begin(), lists[i].end());
    }
    LightIndexLists csr;
    csr.assign(counts, chunks);
    expectEqual(csr, lists);
    counts[0] += 1;
    EXPECT_THROW(csr.assign(counts, chunks), std::logic_error);
}

TEST(LightIndexLists, PairsAndTransposeMatchTheirDefinition) {
    std::mt19937 random(5);
    const auto lists = randomLists(random, 23, 41);
    // Pairs in batches of 3 indices, in index order (as ClusterGrid::assign makes them).
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> batches;
    for (uint32_t index = 0; index < 41; ++index) {
        if (index % 3 == 0)
            batches.emplace_back();
        for (uint32_t list = 0; list < lists.size(); ++list)
            for (uint32_t member : lists[list])
                if (member == index)
                    batches.back().emplace_back(list, index);
    }
    LightIndexLists fromPairs;
    fromPairs.assignFromPairs(lists.size(), batches);
    expectEqual(fromPairs, lists);

    std::vector<std::vector<uint32_t>> transpose(41);
    for (uint32_t list = 0; list < lists.size(); ++list)
        for (uint32_t member : lists[list])
            transpose[member].push_back(list);
    expectEqual(fromPairs.transposed(41), transpose);
}

TEST(CullingTests, SphereTouchesBoxIsTheDistanceToTheBox) {
    std::mt19937 random(6);
    std::uniform_real_distribution<float> coordinate(-5.0f, 5.0f), radius(0.0f, 3.0f);
    const glm::vec3 lo(-1.0f, -0.5f, -2.0f), hi(1.0f, 0.5f, -1.0f);
    for (int i = 0; i < 2000; ++i) {
        const glm::vec3 c(coordinate(random), coordinate(random), coordinate(random));
        const float r = radius(random);
        // Brute force: the nearest point of the box, axis by axis.
        const glm::vec3 nearest = glm::clamp(c, lo, hi);
        const bool touches = glm::length(glm::dvec3(c) - glm::dvec3(nearest)) <= double(r) - 1e-4;
        const bool misses = glm::length(glm::dvec3(c) - glm::dvec3(nearest)) > double(r) + 1e-4;
        const bool test = lighting::sphereTouchesBox(c, r, lo, hi);
        if (touches) {
            EXPECT_TRUE(test) << i;
        }
        if (misses) {
            EXPECT_FALSE(test) << i;
        }
    }
    lighting::LightSphere unbounded;
    unbounded.unbounded = true;
    unbounded.centreView = glm::vec3(100.0f);
    EXPECT_TRUE(lighting::sphereTouchesBox(unbounded, {lo, hi}));
}

TEST(CullingTests, WidenedBoxGrowsByTheSlackOfItsLargestCoordinate) {
    const lighting::ViewBox box = lighting::widenedBox({-1.0f, 2.0f, -30.0f}, {1.0f, 3.0f, -20.0f});
    const float slack = lighting::boundSlackMetres(30.0f);
    EXPECT_GT(slack, 30.0f * 1e-6f); // far above the float error at 30 m (~2e-6)
    EXPECT_FLOAT_EQ(box.lo.x, -1.0f - slack);
    EXPECT_FLOAT_EQ(box.hi.y, 3.0f + slack);
    EXPECT_FLOAT_EQ(box.lo.z, -30.0f - slack);
    EXPECT_FLOAT_EQ(box.hi.z, -20.0f + slack);
}

} // namespace
