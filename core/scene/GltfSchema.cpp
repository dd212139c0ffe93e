#include "core/scene/GltfSchema.h"

#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/ContainedPath.h"
#include "core/Error.h"

namespace mirage::gltf {
namespace {

using nlohmann::json;

enum class Kind { Index, Integer, Number, Bool, String, Object, Uri };

// One property: its name, its type, and for arrays their element kind and length (0: any); for
// objects and arrays of objects the schema of the object.
struct Field;
using Schema = std::vector<Field>;
struct Field {
    const char* name;
    Kind kind;
    bool array = false;
    size_t length = 0;
    const Schema* object = nullptr;  // for Kind::Object (array or not)
    bool map = false;                // an object whose every value is of `kind` (attributes)
};

Field scalar(const char* name, Kind k) {
    return {name, k};
}
Field array(const char* name, Kind k, size_t length = 0) {
    return {name, k, true, length};
}
Field object(const char* name, const Schema* s) {
    return {name, Kind::Object, false, 0, s};
}
Field objects(const char* name, const Schema* s) {
    return {name, Kind::Object, true, 0, s};
}
Field indexMap(const char* name) {
    return {name, Kind::Index, false, 0, nullptr, true};
}

const Schema kTextureInfo = {scalar("index", Kind::Index), scalar("texCoord", Kind::Index),
                             scalar("scale", Kind::Number), scalar("strength", Kind::Number)};
const Schema kPbr = {
    array("baseColorFactor", Kind::Number, 4), object("baseColorTexture", &kTextureInfo),
    scalar("metallicFactor", Kind::Number), scalar("roughnessFactor", Kind::Number),
    object("metallicRoughnessTexture", &kTextureInfo)};
const Schema kMaterialExtensions = [] {
    static const Schema ior = {scalar("ior", Kind::Number)};
    static const Schema transmission = {scalar("transmissionFactor", Kind::Number),
                                        object("transmissionTexture", &kTextureInfo)};
    static const Schema volume = {scalar("thicknessFactor", Kind::Number),
                                  scalar("attenuationDistance", Kind::Number),
                                  array("attenuationColor", Kind::Number, 3)};
    static const Schema emissive = {scalar("emissiveStrength", Kind::Number)};
    static const Schema diffuse = {scalar("diffuseTransmissionFactor", Kind::Number),
                                   array("diffuseTransmissionColorFactor", Kind::Number, 3)};
    return Schema{object("KHR_materials_ior", &ior),
                  object("KHR_materials_transmission", &transmission),
                  object("KHR_materials_volume", &volume),
                  object("KHR_materials_emissive_strength", &emissive),
                  object("KHR_materials_diffuse_transmission", &diffuse)};
}();
const Schema kMaterial = {scalar("name", Kind::String),
                          object("pbrMetallicRoughness", &kPbr),
                          object("normalTexture", &kTextureInfo),
                          object("occlusionTexture", &kTextureInfo),
                          object("emissiveTexture", &kTextureInfo),
                          array("emissiveFactor", Kind::Number, 3),
                          scalar("alphaMode", Kind::String),
                          scalar("alphaCutoff", Kind::Number),
                          scalar("doubleSided", Kind::Bool),
                          object("extensions", &kMaterialExtensions)};
const Schema kNodeExtensions = [] {
    static const Schema light = {scalar("light", Kind::Index)};
    return Schema{object("KHR_lights_punctual", &light)};
}();
const Schema kNode = {scalar("name", Kind::String),          scalar("camera", Kind::Index),
                      array("children", Kind::Index),        scalar("skin", Kind::Index),
                      array("matrix", Kind::Number, 16),     scalar("mesh", Kind::Index),
                      array("rotation", Kind::Number, 4),    array("scale", Kind::Number, 3),
                      array("translation", Kind::Number, 3), array("weights", Kind::Number),
                      object("extensions", &kNodeExtensions)};
const Schema kPrimitive = {indexMap("attributes"), scalar("indices", Kind::Index),
                           scalar("material", Kind::Index), scalar("mode", Kind::Integer)};
const Schema kMesh = {scalar("name", Kind::String), objects("primitives", &kPrimitive),
                      array("weights", Kind::Number)};
const Schema kBuffer = {scalar("name", Kind::String), scalar("uri", Kind::Uri),
                        scalar("byteLength", Kind::Integer)};
const Schema kBufferView = {scalar("buffer", Kind::Index), scalar("byteOffset", Kind::Integer),
                            scalar("byteLength", Kind::Integer),
                            scalar("byteStride", Kind::Integer), scalar("target", Kind::Integer)};
const Schema kSparse = [] {
    static const Schema indices = {scalar("bufferView", Kind::Index),
                                   scalar("byteOffset", Kind::Integer),
                                   scalar("componentType", Kind::Integer)};
    static const Schema values = {scalar("bufferView", Kind::Index),
                                  scalar("byteOffset", Kind::Integer)};
    return Schema{scalar("count", Kind::Integer), object("indices", &indices),
                  object("values", &values)};
}();
const Schema kAccessor = {scalar("bufferView", Kind::Index),
                          scalar("byteOffset", Kind::Integer),
                          scalar("componentType", Kind::Integer),
                          scalar("normalized", Kind::Bool),
                          scalar("count", Kind::Integer),
                          scalar("type", Kind::String),
                          array("max", Kind::Number),
                          array("min", Kind::Number),
                          object("sparse", &kSparse)};
const Schema kImage = {scalar("name", Kind::String), scalar("uri", Kind::Uri),
                       scalar("mimeType", Kind::String), scalar("bufferView", Kind::Index)};
const Schema kTexture = {scalar("sampler", Kind::Index), scalar("source", Kind::Index)};
const Schema kSampler = {scalar("magFilter", Kind::Integer), scalar("minFilter", Kind::Integer),
                         scalar("wrapS", Kind::Integer), scalar("wrapT", Kind::Integer)};
const Schema kCamera = [] {
    static const Schema perspective = {scalar("aspectRatio", Kind::Number),
                                       scalar("yfov", Kind::Number), scalar("zfar", Kind::Number),
                                       scalar("znear", Kind::Number)};
    static const Schema orthographic = {scalar("xmag", Kind::Number), scalar("ymag", Kind::Number),
                                        scalar("zfar", Kind::Number),
                                        scalar("znear", Kind::Number)};
    return Schema{scalar("type", Kind::String), object("perspective", &perspective),
                  object("orthographic", &orthographic)};
}();
const Schema kScene = {scalar("name", Kind::String), array("nodes", Kind::Index)};
const Schema kSkin = {scalar("inverseBindMatrices", Kind::Index), scalar("skeleton", Kind::Index),
                      array("joints", Kind::Index)};
const Schema kAnimation = [] {
    static const Schema target = {scalar("node", Kind::Index), scalar("path", Kind::String)};
    static const Schema channel = {scalar("sampler", Kind::Index), object("target", &target)};
    static const Schema sampler = {scalar("input", Kind::Index),
                                   scalar("interpolation", Kind::String),
                                   scalar("output", Kind::Index)};
    return Schema{objects("channels", &channel), objects("samplers", &sampler)};
}();
const Schema kRootExtensions = [] {
    static const Schema spot = {scalar("innerConeAngle", Kind::Number),
                                scalar("outerConeAngle", Kind::Number)};
    static const Schema light = {scalar("name", Kind::String),      array("color", Kind::Number, 3),
                                 scalar("intensity", Kind::Number), scalar("type", Kind::String),
                                 scalar("range", Kind::Number),     object("spot", &spot)};
    static const Schema lights = {objects("lights", &light)};
    return Schema{object("KHR_lights_punctual", &lights)};
}();
const Schema kAsset = {scalar("version", Kind::String), scalar("minVersion", Kind::String),
                       scalar("generator", Kind::String), scalar("copyright", Kind::String)};
const Schema kRoot = {object("asset", &kAsset),
                      scalar("scene", Kind::Index),
                      objects("scenes", &kScene),
                      objects("nodes", &kNode),
                      objects("meshes", &kMesh),
                      objects("materials", &kMaterial),
                      objects("buffers", &kBuffer),
                      objects("bufferViews", &kBufferView),
                      objects("accessors", &kAccessor),
                      objects("images", &kImage),
                      objects("textures", &kTexture),
                      objects("samplers", &kSampler),
                      objects("cameras", &kCamera),
                      objects("skins", &kSkin),
                      objects("animations", &kAnimation),
                      array("extensionsUsed", Kind::String),
                      array("extensionsRequired", Kind::String),
                      object("extensions", &kRootExtensions)};

const char* kindName(Kind k) {
    switch (k) {
        case Kind::Index:
            return "an index (an integer)";
        case Kind::Integer:
            return "an integer";
        case Kind::Number:
            return "a finite number";
        case Kind::Bool:
            return "true or false";
        case Kind::String:
        case Kind::Uri:
            return "a string";
        case Kind::Object:
            return "an object";
    }
    return "?";
}

std::string shown(const json& v) {
    std::string s = v.dump();
    if (s.size() > 40) s = s.substr(0, 37) + "...";
    return std::string(v.type_name()) + " " + s;
}

class SchemaCheck {
public:
    explicit SchemaCheck(std::string file) : file_(std::move(file)) {}

    void object(const json& j, const Schema& schema, const std::string& path) const {
        if (!j.is_object()) fail(path, "expected an object, got " + shown(j));
        for (const Field& f : schema) {
            const auto it = j.find(f.name);
            if (it == j.end()) continue;
            const std::string at = path.empty() ? f.name : path + "." + f.name;
            if (f.map) {
                if (!it->is_object()) fail(at, "expected an object, got " + shown(*it));
                for (const auto& [key, v] : it->items()) value(v, f, at + "." + key);
            } else if (f.array) {
                elements(*it, f, at);
            } else {
                value(*it, f, at);
            }
        }
    }

private:
    [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
        throw FileError(file_, path + ": " + problem);
    }

    void elements(const json& j, const Field& f, const std::string& at) const {
        if (!j.is_array()) fail(at, "expected an array, got " + shown(j));
        if (f.length > 0 && j.size() != f.length)
            fail(at, "expected " + std::to_string(f.length) + " elements, got " +
                         std::to_string(j.size()));
        for (size_t i = 0; i < j.size(); ++i) value(j[i], f, at + "[" + std::to_string(i) + "]");
    }

    void value(const json& v, const Field& f, const std::string& at) const {
        bool ok = false;
        switch (f.kind) {
            case Kind::Index:  // the range is the reader's to check (it names both ends)
            case Kind::Integer:
                ok = isInteger(v);
                break;
            case Kind::Number:
                ok = v.is_number() && std::isfinite(v.get<double>());
                break;
            case Kind::Bool:
                ok = v.is_boolean();
                break;
            case Kind::String:
                ok = v.is_string();
                break;
            case Kind::Uri:
                ok = v.is_string();
                if (ok) uri(v.get<std::string>(), at);
                break;
            case Kind::Object:
                object(v, *f.object, at);
                ok = true;
                break;
        }
        if (!ok) fail(at, std::string("expected ") + kindName(f.kind) + ", got " + shown(v));
    }

    // glTF integers may be written as 3.0 by some exporters; 3.5 or "3" are wrong.
    static bool isInteger(const json& v) {
        if (v.is_number_integer()) return true;
        return v.is_number_float() && std::isfinite(v.get<double>()) &&
               std::floor(v.get<double>()) == v.get<double>() && std::abs(v.get<double>()) < 9e15;
    }

    // An external URI (after %XX decoding, as tinygltf reads it) must stay in the glTF's folder.
    void uri(const std::string& u, const std::string& at) const {
        if (u.compare(0, 5, "data:") == 0) return;
        const std::string problem = containedReferenceProblem(percentDecoded(u));
        if (!problem.empty())
            fail(at, "the URI '" + u + "' " + problem +
                         "; external files must lie inside the glTF file's folder (or embed the "
                         "data as a data: URI)");
    }

    std::string file_;
};

}  // namespace

void checkGltfSchema(const char* text, size_t size, const std::string& file) {
    const json j = json::parse(text, text + size, nullptr, false);
    if (j.is_discarded()) return;  // tinygltf reports the syntax error
    if (!j.is_object()) throw FileError(file, "expected a JSON object at the top of the glTF");
    SchemaCheck(file).object(j, kRoot, "");
}

}  // namespace mirage::gltf
