#pragma once
// glTF loading, part 4 of 5: buffer views and accessors, read as doubles after every bound,
// type and value has been checked (SceneLoader.cpp). tinygltf leaves all of that unchecked.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <tiny_gltf.h>

namespace mirage::gltf {

const char* typeName(int type);                    // "VEC3" ...
const char* componentTypeName(int componentType);  // "FLOAT (5126)" ...
int componentCount(int type);                      // 3 for VEC3 ...; 0 if unknown
int componentBytes(int componentType);             // 4 for FLOAT ...; 0 if unknown
// One component at `p` as a double; normalized integers map to [0,1] or [-1,1] (glTF 3.11).
double readComponent(const unsigned char* p, int componentType, bool normalized);

// Reads the data of a parsed model; every failure is a mirage::FileError naming `file`, the
// object and the field.
class AccessorReader {
public:
    AccessorReader(const tinygltf::Model& model, std::string file);

    [[noreturn]] void fail(const std::string& problem) const;
    // Throws unless 0 <= index < size; `what` names the referring object and field, `target` the
    // kind of object referred to ("accessor", "node" ...).
    void checkIndex(int index, size_t size, const std::string& what, const char* target) const;
    // Bytes of bufferView `viewIndex` after checking it lies inside its buffer.
    std::pair<const unsigned char*, size_t> viewBytes(int viewIndex, const std::string& what) const;
    // Reads accessor `index` as doubles, count x components, after checking its type, component
    // type, bounds and (with sparse substitution applied) that every value is finite.
    std::vector<double> readAccessor(int index, const std::string& what, int expectedType,
                                     const std::vector<int>& allowedComponentTypes,
                                     bool requireNormalizedInts) const;

private:
    void applySparse(const tinygltf::Accessor& acc, const std::string& name, int components,
                     size_t compBytes, std::vector<double>& values) const;

    const tinygltf::Model& model_;
    std::string file_;
};

}  // namespace mirage::gltf
