#include "scenes/gltf/GltfConverter.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <system_error>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <stb/stb_image.h>
#include <tiny_gltf.h>

#include "scenes/Viewpoints.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/mesh/Tangents.h"

namespace scenes::gltf {

const tinygltf::Accessor& GltfConverter::accessorAt(int accessorIndex,
                                                    const std::string& what) const {
    if (accessorIndex < 0 || size_t(accessorIndex) >= mModel.accessors.size())
        fail(what + ": accessor " + std::to_string(accessorIndex) + " out of range");
    return mModel.accessors[size_t(accessorIndex)];
}

AccessorData GltfConverter::accessorData(const tinygltf::Accessor& accessor,
                                         const std::string& where) const {
    if (accessor.sparse.isSparse)
        fail(where + ": sparse accessors are not supported");
    if (accessor.bufferView < 0)
        fail(where + ": no bufferView (zero-filled accessors are not supported)");
    if (size_t(accessor.bufferView) >= mModel.bufferViews.size())
        fail(where + ": bufferView " + std::to_string(accessor.bufferView) + " out of range");
    const tinygltf::BufferView& view = mModel.bufferViews[size_t(accessor.bufferView)];
    if (view.buffer < 0 || size_t(view.buffer) >= mModel.buffers.size())
        fail(where + ": buffer " + std::to_string(view.buffer) + " out of range");
    const std::vector<unsigned char>& buffer = mModel.buffers[size_t(view.buffer)].data;
    if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
        fail(where + ": bufferView " + std::to_string(accessor.bufferView) + " (" +
             str(view.byteLength) + " bytes from byte " + str(view.byteOffset) +
             ") runs past the end of buffer " + std::to_string(view.buffer) + " (" +
             str(buffer.size()) + " bytes)");

    const int componentBytes = tinygltf::GetComponentSizeInBytes(uint32_t(accessor.componentType));
    const int components = tinygltf::GetNumComponentsInType(uint32_t(accessor.type));
    if (componentBytes <= 0 || components <= 0)
        fail(where + ": invalid componentType or type");
    const size_t elementBytes = size_t(componentBytes) * size_t(components);
    const size_t strideBytes = view.byteStride == 0 ? elementBytes : view.byteStride;
    if (strideBytes < elementBytes)
        fail(where + ": byteStride " + str(strideBytes) + " is smaller than an element (" +
             str(elementBytes) + " bytes)");
    if (accessor.count == 0)
        fail(where + ": count is 0");
    // Written with a division so that no product can overflow, whatever the file claims.
    const size_t available =
        accessor.byteOffset <= view.byteLength ? view.byteLength - accessor.byteOffset : 0;
    if (elementBytes > available || (accessor.count - 1) > (available - elementBytes) / strideBytes)
        fail(where + ": " + str(accessor.count) + " elements of " + str(elementBytes) +
             " bytes every " + str(strideBytes) + " bytes from byte " + str(accessor.byteOffset) +
             " run past the end of bufferView " + std::to_string(accessor.bufferView) + " (" +
             str(view.byteLength) + " bytes)");
    return {buffer.data() + view.byteOffset + accessor.byteOffset, strideBytes, accessor.count};
}

// Float vectors of N components; with allowNormalizedIntegers also normalized unsigned bytes and
// shorts (as glTF allows for texture coordinates). Every value must be finite.
template <int N>
std::vector<glm::vec<N, float>> GltfConverter::readVectors(int accessorIndex,
                                                           const std::string& what,
                                                           bool allowNormalizedIntegers) const {
    const tinygltf::Accessor& accessor = accessorAt(accessorIndex, what);
    const std::string where = what + " (accessor " + std::to_string(accessorIndex) + ")";
    constexpr int kType = N == 2   ? TINYGLTF_TYPE_VEC2
                          : N == 3 ? TINYGLTF_TYPE_VEC3
                                   : TINYGLTF_TYPE_VEC4;
    const int componentType = accessor.componentType;
    const bool normalizedInteger = allowNormalizedIntegers && accessor.normalized &&
                                   (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                    componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (accessor.type != kType ||
        (componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !normalizedInteger))
        fail(where + ": expected VEC" + std::to_string(N) + " of FLOAT" +
             (allowNormalizedIntegers ? " or normalized UNSIGNED_BYTE/UNSIGNED_SHORT" : ""));

    const AccessorData data = accessorData(accessor, where);
    std::vector<glm::vec<N, float>> values(data.count);
    for (size_t i = 0; i < data.count; ++i) {
        const unsigned char* element = data.first + i * data.strideBytes;
        for (int c = 0; c < N; ++c) {
            float value;
            if (componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
                std::memcpy(&value, element + 4 * c, 4);
            } else if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
                value = float(element[c]) / 255.0f;
            } else {
                uint16_t integer;
                std::memcpy(&integer, element + 2 * c, 2);
                value = float(integer) / 65535.0f;
            }
            if (!std::isfinite(value))
                fail(where + ": element " + str(i) + " is NaN or infinite");
            values[i][c] = value;
        }
    }
    return values;
}

std::vector<uint32_t> GltfConverter::readIndices(int accessorIndex, const std::string& what,
                                                 size_t vertexCount) const {
    const tinygltf::Accessor& accessor = accessorAt(accessorIndex, what);
    const std::string where = what + " (accessor " + std::to_string(accessorIndex) + ")";
    const int componentType = accessor.componentType;
    if (accessor.type != TINYGLTF_TYPE_SCALAR ||
        (componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
         componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
         componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(where + ": expected SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");

    const AccessorData data = accessorData(accessor, where);
    std::vector<uint32_t> indices(data.count);
    for (size_t i = 0; i < data.count; ++i) {
        const unsigned char* element = data.first + i * data.strideBytes;
        uint32_t index = 0;
        if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
            index = element[0];
        } else if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
            uint16_t value;
            std::memcpy(&value, element, 2);
            index = value;
        } else {
            std::memcpy(&index, element, 4);
        }
        if (index >= vertexCount)
            fail(where + ": index " + std::to_string(index) + " (element " + str(i) +
                 ") out of range of " + str(vertexCount) + " vertices");
        indices[i] = index;
    }
    return indices;
}

template std::vector<glm::vec<2, float>> GltfConverter::readVectors<2>(int, const std::string&,
                                                                       bool) const;
template std::vector<glm::vec<3, float>> GltfConverter::readVectors<3>(int, const std::string&,
                                                                       bool) const;
template std::vector<glm::vec<4, float>> GltfConverter::readVectors<4>(int, const std::string&,
                                                                       bool) const;

} // namespace scenes::gltf
