#include "core/scene/GltfReader.h"

#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <tiny_gltf.h>
#include <glm/gtc/quaternion.hpp>

#include "core/ContainedPath.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/scene/GltfAccessors.h"
#include "core/scene/GltfFiles.h"
#include "core/scene/GltfImages.h"
#include "core/scene/GltfSchema.h"
#include "core/scene/GltfScreening.h"

namespace mirage::gltf {
namespace {

namespace fs = std::filesystem;

bool allFinite(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

bool allFinite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

std::string quote(const std::string& s) {
    return "'" + s + "'";
}

class GltfReader {
public:
    GltfReader(std::string file, fs::path baseDir)
        : file_(std::move(file)), baseDir_(std::move(baseDir)), base_(baseDir_.string()) {}

    Scene read(const std::string& bytes) {
        parse(bytes);
        checkRequiredExtensions();
        scene_.textures.resize(model_.textures.size());
        decodeImages();
        readTextures();
        readMaterials();
        readMeshes();
        readLights();
        readCameras();
        readNodes();
        readEnvironment();
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(const std::string& problem) const { throw FileError(file_, problem); }

    // A double from the file as a float; values beyond float's range (converting them would be
    // undefined behaviour) and non-finite values are errors naming `what`.
    float toFloat(double v, const std::string& what) const {
        if (!std::isfinite(v) ||
            std::abs(v) > static_cast<double>(std::numeric_limits<float>::max()))
            fail(what + " is " + std::to_string(v) + ", outside the range of a float");
        return static_cast<float>(v);
    }

    void warn(const std::string& message) {
        spdlog::warn("{}: {}", file_, message);
        scene_.warnings.push_back(message);
    }

    void parse(const std::string& bytes) {
        if (bytes.empty()) fail("the file is empty; expected glTF JSON or a .glb binary");
        if (bytes.size() > gltf::kMaxFileBytes)
            fail("the file is larger than 2 GiB; mirage cannot load it");
        const bool binary = gltf::isGlb(bytes);
        const gltf::JsonSpan json = gltf::jsonText(bytes);
        if (gltf::jsonNestingDepth(bytes.data() + json.start, json.size) > gltf::kMaxJsonDepth)
            fail("JSON nesting deeper than " + std::to_string(gltf::kMaxJsonDepth) +
                 " levels; this is not a glTF file mirage can load (check extras/extensions)");
        gltf::checkGltfSchema(bytes.data() + json.start, json.size, file_);

        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(&gltf::loadImageCallback, nullptr);
        loader.SetFsCallbacks(gltf::fileCallbacks(&base_));
        std::string err, warnings;
        bool ok = false;
        // tinygltf reports most problems through `err`, but a few malformed inputs surface as
        // standard exceptions (e.g. std::out_of_range from an empty data URI): both become a
        // FileError. Exceptions from mirage's own code below are deliberately not caught here.
        try {
            if (binary)
                ok = loader.LoadBinaryFromMemory(
                    &model_, &err, &warnings, reinterpret_cast<const unsigned char*>(bytes.data()),
                    static_cast<unsigned int>(bytes.size()), base_);
            else
                ok = loader.LoadASCIIFromString(&model_, &err, &warnings, bytes.data(),
                                                static_cast<unsigned int>(bytes.size()), base_);
        } catch (const std::bad_alloc&) {
            fail("out of memory while parsing the glTF file");
        } catch (const std::exception& e) {
            fail(std::string("the glTF parser rejected the file: ") + e.what());
        }
        std::istringstream warnLines(warnings);
        for (std::string line; std::getline(warnLines, line);)
            if (!line.empty()) warn("glTF parser: " + line);
        if (!ok) {
            while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
            fail(std::string("not a valid glTF ") + (binary ? "binary (.glb)" : "file") + ": " +
                 (err.empty() ? "parse failed" : err) +
                 "; check the file against the glTF 2.0 specification (e.g. with the Khronos "
                 "glTF-Validator)");
        }
    }

    void checkRequiredExtensions() {
        for (const std::string& ext : model_.extensionsRequired)
            if (!gltf::supportedExtensions().count(ext))
                fail("extensionsRequired lists " + quote(ext) +
                     ", which mirage does not support (supported: " +
                     gltf::supportedExtensionList() + "); export the scene without it");
        for (const std::string& ext : model_.extensionsUsed)
            if (!gltf::supportedExtensions().count(ext))
                warn("extension " + quote(ext) + " is used but not supported; it is ignored");
    }

    // ---- images and textures ----

    void decodeImages() {
        images_.resize(model_.images.size());
        for (size_t i = 0; i < model_.images.size(); ++i) {
            tinygltf::Image& image = model_.images[i];
            const std::string name =
                "image " + std::to_string(i) +
                (image.name.empty() ? std::string() : " (" + quote(image.name) + ")");
            Texture& decoded = images_[i];
            decoded.name = image.name;
            if (image.bufferView >= 0) {
                auto [data, size] = data_.viewBytes(image.bufferView, name + " field 'bufferView'");
                std::string why;
                if (!gltf::decodeRgba8(data, size, decoded.width, decoded.height, decoded.pixels,
                                       why))
                    fail(name + " in bufferView " + std::to_string(image.bufferView) +
                         " cannot be used: " + why);
            } else if (!image.image.empty()) {
                decoded.width = image.width;
                decoded.height = image.height;
                decoded.pixels = std::move(image.image);
            } else {
                fail(name + " could not be read from uri " + quote(image.uri) + " (looked in " +
                     baseDir_.string() +
                     ", the glTF file's folder, only); put the file there or embed the image");
            }
            MR_CHECK(
                decoded.pixels.size() == static_cast<size_t>(decoded.width) * decoded.height * 4,
                "decoded image size mismatch");
        }
    }

    static Texture::Wrap wrapMode(int mode) {
        if (mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return Texture::Wrap::ClampToEdge;
        if (mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return Texture::Wrap::MirroredRepeat;
        return Texture::Wrap::Repeat;
    }

    void readTextures() {
        for (size_t i = 0; i < model_.textures.size(); ++i) {
            const tinygltf::Texture& src = model_.textures[i];
            const std::string name = "texture " + std::to_string(i);
            if (src.source < 0)
                fail(name +
                     " has no 'source' image (image sources from extensions such as "
                     "KHR_texture_basisu are not supported); give it a PNG or JPEG source");
            data_.checkIndex(src.source, images_.size(), name + " field 'source'", "image");
            Texture& dst = scene_.textures[i];
            dst = images_[static_cast<size_t>(src.source)];
            if (!src.name.empty()) dst.name = src.name;
            if (src.sampler >= 0) {
                data_.checkIndex(src.sampler, model_.samplers.size(), name + " field 'sampler'",
                                 "sampler");
                const tinygltf::Sampler& s = model_.samplers[static_cast<size_t>(src.sampler)];
                dst.wrapS = wrapMode(s.wrapS);
                dst.wrapT = wrapMode(s.wrapT);
                dst.magFilter = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST
                                    ? Texture::Filter::Nearest
                                    : Texture::Filter::Linear;
                dst.minFilter = (s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
                                 s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
                                 s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR)
                                    ? Texture::Filter::Nearest
                                    : Texture::Filter::Linear;
                dst.mipmaps = !(s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
                                s.minFilter == TINYGLTF_TEXTURE_FILTER_LINEAR);
            }
        }
        images_.clear();
    }

    // ---- materials ----

    double number(const tinygltf::Value& object, const char* key, double fallback,
                  const std::string& what, double lo, double hi) const {
        if (!object.IsObject() || !object.Has(key)) return fallback;
        const tinygltf::Value& v = object.Get(key);
        if (!v.IsNumber()) fail(what + " field '" + key + "' must be a number");
        double x = v.GetNumberAsDouble();
        // Every such field ends up in a float, so the float range bounds it too.
        const double floatMax = static_cast<double>(std::numeric_limits<float>::max());
        if (!std::isfinite(x) || x < lo || x > hi || std::abs(x) > floatMax)
            fail(what + " field '" + key + "' is " + std::to_string(x) + "; it must be in [" +
                 std::to_string(lo) + ", " +
                 (std::isinf(hi) ? std::string("inf") : std::to_string(hi)) + "]");
        return x;
    }

    TextureRef textureRef(int index, int texCoord, const std::string& what, bool srgb,
                          const tinygltf::ExtensionMap* extensions = nullptr) {
        if (index < 0) return {};
        data_.checkIndex(index, scene_.textures.size(), what + " field 'index'", "texture");
        if (texCoord != 0 && texCoord != 1)
            fail(what + " uses TEXCOORD_" + std::to_string(texCoord) +
                 "; mirage supports only TEXCOORD_0 and TEXCOORD_1");
        if (extensions && extensions->count("KHR_texture_transform"))
            warn(what +
                 " uses KHR_texture_transform, which is not supported; the transform is ignored");
        Texture& texture = scene_.textures[static_cast<size_t>(index)];
        auto [it, inserted] = textureUse_.emplace(index, srgb);
        if (!inserted && it->second != srgb) {
            warn("texture " + std::to_string(index) +
                 " is used both as colour (sRGB) and as data (linear); treated as sRGB");
            it->second = true;
        }
        texture.srgb = it->second;
        return {index, texCoord};
    }

    TextureRef extensionTextureRef(const tinygltf::Value& ext, const char* key,
                                   const std::string& what, bool srgb) {
        if (!ext.Has(key)) return {};
        const tinygltf::Value& info = ext.Get(key);
        const std::string field = what + " " + key;
        if (!info.IsObject() || !info.Has("index") || !info.Get("index").IsInt())
            fail(field + " must be an object with an integer 'index'");
        int texCoord = 0;
        if (info.Has("texCoord")) {
            if (!info.Get("texCoord").IsInt()) fail(field + " field 'texCoord' must be an integer");
            texCoord = info.Get("texCoord").GetNumberAsInt();
        }
        return textureRef(info.Get("index").GetNumberAsInt(), texCoord, field, srgb);
    }

    const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name,
                                     const std::string& what) const {
        auto it = map.find(name);
        if (it == map.end()) return nullptr;
        if (!it->second.IsObject()) fail(what + " extension " + name + " must be a JSON object");
        return &it->second;
    }

    void readMaterials() {
        constexpr double kInf = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < model_.materials.size(); ++i) {
            const tinygltf::Material& src = model_.materials[i];
            const std::string name = "material " + std::to_string(i);
            Material m;
            m.name = src.name;
            const auto& pbr = src.pbrMetallicRoughness;
            if (!pbr.baseColorFactor.empty()) {
                if (pbr.baseColorFactor.size() != 4 || !allFinite(pbr.baseColorFactor))
                    fail(name + " pbrMetallicRoughness.baseColorFactor must be 4 finite numbers");
                for (int c = 0; c < 4; ++c) {
                    if (pbr.baseColorFactor[static_cast<size_t>(c)] < 0 ||
                        pbr.baseColorFactor[static_cast<size_t>(c)] > 1)
                        fail(name +
                             " pbrMetallicRoughness.baseColorFactor components must be in [0, 1]");
                    m.baseColor[c] =
                        static_cast<float>(pbr.baseColorFactor[static_cast<size_t>(c)]);
                }
            }
            auto unit = [&](double v, const char* field) {
                if (!std::isfinite(v) || v < 0 || v > 1)
                    fail(name + " " + field + " is " + std::to_string(v) +
                         "; it must be in [0, 1]");
                return static_cast<float>(v);
            };
            m.metallic = unit(pbr.metallicFactor, "pbrMetallicRoughness.metallicFactor");
            m.roughness = unit(pbr.roughnessFactor, "pbrMetallicRoughness.roughnessFactor");
            m.baseColorTexture =
                textureRef(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                           name + " baseColorTexture", true, &pbr.baseColorTexture.extensions);
            m.metallicRoughnessTexture = textureRef(pbr.metallicRoughnessTexture.index,
                                                    pbr.metallicRoughnessTexture.texCoord,
                                                    name + " metallicRoughnessTexture", false,
                                                    &pbr.metallicRoughnessTexture.extensions);
            m.normalTexture =
                textureRef(src.normalTexture.index, src.normalTexture.texCoord,
                           name + " normalTexture", false, &src.normalTexture.extensions);
            if (!std::isfinite(src.normalTexture.scale))
                fail(name + " normalTexture.scale must be finite");
            m.normalScale = toFloat(src.normalTexture.scale, name + " normalTexture.scale");
            m.emissiveTexture =
                textureRef(src.emissiveTexture.index, src.emissiveTexture.texCoord,
                           name + " emissiveTexture", true, &src.emissiveTexture.extensions);
            if (src.occlusionTexture.index >= 0)
                data_.checkIndex(src.occlusionTexture.index, scene_.textures.size(),
                                 name + " occlusionTexture field 'index'", "texture");
            float emissiveStrength = 1.0f;
            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_materials_emissive_strength", name))
                emissiveStrength =
                    static_cast<float>(number(*ext, "emissiveStrength", 1.0,
                                              name + " KHR_materials_emissive_strength", 0, kInf));
            if (!src.emissiveFactor.empty()) {
                if (src.emissiveFactor.size() != 3 || !allFinite(src.emissiveFactor))
                    fail(name + " emissiveFactor must be 3 finite numbers");
                for (int c = 0; c < 3; ++c)
                    m.emissive[c] =
                        unit(src.emissiveFactor[static_cast<size_t>(c)], "emissiveFactor") *
                        emissiveStrength;
            }
            m.doubleSided = src.doubleSided;
            if (src.alphaMode == "OPAQUE" || src.alphaMode.empty())
                m.alphaMode = Material::AlphaMode::Opaque;
            else if (src.alphaMode == "MASK")
                m.alphaMode = Material::AlphaMode::Mask;
            else if (src.alphaMode == "BLEND")
                m.alphaMode = Material::AlphaMode::Blend;
            else
                fail(name + " alphaMode is " + quote(src.alphaMode) +
                     "; expected OPAQUE, MASK or BLEND");
            if (!std::isfinite(src.alphaCutoff) || src.alphaCutoff < 0)
                fail(name + " alphaCutoff must be a finite number >= 0");
            m.alphaCutoff = toFloat(src.alphaCutoff, name + " alphaCutoff");

            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_materials_transmission", name)) {
                const std::string what = name + " KHR_materials_transmission";
                m.transmission =
                    static_cast<float>(number(*ext, "transmissionFactor", 0.0, what, 0, 1));
                m.transmissionTexture =
                    extensionTextureRef(*ext, "transmissionTexture", what, false);
            }
            if (const tinygltf::Value* ext = extension(src.extensions, "KHR_materials_ior", name)) {
                m.ior = static_cast<float>(
                    number(*ext, "ior", 1.5, name + " KHR_materials_ior", 1.0, 10.0));
            }
            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_materials_volume", name)) {
                const std::string what = name + " KHR_materials_volume";
                m.thickness =
                    static_cast<float>(number(*ext, "thicknessFactor", 0.0, what, 0, kInf));
                m.thicknessTexture = extensionTextureRef(*ext, "thicknessTexture", what, false);
                if (ext->Has("attenuationDistance")) {
                    double d = number(*ext, "attenuationDistance", kInf, what, 0, kInf);
                    if (d <= 0)
                        fail(what +
                             " field 'attenuationDistance' must be > 0 (omit it for no "
                             "attenuation)");
                    m.attenuationDistance = static_cast<float>(d);
                }
                if (ext->Has("attenuationColor")) {
                    const tinygltf::Value& c = ext->Get("attenuationColor");
                    if (!c.IsArray() || c.ArrayLen() != 3)
                        fail(what + " field 'attenuationColor' must be an array of 3 numbers");
                    for (int k = 0; k < 3; ++k) {
                        const tinygltf::Value& v = c.Get(k);
                        if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()) ||
                            v.GetNumberAsDouble() < 0 || v.GetNumberAsDouble() > 1)
                            fail(what + " attenuationColor[" + std::to_string(k) +
                                 "] must be a number in [0, 1]");
                        m.attenuationColor[k] = static_cast<float>(v.GetNumberAsDouble());
                    }
                }
            }
            if (const tinygltf::Value* mirage = mirageExtras(src.extras, name)) {
                if (mirage->Has("roughness_variation"))
                    warn(name +
                         " extras.mirage.roughness_variation is not read: vary the "
                         "roughness across the surface with a metallicRoughnessTexture");
            }
            readScattering(src, name, m);
            scene_.materials.push_back(std::move(m));
        }
    }

    // A 3-vector of numbers in [lo, hi] at ext[key].
    glm::vec3 vec3Field(const tinygltf::Value& ext, const char* key, const std::string& what,
                        double lo, double hi) const {
        const tinygltf::Value& c = ext.Get(key);
        if (!c.IsArray() || c.ArrayLen() != 3)
            fail(what + " field '" + key + "' must be an array of 3 numbers");
        glm::vec3 out;
        for (int k = 0; k < 3; ++k) {
            const tinygltf::Value& v = c.Get(k);
            if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()) ||
                v.GetNumberAsDouble() < lo || v.GetNumberAsDouble() > hi)
                fail(what + " " + key + "[" + std::to_string(k) + "] must be a number in [" +
                     std::to_string(lo) + ", " + std::to_string(hi) + "]");
            out[k] = static_cast<float>(v.GetNumberAsDouble());
        }
        return out;
    }

    // Translucent interiors (docs/scene.md, "Translucent materials"): MIRAGE_materials_scattering
    // (extinction, albedo, an optional density grid file), or the standard
    // KHR_materials_diffuse_transmission together with KHR_materials_volume's attenuation for a
    // homogeneous medium. KHR_materials_volume fills what the mirage extension leaves out:
    // extinction = 1 / attenuationDistance, albedo = attenuationColor.
    void readScattering(const tinygltf::Material& src, const std::string& name, Material& m) {
        const tinygltf::Value* volume = extension(src.extensions, "KHR_materials_volume", name);
        const tinygltf::Value* diffuse =
            extension(src.extensions, "KHR_materials_diffuse_transmission", name);
        const tinygltf::Value* ext = extension(src.extensions, "MIRAGE_materials_scattering", name);
        double diffuseFactor = 0.0;
        if (diffuse)
            diffuseFactor = number(*diffuse, "diffuseTransmissionFactor", 0.0,
                                   name + " KHR_materials_diffuse_transmission", 0, 1);
        if (!ext && diffuseFactor <= 0) return;
        const std::string what =
            name + (ext ? " MIRAGE_materials_scattering" : " KHR_materials_diffuse_transmission");
        if (volume && volume->Has("thicknessFactor") && m.thickness <= 0)
            fail(what +
                 ": KHR_materials_volume thicknessFactor is 0, which glTF defines as "
                 "thin-walled (no inside); a translucent material needs a closed mesh "
                 "with thicknessFactor > 0");
        Material::Scattering& sc = m.scattering;
        sc.present = true;
        const bool volumeAttenuation = std::isfinite(m.attenuationDistance);
        if (ext && ext->Has("extinction")) {
            sc.extinction = static_cast<float>(number(*ext, "extinction", 0.0, what, 0, 1e9));
        } else if (volumeAttenuation) {
            sc.extinction = 1.0f / m.attenuationDistance;
        } else {
            fail(what +
                 " has no extinction: give 'extinction' (1/m at density 1) or "
                 "KHR_materials_volume attenuationDistance (extinction = 1 / distance)");
        }
        if (ext && ext->Has("albedo"))
            sc.albedo = vec3Field(*ext, "albedo", what, 0, 1);
        else if (volume && volume->Has("attenuationColor"))
            sc.albedo = m.attenuationColor;
        if (!ext || !ext->Has("density")) return;
        const tinygltf::Value& d = ext->Get("density");
        const std::string dwhat = what + " density";
        if (!d.IsObject()) fail(dwhat + " must be an object with 'uri', 'boundsMin', 'boundsMax'");
        if (!d.Has("uri") || !d.Get("uri").IsString() || d.Get("uri").Get<std::string>().empty())
            fail(dwhat + " needs a string 'uri': the .nrrd or .raw file beside the glTF");
        if (!d.Has("boundsMin") || !d.Has("boundsMax"))
            fail(dwhat + " needs 'boundsMin' and 'boundsMax' (mesh-local box the grid fills)");
        const std::string uri = d.Get("uri").Get<std::string>();
        glm::vec3 lo = vec3Field(d, "boundsMin", dwhat, -1e9, 1e9);
        glm::vec3 hi = vec3Field(d, "boundsMax", dwhat, -1e9, 1e9);
        for (int k = 0; k < 3; ++k)
            if (!(hi[k] > lo[k]))
                fail(dwhat + " boundsMax[" + std::to_string(k) + "] must be > boundsMin[" +
                     std::to_string(k) + "]; swap or fix the bounds");
        const std::string bytes = readSideFile(uri, dwhat);
        const std::string where = dwhat + " file " + quote(uri);
        DensityGrid grid;
        try {
            const bool nrrd = uri.size() >= 5 && uri.compare(uri.size() - 5, 5, ".nrrd") == 0;
            if (nrrd) {
                if (d.Has("dimensions") || d.Has("type"))
                    fail(where + ":" +
                         " 'dimensions'/'type' are for .raw files; an NRRD header "
                         "states them (remove the fields)");
                grid = parseNrrdDensity(bytes);
            } else {
                if (!d.Has("dimensions") || !d.Get("dimensions").IsArray() ||
                    d.Get("dimensions").ArrayLen() != 3)
                    fail(where + ": a raw file needs 'dimensions': [nx, ny, nz] (or use .nrrd)");
                int n[3];
                for (int k = 0; k < 3; ++k) {
                    const tinygltf::Value& v = d.Get("dimensions").Get(k);
                    if (!v.IsInt())
                        fail(dwhat + " dimensions[" + std::to_string(k) + "] must be an integer");
                    n[k] = v.GetNumberAsInt();
                }
                std::string type = "float32";
                if (d.Has("type")) {
                    if (!d.Get("type").IsString()) fail(dwhat + " field 'type' must be a string");
                    type = d.Get("type").Get<std::string>();
                }
                grid = parseRawDensity(bytes, n[0], n[1], n[2], densitySampleType(type));
            }
        } catch (const FileError&) {
            throw;
        } catch (const Error& e) {
            fail(where + ": " + e.what());
        }
        grid.boundsMin = lo;
        grid.boundsMax = hi;
        sc.density = std::make_shared<const DensityGrid>(std::move(grid));
        sc.densityUri = uri;
    }

    // A file beside the glTF (resolved against its folder only), at most 1 GiB.
    std::string readSideFile(const std::string& uri, const std::string& what) const {
        if (baseDir_.empty())
            fail(what + " refers to file " + quote(uri) +
                 ", but the scene was loaded from memory without a folder");
        const fs::path path = resolveContained(baseDir_, uri, file_, what + " file");
        std::error_code ec;
        if (!fs::is_regular_file(path, ec))
            fail(what + " file " + quote(uri) + " was not found (looked in " + baseDir_.string() +
                 ", the glTF file's folder); put it there or fix the uri");
        const auto size = fs::file_size(path, ec);
        if (ec || size > (uintmax_t(1) << 30))
            fail(what + " file " + quote(uri) + " is unreadable or larger than 1 GiB");
        std::ifstream in(path, std::ios::binary);
        std::string bytes(size_t(size), '\0');
        if (!in.read(bytes.data(), std::streamsize(size)))
            fail(what + " file " + quote(uri) + " could not be read");
        return bytes;
    }

    // extras.mirage of an object, or null; throws if present but not an object.
    const tinygltf::Value* mirageExtras(const tinygltf::Value& extras,
                                        const std::string& what) const {
        if (!extras.IsObject() || !extras.Has("mirage")) return nullptr;
        const tinygltf::Value& m = extras.Get("mirage");
        if (!m.IsObject()) fail(what + " extras.mirage must be a JSON object");
        return &m;
    }

    // ---- meshes ----

    void readMeshes() {
        for (size_t i = 0; i < model_.meshes.size(); ++i) {
            const tinygltf::Mesh& src = model_.meshes[i];
            Mesh mesh;
            mesh.name = src.name;
            for (size_t p = 0; p < src.primitives.size(); ++p) {
                const std::string what =
                    "mesh " + std::to_string(i) + " primitive " + std::to_string(p);
                std::optional<Primitive> prim = readPrimitive(src.primitives[p], what);
                if (prim) mesh.primitives.push_back(std::move(*prim));
            }
            scene_.meshes.push_back(std::move(mesh));
        }
    }

    template <int N>
    std::vector<glm::vec<N, float>> toVectors(const std::vector<double>& flat) const {
        std::vector<glm::vec<N, float>> out(flat.size() / N);
        for (size_t i = 0; i < out.size(); ++i)
            for (int c = 0; c < N; ++c)
                out[i][c] = static_cast<float>(flat[i * N + static_cast<size_t>(c)]);
        return out;
    }

    std::optional<Primitive> readPrimitive(const tinygltf::Primitive& src,
                                           const std::string& what) {
        const int mode = src.mode < 0 ? TINYGLTF_MODE_TRIANGLES : src.mode;
        if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE ||
            mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP) {
            warn(what + " has mode " + std::to_string(mode) +
                 " (points or lines); mirage renders triangles only, skipped");
            return std::nullopt;
        }
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN)
            fail(what + " has mode " + std::to_string(mode) + "; glTF modes are 0..6");
        if (!src.targets.empty())
            warn(what + " has morph targets; they are ignored (base shape used)");

        Primitive prim;
        if (src.material >= 0 || src.material < -1)
            data_.checkIndex(src.material, model_.materials.size(), what + " field 'material'",
                             "material");
        prim.material = src.material;

        auto attribute = [&](const char* key) -> int {
            auto it = src.attributes.find(key);
            return it == src.attributes.end() ? -2 : it->second;
        };
        const int position = attribute("POSITION");
        if (position == -2) fail(what + " has no POSITION attribute");
        const std::vector<int> floatOnly = {TINYGLTF_COMPONENT_TYPE_FLOAT};
        prim.positions = toVectors<3>(
            data_.readAccessor(position, what + " POSITION", TINYGLTF_TYPE_VEC3, floatOnly, false));
        const size_t vertexCount = prim.positions.size();
        auto checkCount = [&](size_t count, const char* key) {
            if (count != vertexCount)
                fail(what + " attribute " + key + " has " + std::to_string(count) +
                     " elements but POSITION has " + std::to_string(vertexCount) +
                     "; all attributes of a primitive need the same count");
        };
        if (int a = attribute("NORMAL"); a != -2) {
            prim.normals = toVectors<3>(
                data_.readAccessor(a, what + " NORMAL", TINYGLTF_TYPE_VEC3, floatOnly, false));
            checkCount(prim.normals.size(), "NORMAL");
        }
        if (int a = attribute("TANGENT"); a != -2) {
            prim.tangents = toVectors<4>(
                data_.readAccessor(a, what + " TANGENT", TINYGLTF_TYPE_VEC4, floatOnly, false));
            checkCount(prim.tangents.size(), "TANGENT");
        }
        const std::vector<int> uvTypes = {TINYGLTF_COMPONENT_TYPE_FLOAT,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};
        if (int a = attribute("TEXCOORD_0"); a != -2) {
            prim.uv0 = toVectors<2>(
                data_.readAccessor(a, what + " TEXCOORD_0", TINYGLTF_TYPE_VEC2, uvTypes, true));
            checkCount(prim.uv0.size(), "TEXCOORD_0");
        }
        if (int a = attribute("TEXCOORD_1"); a != -2) {
            prim.uv1 = toVectors<2>(
                data_.readAccessor(a, what + " TEXCOORD_1", TINYGLTF_TYPE_VEC2, uvTypes, true));
            checkCount(prim.uv1.size(), "TEXCOORD_1");
        }

        // Indices: any unsigned integer type, or none (then 0..n-1).
        std::vector<uint32_t> raw;
        if (src.indices >= 0 || src.indices < -1) {
            const std::vector<double> idx = data_.readAccessor(
                src.indices, what + " indices", TINYGLTF_TYPE_SCALAR,
                {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                false);
            raw.resize(idx.size());
            for (size_t k = 0; k < idx.size(); ++k) {
                if (idx[k] >= static_cast<double>(vertexCount))
                    fail(what + " index " + std::to_string(k) + " is " +
                         std::to_string(static_cast<uint64_t>(idx[k])) +
                         " but the primitive has only " + std::to_string(vertexCount) +
                         " vertices");
                raw[k] = static_cast<uint32_t>(idx[k]);
            }
        } else {
            if (vertexCount > std::numeric_limits<uint32_t>::max())
                fail(what + " has too many vertices");
            raw.resize(vertexCount);
            for (size_t k = 0; k < vertexCount; ++k) raw[k] = static_cast<uint32_t>(k);
        }
        prim.indices = toTriangleList(raw, mode, what);
        if (prim.indices.empty()) {
            warn(what + " has no complete triangle; skipped");
            return std::nullopt;
        }
        if (prim.normals.empty())
            generateFlatNormals(prim);
        else
            repairZeroNormals(prim, what);

        if (prim.material >= 0) {
            const Material& m = scene_.materials[static_cast<size_t>(prim.material)];
            for (const TextureRef* t :
                 {&m.baseColorTexture, &m.metallicRoughnessTexture, &m.normalTexture,
                  &m.emissiveTexture, &m.transmissionTexture, &m.thicknessTexture})
                if (t->valid() && (t->texCoord == 0 ? prim.uv0.empty() : prim.uv1.empty()))
                    warn(what + " uses material " + std::to_string(prim.material) +
                         " whose texture reads TEXCOORD_" + std::to_string(t->texCoord) +
                         ", which the primitive lacks");
        }
        return prim;
    }

    std::vector<uint32_t> toTriangleList(const std::vector<uint32_t>& raw, int mode,
                                         const std::string& what) {
        std::vector<uint32_t> tri;
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (raw.size() % 3 != 0)
                warn(what + " has " + std::to_string(raw.size()) +
                     " indices, not a multiple of 3; the last " + std::to_string(raw.size() % 3) +
                     " are ignored");
            tri.assign(raw.begin(),
                       raw.begin() + static_cast<std::ptrdiff_t>(raw.size() - raw.size() % 3));
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (size_t k = 0; k + 2 < raw.size(); ++k) {
                // Every other triangle flips its winding so all face the same way (glTF 3.7.2.1).
                if (k % 2 == 0)
                    tri.insert(tri.end(), {raw[k], raw[k + 1], raw[k + 2]});
                else
                    tri.insert(tri.end(), {raw[k + 1], raw[k], raw[k + 2]});
            }
        } else {  // fan
            for (size_t k = 1; k + 1 < raw.size(); ++k)
                tri.insert(tri.end(), {raw[0], raw[k], raw[k + 1]});
        }
        return tri;
    }

    static glm::vec3 faceNormal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
        glm::dvec3 n = glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
        double len = glm::length(n);
        // A degenerate triangle covers no area; any unit normal will do.
        return len > 0 && std::isfinite(len) ? glm::vec3(n / len) : glm::vec3(0, 1, 0);
    }

    // glTF 3.7.2.1: without normals, clients must use flat normals. Flat shading needs one vertex
    // per triangle corner, so the primitive is un-indexed.
    static void generateFlatNormals(Primitive& prim) {
        Primitive flat;
        flat.material = prim.material;
        const size_t n = prim.indices.size();
        flat.positions.reserve(n);
        flat.normals.reserve(n);
        for (size_t k = 0; k < n; k += 3) {
            glm::vec3 nrm =
                faceNormal(prim.positions[prim.indices[k]], prim.positions[prim.indices[k + 1]],
                           prim.positions[prim.indices[k + 2]]);
            for (size_t j = 0; j < 3; ++j) {
                uint32_t v = prim.indices[k + j];
                flat.positions.push_back(prim.positions[v]);
                flat.normals.push_back(nrm);
                if (!prim.tangents.empty()) flat.tangents.push_back(prim.tangents[v]);
                if (!prim.uv0.empty()) flat.uv0.push_back(prim.uv0[v]);
                if (!prim.uv1.empty()) flat.uv1.push_back(prim.uv1[v]);
                flat.indices.push_back(static_cast<uint32_t>(k + j));
            }
        }
        prim = std::move(flat);
    }

    // Normals of zero length (invalid glTF, but common) would become NaN when normalised; they
    // are replaced by the area-weighted normal of the triangles around the vertex.
    void repairZeroNormals(Primitive& prim, const std::string& what) {
        size_t bad = 0;
        for (glm::vec3& n : prim.normals) {
            float len = glm::length(n);
            if (len < 1e-8f)
                ++bad;
            else
                n /= len;
        }
        if (bad == 0) return;
        std::vector<glm::dvec3> accumulated(prim.positions.size(), glm::dvec3(0.0));
        for (size_t k = 0; k < prim.indices.size(); k += 3) {
            const glm::dvec3 a(prim.positions[prim.indices[k]]),
                b(prim.positions[prim.indices[k + 1]]), c(prim.positions[prim.indices[k + 2]]);
            const glm::dvec3 n = glm::cross(b - a, c - a);
            for (size_t j = 0; j < 3; ++j) accumulated[prim.indices[k + j]] += n;
        }
        for (size_t v = 0; v < prim.normals.size(); ++v) {
            if (glm::length(prim.normals[v]) >= 0.5f) continue;
            double len = glm::length(accumulated[v]);
            prim.normals[v] = len > 0 && std::isfinite(len) ? glm::vec3(accumulated[v] / len)
                                                            : glm::vec3(0, 1, 0);
        }
        warn(what + " has " + std::to_string(bad) +
             " zero-length normals; replaced by geometric normals");
    }

    // ---- lights and cameras ----

    void readLights() {
        constexpr double kHalfPi = 1.5707963267948966;
        for (size_t i = 0; i < model_.lights.size(); ++i) {
            const tinygltf::Light& src = model_.lights[i];
            const std::string name = "KHR_lights_punctual light " + std::to_string(i);
            Light l;
            l.name = src.name;
            if (src.type == "point")
                l.type = Light::Type::Point;
            else if (src.type == "spot")
                l.type = Light::Type::Spot;
            else if (src.type == "directional")
                l.type = Light::Type::Directional;
            else
                fail(name + " has type " + quote(src.type) +
                     "; expected point, spot or directional");
            if (!src.color.empty()) {
                if (src.color.size() != 3 || !allFinite(src.color))
                    fail(name + " color must be 3 finite numbers");
                for (int c = 0; c < 3; ++c) {
                    if (src.color[static_cast<size_t>(c)] < 0)
                        fail(name + " color must not be negative");
                    l.color[c] = toFloat(src.color[static_cast<size_t>(c)], name + " color");
                }
            }
            if (!std::isfinite(src.intensity) || src.intensity < 0)
                fail(name +
                     " intensity must be a finite number >= 0 (candela for point/spot, lux for "
                     "directional)");
            l.intensity = toFloat(src.intensity, name + " intensity");
            if (!std::isfinite(src.range) || src.range < 0)
                fail(name + " range must be a finite number > 0 (omit it for unlimited range)");
            l.range = toFloat(src.range, name + " range");
            if (l.type == Light::Type::Spot) {
                const double inner = src.spot.innerConeAngle, outer = src.spot.outerConeAngle;
                if (!std::isfinite(inner) || !std::isfinite(outer) || inner < 0 ||
                    outer > kHalfPi + 1e-9 || !(inner < outer))
                    fail(name +
                         " spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= "
                         "pi/2 (radians); got " +
                         std::to_string(inner) + " and " + std::to_string(outer));
                l.innerConeAngle = static_cast<float>(inner);
                l.outerConeAngle = static_cast<float>(outer);
            }
            scene_.lights.push_back(l);
        }
    }

    void readCameras() {
        for (size_t i = 0; i < model_.cameras.size(); ++i) {
            const tinygltf::Camera& src = model_.cameras[i];
            const std::string name = "camera " + std::to_string(i);
            CameraNodeInfo c;
            c.name = src.name;
            if (src.type == "perspective") {
                const auto& p = src.perspective;
                if (!std::isfinite(p.yfov) || p.yfov <= 0 || p.yfov >= 3.14159)
                    fail(name + " perspective.yfov must be in (0, pi) radians; got " +
                         std::to_string(p.yfov));
                if (!std::isfinite(p.znear) || p.znear <= 0)
                    fail(name + " perspective.znear must be > 0 metres; got " +
                         std::to_string(p.znear));
                if (!std::isfinite(p.aspectRatio) || p.aspectRatio < 0)
                    fail(name + " perspective.aspectRatio must be > 0 (or absent)");
                if (!std::isfinite(p.zfar) || p.zfar < 0 || (p.zfar > 0 && p.zfar <= p.znear))
                    fail(name +
                         " perspective.zfar must be greater than znear (or absent for infinite)");
                c.yfov = toFloat(p.yfov, name + " yfov");
                c.aspectRatio = toFloat(p.aspectRatio, name + " aspectRatio");
                c.znear = toFloat(p.znear, name + " znear");
                c.infiniteFar = p.zfar == 0;
                c.zfar = c.infiniteFar ? toFloat(std::min(std::max(1000.0, p.znear * 1000.0), 1e30),
                                                 name + " znear * 1000")
                                       : toFloat(p.zfar, name + " zfar");
            } else if (src.type == "orthographic") {
                const auto& o = src.orthographic;
                if (!std::isfinite(o.xmag) || !std::isfinite(o.ymag) || o.xmag == 0 || o.ymag == 0)
                    fail(name + " orthographic.xmag and ymag must be finite and non-zero");
                if (!std::isfinite(o.znear) || !std::isfinite(o.zfar) || o.znear < 0 ||
                    o.zfar <= o.znear)
                    fail(name + " orthographic needs 0 <= znear < zfar");
                c.projection = CameraNodeInfo::Projection::Orthographic;
                c.xmag = toFloat(o.xmag, name + " xmag");
                c.ymag = toFloat(o.ymag, name + " ymag");
                c.znear = toFloat(o.znear, name + " znear");
                c.zfar = toFloat(o.zfar, name + " zfar");
            } else {
                fail(name + " has type " + quote(src.type) +
                     "; expected perspective or orthographic");
            }
            scene_.cameras.push_back(c);
        }
    }

    // ---- nodes ----

    glm::dmat4 localMatrix(const tinygltf::Node& src, const std::string& name) {
        if (!src.matrix.empty()) {
            if (src.matrix.size() != 16) fail(name + " matrix must have 16 numbers (column-major)");
            if (!allFinite(src.matrix)) fail(name + " matrix contains NaN or infinity");
            if (!src.translation.empty() || !src.rotation.empty() || !src.scale.empty())
                warn(name + " has both matrix and TRS; the matrix is used");
            glm::dmat4 m;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) m[c][r] = src.matrix[static_cast<size_t>(c * 4 + r)];
            return m;
        }
        glm::dvec3 t(0.0), s(1.0);
        glm::dquat q(1.0, 0.0, 0.0, 0.0);
        if (!src.translation.empty()) {
            if (src.translation.size() != 3 || !allFinite(src.translation))
                fail(name + " translation must be 3 finite numbers (metres)");
            t = {src.translation[0], src.translation[1], src.translation[2]};
        }
        if (!src.rotation.empty()) {
            if (src.rotation.size() != 4 || !allFinite(src.rotation))
                fail(name + " rotation must be 4 finite numbers (quaternion x, y, z, w)");
            // glTF stores x, y, z, w; glm's constructor takes w first.
            q = glm::dquat(src.rotation[3], src.rotation[0], src.rotation[1], src.rotation[2]);
            const double len = glm::length(q);
            if (!(len > 1e-6) || !std::isfinite(len))
                fail(name + " rotation quaternion has zero length");
            if (std::abs(len - 1.0) > 1e-3)
                warn(name + " rotation quaternion is not unit length; normalised");
            q /= len;
        }
        if (!src.scale.empty()) {
            if (src.scale.size() != 3 || !allFinite(src.scale))
                fail(name + " scale must be 3 finite numbers");
            s = {src.scale[0], src.scale[1], src.scale[2]};
        }
        // glTF: M = T * R * S.
        glm::dmat4 m = glm::mat4_cast(q);
        m[0] *= s.x;
        m[1] *= s.y;
        m[2] *= s.z;
        m[3] = glm::dvec4(t, 1.0);
        return m;
    }

    void readNodes() {
        const size_t count = model_.nodes.size();
        scene_.nodes.resize(count);
        std::vector<std::optional<bool>> explicitReal(count);
        for (size_t i = 0; i < count; ++i) {
            const tinygltf::Node& src = model_.nodes[i];
            const std::string name = "node " + std::to_string(i) +
                                     (src.name.empty() ? "" : " (" + quote(src.name) + ")");
            Node& node = scene_.nodes[i];
            node.name = src.name;
            node.local = localMatrix(src, name);
            if (src.mesh != -1)
                data_.checkIndex(src.mesh, scene_.meshes.size(), name + " field 'mesh'", "mesh");
            node.mesh = src.mesh;
            if (src.camera != -1)
                data_.checkIndex(src.camera, scene_.cameras.size(), name + " field 'camera'",
                                 "camera");
            node.camera = src.camera;
            if (src.skin >= 0) warn(name + " has a skin; skinning is ignored (bind pose used)");
            if (const tinygltf::Value* ext =
                    extension(src.extensions, "KHR_lights_punctual", name)) {
                if (!ext->Has("light") || !ext->Get("light").IsInt())
                    fail(name + " extensions.KHR_lights_punctual needs an integer 'light'");
                const int light = ext->Get("light").GetNumberAsInt();
                data_.checkIndex(light, scene_.lights.size(),
                                 name + " KHR_lights_punctual field 'light'", "light");
                node.light = light;
            }
            if (const tinygltf::Value* mirage = mirageExtras(src.extras, name)) {
                if (mirage->Has("real")) {
                    if (!mirage->Get("real").IsBool())
                        fail(name + " extras.mirage.real must be true or false");
                    explicitReal[i] = mirage->Get("real").Get<bool>();
                }
            }
            for (int child : src.children) {
                data_.checkIndex(child, count, name + " field 'children'", "node");
                if (static_cast<size_t>(child) == i)
                    fail(name + " lists itself as a child; the node graph must be a tree");
                Node& c = scene_.nodes[static_cast<size_t>(child)];
                if (c.parent == static_cast<int>(i))
                    fail(name + " lists node " + std::to_string(child) + " twice in 'children'");
                if (c.parent >= 0)
                    fail("node " + std::to_string(child) + " is a child of both node " +
                         std::to_string(c.parent) + " and node " + std::to_string(i) +
                         "; glTF nodes must form disjoint trees");
                c.parent = static_cast<int>(i);
                node.children.push_back(child);
            }
        }

        // World transforms and real/virtual inheritance, top-down from the parentless nodes. Nodes
        // never reached from a parentless node sit on a cycle (every node has at most one parent).
        std::vector<char> visited(count, 0);
        std::vector<int> stack;
        for (size_t i = 0; i < count; ++i)
            if (scene_.nodes[i].parent < 0) stack.push_back(static_cast<int>(i));
        while (!stack.empty()) {
            const size_t i = static_cast<size_t>(stack.back());
            stack.pop_back();
            visited[i] = 1;
            Node& node = scene_.nodes[i];
            const Node* parent =
                node.parent >= 0 ? &scene_.nodes[static_cast<size_t>(node.parent)] : nullptr;
            node.world = parent ? parent->world * node.local : node.local;
            if (!allFinite(node.world))
                fail("node " + std::to_string(i) +
                     " world transform overflows (non-finite); check the scales along its parents");
            const Origin inherited = parent ? parent->origin : Origin::Virtual;
            node.origin =
                explicitReal[i] ? (*explicitReal[i] ? Origin::Real : Origin::Virtual) : inherited;
            if (node.light >= 0 &&
                !(glm::length(glm::dmat3(node.world) * glm::dvec3(0, 0, -1)) > 1e-12))
                fail("node " + std::to_string(i) +
                     " holds a light but its world transform collapses the -Z axis (zero scale)");
            for (int child : node.children) stack.push_back(child);
        }
        for (size_t i = 0; i < count; ++i)
            if (!visited[i])
                fail("node " + std::to_string(i) +
                     " is part of a cycle in the node hierarchy (children lead back to it); "
                     "glTF nodes must form trees");

        // Roots: the default scene (or scene 0); without scenes, every parentless node.
        if (model_.scenes.empty()) {
            if (count > 0) warn("the file has no 'scenes'; all parentless nodes are used as roots");
            for (size_t i = 0; i < count; ++i)
                if (scene_.nodes[i].parent < 0) scene_.roots.push_back(static_cast<int>(i));
            return;
        }
        int sceneIndex = model_.defaultScene;
        if (sceneIndex != -1)
            data_.checkIndex(sceneIndex, model_.scenes.size(), "field 'scene'", "scene");
        else
            sceneIndex = 0;
        sceneIndex_ = sceneIndex;
        std::set<int> seen;
        for (int root : model_.scenes[static_cast<size_t>(sceneIndex)].nodes) {
            const std::string what = "scene " + std::to_string(sceneIndex) + " field 'nodes'";
            data_.checkIndex(root, count, what, "node");
            if (scene_.nodes[static_cast<size_t>(root)].parent >= 0)
                fail(what + " lists node " + std::to_string(root) + ", which is a child of node " +
                     std::to_string(scene_.nodes[static_cast<size_t>(root)].parent) +
                     "; scene roots must be root nodes");
            if (!seen.insert(root).second)
                fail(what + " lists node " + std::to_string(root) + " twice");
            scene_.roots.push_back(root);
        }
    }

    // ---- environment (extras.mirage.environment of the scene in use, else of the asset) ----

    std::string stringField(const tinygltf::Value& object, const char* key, const std::string& what,
                            bool required) const {
        if (!object.Has(key)) {
            if (required) fail(what + " needs a string field '" + key + "'");
            return {};
        }
        if (!object.Get(key).IsString()) fail(what + " field '" + key + "' must be a string");
        return object.Get(key).Get<std::string>();
    }

    fs::path existingFile(const std::string& relative, const std::string& what) const {
        if (relative.empty()) fail(what + " is empty");
        fs::path p = resolveContained(baseDir_, relative, file_, what);
        std::error_code ec;
        p = fs::absolute(p, ec).lexically_normal();
        if (ec || !fs::is_regular_file(p, ec))
            fail(what + " names " + quote(relative) + ", but " + p.string() +
                 " does not exist; paths are relative to the glTF file");
        return p;
    }

    void readEnvironment() {
        const tinygltf::Value* mirage = nullptr;
        std::string where;
        if (sceneIndex_ >= 0) {
            where = "scene " + std::to_string(sceneIndex_);
            mirage = mirageExtras(model_.scenes[static_cast<size_t>(sceneIndex_)].extras, where);
        }
        if (!mirage || !mirage->Has("environment")) {
            where = "asset";
            mirage = mirageExtras(model_.asset.extras, where);
        }
        if (!mirage || !mirage->Has("environment")) return;
        const std::string what = where + " extras.mirage.environment";
        const tinygltf::Value& env = mirage->Get("environment");
        if (!env.IsObject()) fail(what + " must be a JSON object");
        Environment& e = scene_.environment;
        const std::string type = stringField(env, "type", what, true);
        if (type == "none") return;
        constexpr double kInf = std::numeric_limits<double>::infinity();
        e.image = existingFile(stringField(env, "image", what, true), what + " field 'image'");
        e.intensity = static_cast<float>(number(env, "intensity", 1.0, what, 0, kInf));
        if (type == "equirectangular") {
            e.kind = Environment::Kind::Equirectangular;
            e.rotationYDeg = number(env, "rotation_y_deg", 0.0, what, -1e6, 1e6);
        } else if (type == "fisheye") {
            e.kind = Environment::Kind::Fisheye;
            e.calibration = existingFile(stringField(env, "calibration", what, true),
                                         what + " field 'calibration'");
            if (!env.Has("T_world_camera"))
                fail(what + " needs 'T_world_camera': [tx, ty, tz, qw, qx, qy, qz]");
            const tinygltf::Value& t = env.Get("T_world_camera");
            if (!t.IsArray() || t.ArrayLen() != 7)
                fail(what +
                     " field 'T_world_camera' must be 7 numbers [tx, ty, tz, qw, qx, qy, qz]");
            std::array<double, 7> v{};
            for (int k = 0; k < 7; ++k) {
                if (!t.Get(k).IsNumber() || !std::isfinite(t.Get(k).GetNumberAsDouble()))
                    fail(what + " T_world_camera[" + std::to_string(k) +
                         "] must be a finite number");
                v[static_cast<size_t>(k)] = t.Get(k).GetNumberAsDouble();
            }
            glm::dquat q(v[3], v[4], v[5], v[6]);
            const double len = glm::length(q);
            if (!(len > 1e-6)) fail(what + " T_world_camera quaternion has zero length");
            e.T_world_camera.rotation = q / len;
            e.T_world_camera.translation = {v[0], v[1], v[2]};
        } else {
            fail(what + " field 'type' is " + quote(type) +
                 "; expected equirectangular, fisheye or none");
        }
    }

    std::string file_;
    fs::path baseDir_;
    std::string base_;  // baseDir_ as tinygltf and the file callbacks see it
    tinygltf::Model model_;
    gltf::AccessorReader data_{model_, file_};
    Scene scene_;
    std::vector<Texture> images_;     // decoded glTF images, before textures copy them
    std::map<int, bool> textureUse_;  // texture index -> used as sRGB colour
    int sceneIndex_ = -1;
};

}  // namespace

Scene readGltf(const std::string& bytes, const std::string& name, const fs::path& baseDir) {
    GltfReader reader(name, baseDir);
    return reader.read(bytes);
}

}  // namespace mirage::gltf
