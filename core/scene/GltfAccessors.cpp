#include "core/scene/GltfAccessors.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "core/Error.h"
#include "core/scene/GltfScreening.h"

namespace mirage::gltf {

const char* typeName(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return "SCALAR";
        case TINYGLTF_TYPE_VEC2:
            return "VEC2";
        case TINYGLTF_TYPE_VEC3:
            return "VEC3";
        case TINYGLTF_TYPE_VEC4:
            return "VEC4";
        case TINYGLTF_TYPE_MAT2:
            return "MAT2";
        case TINYGLTF_TYPE_MAT3:
            return "MAT3";
        case TINYGLTF_TYPE_MAT4:
            return "MAT4";
        default:
            return "unknown";
    }
}

const char* componentTypeName(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return "BYTE (5120)";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return "UNSIGNED_BYTE (5121)";
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return "SHORT (5122)";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return "UNSIGNED_SHORT (5123)";
        case TINYGLTF_COMPONENT_TYPE_INT:
            return "INT (5124)";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return "UNSIGNED_INT (5125)";
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return "FLOAT (5126)";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE:
            return "DOUBLE (5130, not glTF)";
        default:
            return "unknown";
    }
}

int componentCount(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return 1;
        case TINYGLTF_TYPE_VEC2:
            return 2;
        case TINYGLTF_TYPE_VEC3:
            return 3;
        case TINYGLTF_TYPE_VEC4:
            return 4;
        case TINYGLTF_TYPE_MAT2:
            return 4;
        case TINYGLTF_TYPE_MAT3:
            return 9;
        case TINYGLTF_TYPE_MAT4:
            return 16;
        default:
            return 0;
    }
}

int componentBytes(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return 2;
        case TINYGLTF_COMPONENT_TYPE_INT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return 4;
        default:
            return 0;
    }
}

// The value of type T at `p` (unaligned). Normalized 8- and 16-bit integers are divided by their
// largest value, signed ones clamped at -1 (glTF 3.11: [0,1] or [-1,1]); glTF has no normalized
// 32-bit components.
template <class T>
double loadComponent(const unsigned char* p, bool normalized) {
    T v;
    std::memcpy(&v, p, sizeof v);
    if constexpr (std::is_integral_v<T> && sizeof(T) < 4)
        if (normalized) return std::max(double(v) / double(std::numeric_limits<T>::max()), -1.0);
    return double(v);
}

// One component at `p` as a double; normalized integers map to [0,1] or [-1,1] (glTF 3.11).
double readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return loadComponent<int8_t>(p, normalized);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return loadComponent<uint8_t>(p, normalized);
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return loadComponent<int16_t>(p, normalized);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return loadComponent<uint16_t>(p, normalized);
        case TINYGLTF_COMPONENT_TYPE_INT:
            return loadComponent<int32_t>(p, normalized);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return loadComponent<uint32_t>(p, normalized);
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return loadComponent<float>(p, normalized);
        default:
            return 0.0;
    }
}

AccessorReader::AccessorReader(const tinygltf::Model& model, std::string file)
    : model_(model), file_(std::move(file)) {}

void AccessorReader::fail(const std::string& problem) const {
    throw FileError(file_, problem);
}

void AccessorReader::checkIndex(int index, size_t size, const std::string& what,
                                const char* target) const {
    if (index < 0 || static_cast<size_t>(index) >= size)
        fail(what + " refers to " + target + " " + std::to_string(index) + ", but the file has " +
             std::to_string(size) + " " + target + (size == 1 ? "" : "s") + " (valid: 0.." +
             (size == 0 ? std::string("none") : std::to_string(size - 1)) +
             "); fix the index or add the missing " + target);
}

std::pair<const unsigned char*, size_t> AccessorReader::viewBytes(int viewIndex,
                                                                  const std::string& what) const {
    checkIndex(viewIndex, model_.bufferViews.size(), what, "bufferView");
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(viewIndex)];
    const std::string viewName = "bufferView " + std::to_string(viewIndex);
    checkIndex(view.buffer, model_.buffers.size(), viewName + " field 'buffer'", "buffer");
    const tinygltf::Buffer& buffer = model_.buffers[static_cast<size_t>(view.buffer)];
    const size_t size = buffer.data.size();
    if (view.byteLength == 0)
        fail(viewName + " has byteLength 0; a bufferView must hold at least one byte");
    if (view.byteOffset > size || view.byteLength > size - view.byteOffset)
        fail(viewName + " covers bytes [" + std::to_string(view.byteOffset) + ", " +
             std::to_string(view.byteOffset + view.byteLength) + ") of buffer " +
             std::to_string(view.buffer) + ", which has only " + std::to_string(size) +
             " bytes; fix byteOffset/byteLength or the buffer");
    return {buffer.data.data() + view.byteOffset, view.byteLength};
}

std::vector<double> AccessorReader::readAccessor(int index, const std::string& what,
                                                 int expectedType,
                                                 const std::vector<int>& allowedComponentTypes,
                                                 bool requireNormalizedInts) const {
    checkIndex(index, model_.accessors.size(), what, "accessor");
    const tinygltf::Accessor& acc = model_.accessors[static_cast<size_t>(index)];
    const std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
    if (acc.type != expectedType)
        fail(name + " has type " + typeName(acc.type) + ", expected " + typeName(expectedType));
    if (std::find(allowedComponentTypes.begin(), allowedComponentTypes.end(), acc.componentType) ==
        allowedComponentTypes.end()) {
        std::string allowed;
        for (int t : allowedComponentTypes)
            allowed += (allowed.empty() ? "" : ", ") + std::string(componentTypeName(t));
        fail(name + " has componentType " + componentTypeName(acc.componentType) +
             ", expected one of: " + allowed);
    }
    const bool isInteger = acc.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT;
    if (requireNormalizedInts && isInteger && !acc.normalized)
        fail(name + " stores integers without \"normalized\": true; set it or use FLOAT");
    if (acc.count == 0) fail(name + " has count 0");
    const int components = componentCount(acc.type);
    const size_t compBytes = static_cast<size_t>(componentBytes(acc.componentType));
    const size_t elementBytes = compBytes * static_cast<size_t>(components);
    const bool normalized = acc.normalized;

    std::vector<double> values;
    if (acc.bufferView < 0) {
        if (!acc.sparse.isSparse)
            fail(name + " has neither a bufferView nor sparse data; give it a bufferView");
        if (acc.count > kMaxZeroAccessorCount)
            fail(name + " has no bufferView and count " + std::to_string(acc.count) +
                 "; mirage accepts at most " + std::to_string(kMaxZeroAccessorCount) +
                 " elements for such accessors");
        values.assign(acc.count * static_cast<size_t>(components), 0.0);
    } else {
        auto [data, size] = viewBytes(acc.bufferView, name + " field 'bufferView'");
        const size_t declaredStride =
            model_.bufferViews[static_cast<size_t>(acc.bufferView)].byteStride;
        const size_t stride = declaredStride ? declaredStride : elementBytes;
        if (declaredStride != 0 && declaredStride < elementBytes)
            fail("bufferView " + std::to_string(acc.bufferView) + " has byteStride " +
                 std::to_string(declaredStride) + ", smaller than one element of " + name + " (" +
                 std::to_string(elementBytes) + " bytes)");
        // Overflow-safe form of: byteOffset + stride * (count - 1) + elementBytes <= size.
        if (acc.byteOffset > size || elementBytes > size - acc.byteOffset ||
            (acc.count - 1) > (size - acc.byteOffset - elementBytes) / stride)
            fail(name + " reads " + std::to_string(acc.count) + " elements of " +
                 std::to_string(elementBytes) + " bytes (stride " + std::to_string(stride) +
                 ") from byteOffset " + std::to_string(acc.byteOffset) + " of bufferView " +
                 std::to_string(acc.bufferView) + ", which has only " + std::to_string(size) +
                 " bytes; fix count/byteOffset or the bufferView");
        values.resize(acc.count * static_cast<size_t>(components));
        for (size_t i = 0; i < acc.count; ++i) {
            const unsigned char* element = data + acc.byteOffset + i * stride;
            for (int c = 0; c < components; ++c)
                values[i * static_cast<size_t>(components) + static_cast<size_t>(c)] =
                    readComponent(element + static_cast<size_t>(c) * compBytes, acc.componentType,
                                  normalized);
        }
    }
    if (acc.sparse.isSparse) applySparse(acc, name, components, compBytes, values);
    for (size_t i = 0; i < values.size(); ++i)
        if (!std::isfinite(values[i]))
            fail(name + " element " + std::to_string(i / static_cast<size_t>(components)) +
                 " component " + std::to_string(i % static_cast<size_t>(components)) + " is " +
                 (std::isnan(values[i]) ? "NaN" : "infinite") + "; vertex data must be finite");
    return values;
}

void AccessorReader::applySparse(const tinygltf::Accessor& acc, const std::string& name,
                                 int components, size_t compBytes,
                                 std::vector<double>& values) const {
    const auto& sparse = acc.sparse;
    if (sparse.count <= 0 || static_cast<size_t>(sparse.count) > acc.count)
        fail(name + " sparse.count is " + std::to_string(sparse.count) + "; it must be in 1.." +
             std::to_string(acc.count));
    const size_t n = static_cast<size_t>(sparse.count);
    const int indexType = sparse.indices.componentType;
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(name + " sparse.indices.componentType is " + componentTypeName(indexType) +
             ", expected UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    const size_t indexBytes = static_cast<size_t>(componentBytes(indexType));
    auto [indexData, indexSize] =
        viewBytes(sparse.indices.bufferView, name + " sparse.indices.bufferView");
    auto [valueData, valueSize] =
        viewBytes(sparse.values.bufferView, name + " sparse.values.bufferView");
    const size_t elementBytes = compBytes * static_cast<size_t>(components);
    if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
        fail(name + " sparse byteOffset is negative");
    const size_t indexOffset = static_cast<size_t>(sparse.indices.byteOffset);
    const size_t valueOffset = static_cast<size_t>(sparse.values.byteOffset);
    if (indexOffset > indexSize || n > (indexSize - indexOffset) / indexBytes)
        fail(name + " sparse.indices need " + std::to_string(n * indexBytes) +
             " bytes from byteOffset " + std::to_string(indexOffset) + " but bufferView " +
             std::to_string(sparse.indices.bufferView) + " has " + std::to_string(indexSize));
    if (valueOffset > valueSize || n > (valueSize - valueOffset) / elementBytes)
        fail(name + " sparse.values need " + std::to_string(n * elementBytes) +
             " bytes from byteOffset " + std::to_string(valueOffset) + " but bufferView " +
             std::to_string(sparse.values.bufferView) + " has " + std::to_string(valueSize));
    for (size_t i = 0; i < n; ++i) {
        const double target =
            readComponent(indexData + indexOffset + i * indexBytes, indexType, false);
        if (target >= static_cast<double>(acc.count))
            fail(name + " sparse index " + std::to_string(i) + " is " +
                 std::to_string(static_cast<uint64_t>(target)) + ", outside the accessor's " +
                 std::to_string(acc.count) + " elements");
        const size_t t = static_cast<size_t>(target);
        for (int c = 0; c < components; ++c)
            values[t * static_cast<size_t>(components) + static_cast<size_t>(c)] = readComponent(
                valueData + valueOffset + i * elementBytes + static_cast<size_t>(c) * compBytes,
                acc.componentType, acc.normalized);
    }
}

}  // namespace mirage::gltf
