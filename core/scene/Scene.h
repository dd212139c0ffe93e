#pragma once
// The scene model: what a glTF 2.0 file describes, flattened into plain C++ data that both the
// real-time renderer and the Embree reference renderer consume. Conventions (docs/scene.md):
//  - World frame = glTF frame: right-handed, metres, +Y up.
//  - Colours (baseColor, emissive, light colour, attenuation colour) are LINEAR; textures marked
//    srgb are decoded to linear when sampled (Texture::srgb says how the stored bytes are encoded).
//  - Every node and light is REAL (a pre-modelled proxy of something in the footage) or VIRTUAL.
//    Set by node extras {"mirage": {"real": true}}; inherited by children; default virtual.
//  - Lights follow KHR_lights_punctual: point/spot intensity in candela, directional in lux;
//    spot cones in radians; a light shines down its node's -Z axis.
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "core/scene/DensityGrid.h"

namespace mirage {

enum class Origin { Virtual, Real };

struct Texture {
    std::string name;
    int width = 0, height = 0;
    int components = 4;                 // always RGBA8 after loading
    std::vector<unsigned char> pixels;  // row-major, top row first, RGBA8
    // How the stored bytes are encoded: true when a material uses the texture as baseColor or
    // emissive (sRGB-encoded colour), false for data textures (normal, metallic-roughness,
    // transmission), which are linear. A texture used both ways is reported as sRGB with a
    // warning (Scene::warnings).
    bool srgb = false;
    // glTF sampler state (defaults = glTF's when a texture has no sampler).
    enum class Wrap { Repeat, ClampToEdge, MirroredRepeat };
    Wrap wrapS = Wrap::Repeat, wrapT = Wrap::Repeat;
    enum class Filter { Linear, Nearest };
    Filter magFilter = Filter::Linear;
    Filter minFilter = Filter::Linear;
    bool mipmaps = true;  // false when the sampler's minFilter is NEAREST or LINEAR
};

struct TextureRef {
    int texture = -1;  // index into Scene::textures, -1 = none
    int texCoord = 0;  // which UV set (0 or 1)
    bool valid() const { return texture >= 0; }
};

struct Material {
    std::string name;
    // PBR metallic-roughness.
    glm::vec4 baseColor{1.0f};    // linear RGBA
    TextureRef baseColorTexture;  // sRGB-encoded
    float metallic = 1.0f, roughness = 1.0f;
    TextureRef metallicRoughnessTexture;  // linear; G = roughness, B = metallic
    TextureRef normalTexture;             // linear, tangent space
    float normalScale = 1.0f;
    // Linear; KHR_materials_emissive_strength is already folded in (emissiveFactor * strength).
    glm::vec3 emissive{0.0f};
    TextureRef emissiveTexture;  // sRGB-encoded
    bool doubleSided = false;
    enum class AlphaMode { Opaque, Mask, Blend } alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;
    // KHR_materials_transmission: fraction of light transmitted through the surface.
    float transmission = 0.0f;
    TextureRef transmissionTexture;  // R channel
    // KHR_materials_ior.
    float ior = 1.5f;
    // KHR_materials_volume: thickness in the mesh's local units; Beer-Lambert attenuation:
    // after distance d inside, light keeps attenuationColor^(d / attenuationDistance).
    float thickness = 0.0f;
    TextureRef thicknessTexture;       // G channel, multiplies thickness
    glm::vec3 attenuationColor{1.0f};  // linear
    float attenuationDistance = std::numeric_limits<float>::infinity();  // metres
    // mirage extras (docs/scene.md), filled as features arrive:
    // A translucent object: a closed mesh filled with a participating medium whose extinction is
    // sigma_t(x) = extinction * density(x), from MIRAGE_materials_scattering or from
    // KHR_materials_diffuse_transmission + KHR_materials_volume (docs/scene.md). Its boundary is
    // a smooth interface of index `ior` that weights light by Fresnel but does not bend it.
    struct Scattering {
        bool present = false;
        float extinction = 0.0f;  // sigma_t at density 1, 1/m (world metres)
        glm::vec3 albedo{1.0f};   // single-scattering albedo sigma_s / sigma_t, linear
        std::shared_ptr<const DensityGrid> density;  // null: density 1 everywhere inside
        std::string densityUri;                      // as the glTF names it (messages, cache keys)
    } scattering;

    bool isTranslucent() const { return scattering.present; }
    // Metals (metallic >= 0.99, no transmission) are specular up to kRoughReflectorMaxRoughness:
    // a perfect mirror up to kMirrorMaxRoughness, a rough reflector above it (the real-time
    // renderer traces its mirror ray and blurs the reflection with the fuzzy-reflection filter,
    // docs/specular.md). Rougher metals stay glossy surfaces (punctual GGX + environment): a
    // reflection lobe that wide no longer fits the filter's cone.
    static constexpr float kMirrorMaxRoughness = 0.05f;
    static constexpr float kRoughReflectorMaxRoughness = 0.5f;
    bool isMetal() const { return metallic >= 0.99f && transmission == 0 && !isTranslucent(); }
    bool isMirror() const { return isMetal() && roughness <= kMirrorMaxRoughness; }
    bool isRoughReflector() const {
        return isMetal() && roughness > kMirrorMaxRoughness &&
               roughness <= kRoughReflectorMaxRoughness;
    }
    bool isTransmissive() const { return transmission > 0.0f && !isTranslucent(); }
    // Frosted glass: transmissive with roughness above the mirror threshold (the real-time
    // renderer blurs what is seen through it with the same filter, docs/specular.md).
    bool isRoughGlass() const {
        return isTransmissive() && !isMirror() && roughness > kMirrorMaxRoughness;
    }
};

struct Primitive {
    std::vector<glm::vec3> positions;  // mesh-local frame
    std::vector<glm::vec3> normals;    // generated (flat) when the file has none
    std::vector<glm::vec4> tangents;   // empty when absent
    std::vector<glm::vec2> uv0, uv1;   // empty when absent
    std::vector<uint32_t> indices;     // triangle list (always indexed after loading)
    int material = -1;                 // -1 = glTF default material
};

struct Mesh {
    std::string name;
    std::vector<Primitive> primitives;
};

struct Light {
    enum class Type { Point, Spot, Directional };
    std::string name;
    Type type = Type::Point;
    glm::vec3 color{1.0f};                       // linear
    float intensity = 1.0f;                      // candela (point, spot) or lux (directional)
    float range = 0.0f;                          // metres; 0 = infinite
    float innerConeAngle = 0.0f;                 // radians
    float outerConeAngle = 0.7853981633974483f;  // radians
};

struct CameraNodeInfo {
    std::string name;
    enum class Projection { Perspective, Orthographic };
    Projection projection = Projection::Perspective;
    float yfov = 0.8f;         // radians, vertical (perspective)
    float aspectRatio = 0.0f;  // 0 = use the output's
    // Metres. glTF's "no zfar" (infinite projection) is reported as 1000 m so that consumers
    // can always build a finite projection; `infiniteFar` says it was absent.
    float znear = 0.01f, zfar = 1000.0f;
    bool infiniteFar = false;
    float xmag = 1.0f, ymag = 1.0f;  // orthographic half-extents, metres
};

struct Node {
    std::string name;
    int parent = -1;
    std::vector<int> children;
    glm::dmat4 local{1.0};  // parent-from-node
    glm::dmat4 world{1.0};  // world-from-node (computed by the loader)
    int mesh = -1, light = -1, camera = -1;
    Origin origin = Origin::Virtual;  // after inheritance from parents
};

// Environment light: an equirectangular image over world directions, or a fish-eye camera image
// whose calibration and pose map pixels to world directions.
struct Environment {
    enum class Kind { None, Equirectangular, Fisheye };
    Kind kind = Kind::None;
    std::filesystem::path image;        // resolved absolute path
    float intensity = 1.0f;             // multiplier on the (linear) image
    double rotationYDeg = 0.0;          // equirect: rotation about world +Y
    std::filesystem::path calibration;  // fish-eye: OpenCV YAML
    Pose T_world_camera;                // fish-eye: camera pose in the world (OpenCV axes)
    Origin origin = Origin::Real;       // the captured environment is real
};

// A mesh placed in the world: what renderers iterate over.
struct MeshInstance {
    int node = -1, mesh = -1;
    glm::dmat4 world{1.0};
    Origin origin = Origin::Virtual;
};

struct LightInstance {
    int node = -1, light = -1;
    glm::dvec3 position{0.0};        // world, metres
    glm::dvec3 direction{0, 0, -1};  // world, unit; the light shines along it
    Origin origin = Origin::Virtual;
};

struct Scene {
    std::filesystem::path source;  // the file it was loaded from
    std::vector<Texture> textures;
    std::vector<Material> materials;
    std::vector<Mesh> meshes;
    std::vector<Light> lights;
    std::vector<CameraNodeInfo> cameras;
    std::vector<Node> nodes;
    std::vector<int> roots;  // root nodes of the glTF scene in use (the default scene)
    Environment environment;
    // Non-fatal problems found while loading (skipped point/line primitives, unknown optional
    // extensions, ...); each is also logged as a warning.
    std::vector<std::string> warnings;

    // Instances of the nodes reachable from `roots`, in depth-first order.
    std::vector<MeshInstance> meshInstances() const;
    std::vector<LightInstance> lightInstances() const;
    // Index of the node called `name` that holds a camera; throws mirage::Error listing the
    // camera nodes there are when none matches. An empty name picks the first camera node
    // (lowest index) reachable from the roots.
    int findCameraNode(const std::string& name) const;
    // The material of a primitive, the glTF default material for -1.
    const Material& material(int index) const;
    // True when any mesh or light instance is virtual (something to composite).
    bool hasVirtual() const;
};

// Loads a .gltf or .glb. Throws mirage::FileError naming the file and the problem on bad input
// (missing buffers, out-of-range indices, wrong accessor types, non-finite transforms, unknown
// required extensions); never crashes on malformed data.
Scene loadScene(const std::filesystem::path& path);
// Loads from memory (used by the fuzz target); `name` is used in error messages and `baseDir`
// resolves external URIs.
Scene loadSceneFromMemory(const std::string& bytes, const std::string& name,
                          const std::filesystem::path& baseDir);

}  // namespace mirage
