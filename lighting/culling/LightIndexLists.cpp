#include "lighting/culling/LightIndexLists.h"

#include <algorithm>
#include <stdexcept>

#include <tbb/parallel_for.h>

namespace lighting {

namespace {

void checkPairCount(uint64_t total) {
    if (total >= uint64_t(UINT32_MAX))
        throw std::length_error("LightIndexLists: more than 2^32 - 1 pairs");
}

} // namespace

void LightIndexLists::assign(std::span<const uint32_t> counts,
                             std::span<const std::vector<uint32_t>> chunks) {
    mOffsets.resize(counts.size() + 1);
    mOffsets[0] = 0;
    uint64_t total = 0;
    for (size_t i = 0; i < counts.size(); ++i) {
        total += counts[i];
        checkPairCount(total);
        mOffsets[i + 1] = uint32_t(total);
    }
    std::vector<uint32_t> chunkStart(chunks.size() + 1, 0);
    uint64_t chunked = 0;
    for (size_t c = 0; c < chunks.size(); ++c) {
        chunked += chunks[c].size();
        checkPairCount(chunked);
        chunkStart[c + 1] = uint32_t(chunked);
    }
    if (chunked != total)
        throw std::logic_error("LightIndexLists::assign: chunks do not hold the counted entries");
    mIndices.resize(size_t(total));
    tbb::parallel_for(size_t(0), chunks.size(), [&](size_t c) {
        std::copy(chunks[c].begin(), chunks[c].end(), mIndices.begin() + chunkStart[c]);
    });
}

void LightIndexLists::assign(std::span<const std::vector<uint32_t>> lists) {
    std::vector<uint32_t> counts(lists.size());
    for (size_t i = 0; i < lists.size(); ++i)
        counts[i] = uint32_t(std::min<size_t>(lists[i].size(), UINT32_MAX));
    assign(counts, lists);
}

void LightIndexLists::assignFromPairs(
    size_t listCount, std::span<const std::vector<std::pair<uint32_t, uint32_t>>> batches) {
    uint64_t total = 0;
    for (const auto& pairs : batches)
        total += pairs.size();
    checkPairCount(total);
    mOffsets.assign(listCount + 1, 0u);
    for (const auto& pairs : batches)
        for (const auto& pair : pairs)
            ++mOffsets[pair.first + 1];
    for (size_t i = 1; i < mOffsets.size(); ++i)
        mOffsets[i] += mOffsets[i - 1];
    mIndices.resize(size_t(total));
    std::vector<uint32_t> cursor(mOffsets.begin(), mOffsets.end() - 1);
    for (const auto& pairs : batches)
        for (const auto& pair : pairs)
            mIndices[cursor[pair.first]++] = pair.second;
}

LightIndexLists LightIndexLists::transposed(size_t resultListCount) const {
    LightIndexLists result;
    result.mOffsets.assign(resultListCount + 1, 0u);
    for (uint32_t index : mIndices)
        ++result.mOffsets[index + 1];
    for (size_t j = 1; j < result.mOffsets.size(); ++j)
        result.mOffsets[j] += result.mOffsets[j - 1];
    result.mIndices.resize(mIndices.size());
    std::vector<uint32_t> cursor(result.mOffsets.begin(), result.mOffsets.end() - 1);
    for (size_t i = 0; i < listCount(); ++i)
        for (uint32_t index : (*this)[i])
            result.mIndices[cursor[index]++] = uint32_t(i);
    return result;
}

} // namespace lighting
