#include "lighting/lists/PacketContributingLights.h"

#include <algorithm>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "lighting/kernel/ShadingPacket.h"

namespace lighting {

using kernel::kPacketHeight;
using kernel::kPacketLanes;
using kernel::kPacketWidth;

void PacketContributingLights::build(const ContributingLights& pixels, size_t lightCount) {
    const int width = pixels.width(), height = pixels.height();
    mPacketsX = size_t((width + kPacketWidth - 1) / kPacketWidth);
    const int packetRows = (height + kPacketHeight - 1) / kPacketHeight;
    mOffsets.assign(mPacketsX * size_t(packetRows) + 1, 0);
    mRowIndices.resize(size_t(packetRows));
    mRowMasks.resize(size_t(packetRows));
    // Pass 1, packet rows in parallel: a lane mask per light (touched lights listed, then sorted),
    // each row's lists into its own vectors and each packet's count into mOffsets[packet + 1].
    tbb::parallel_for(0, packetRows, [&](int row) {
        std::vector<uint16_t> maskOfLight(lightCount, 0);
        std::vector<uint32_t> touched;
        std::vector<uint32_t>& indices = mRowIndices[size_t(row)];
        std::vector<uint16_t>& masks = mRowMasks[size_t(row)];
        indices.clear();
        masks.clear();
        for (size_t px = 0; px < mPacketsX; ++px) {
            touched.clear();
            for (int lane = 0; lane < kPacketLanes; ++lane) {
                const int x = int(px) * kPacketWidth + kernel::laneX(lane);
                const int y = row * kPacketHeight + kernel::laneY(lane);
                if (x >= width || y >= height)
                    continue;
                for (uint32_t light : pixels.lightsOf(size_t(y) * size_t(width) + size_t(x))) {
                    if (maskOfLight[light] == 0)
                        touched.push_back(light);
                    maskOfLight[light] |= uint16_t(1u << lane);
                }
            }
            std::sort(touched.begin(), touched.end());
            for (uint32_t light : touched) {
                indices.push_back(light);
                masks.push_back(maskOfLight[light]);
                maskOfLight[light] = 0;
            }
            mOffsets[size_t(row) * mPacketsX + px + 1] = uint32_t(touched.size());
        }
    });
    // Pass 2: prefix sum in packet order, then each row's lists copied to its place.
    uint64_t total = 0;
    for (size_t packet = 1; packet < mOffsets.size(); ++packet) {
        total += mOffsets[packet];
        if (total >= uint64_t(UINT32_MAX))
            throw std::length_error("PacketContributingLights: too many (packet, light) pairs");
        mOffsets[packet] = uint32_t(total);
    }
    mIndices.resize(size_t(total));
    mLaneMasks.resize(size_t(total));
    tbb::parallel_for(0, packetRows, [&](int row) {
        const size_t first = mOffsets[size_t(row) * mPacketsX];
        std::copy(mRowIndices[size_t(row)].begin(), mRowIndices[size_t(row)].end(),
                  mIndices.begin() + first);
        std::copy(mRowMasks[size_t(row)].begin(), mRowMasks[size_t(row)].end(),
                  mLaneMasks.begin() + first);
    });
}

} // namespace lighting
