#pragma once
// A mirage::Scene prepared for ray tracing with Embree: every mesh primitive flattened into world
// space (one Embree triangle geometry each), materials resolved (textures decoded to linear),
// punctual lights and the environment light. One RayTracingScene holds either the whole scene or
// only its REAL parts (SceneSubset::RealOnly): the latter is what L_r of differential rendering
// sees — real geometry as the only occluders, real lights and the (real) environment.
//
// Units and frames: world = glTF (metres, +Y up). Lights follow KHR_lights_punctual, read as
// radiometric quantities: point/spot intensity is radiant intensity (W/sr, per colour channel
// after multiplying by the light colour), directional intensity is irradiance (W/m^2). The glTF
// light `range` is ignored (physically based inverse-square falloff).
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/Scene.h"
#include "render/raytrace/Bsdf.h"
#include "render/raytrace/EmbreeDevice.h"
#include "render/raytrace/EnvironmentLight.h"

namespace mirage::raytrace {

enum class SceneSubset { All, RealOnly };

struct SurfaceHit {
    glm::vec3 p{0.0f};   // world position (metres)
    glm::vec3 ng{0.0f};  // unit geometric normal, counter-clockwise front face (glTF winding)
    glm::vec3 ns{0.0f};  // unit shading normal, same hemisphere as ng
    glm::vec2 uv[2]{};   // texture coordinates 0 and 1 (0 where absent)
    float t = 0.0f;
    uint32_t geometry = 0;
};

struct PunctualLight {
    Light::Type type = Light::Type::Point;
    glm::vec3 position{0.0f};       // world
    glm::vec3 direction{0, 0, -1};  // world, unit, the way the light shines
    glm::vec3 intensity{1.0f};      // colour * intensity: W/sr (point, spot) or W/m^2 (directional)
    float cosInner = 1.0f, cosOuter = 0.0f;  // spot cone (cosines)
    Origin origin = Origin::Real;
    // KHR_lights_punctual spot falloff: ((cos - cosOuter) / (cosInner - cosOuter))^2 clamped;
    // 1 for point and directional lights. `cosAngle` = dot(direction, light-to-point).
    float spotFactor(float cosAngle) const;
};

// Material of one geometry, resolved for shading.
struct ShadingMaterial {
    Material gltf;
    glm::vec3 sigmaA{0.0f};  // Beer-Lambert absorption coefficient inside (1/m), per channel
    bool hasVolume = false;
};

// The participating medium inside a translucent object (Material::Scattering placed in the
// world): sigma_t(x) = extinction * density(localFromWorld x), 1/m; single-scattering albedo per
// channel; isotropic phase function. Its boundary weights light by Fresnel (index `ior`) and does
// not bend it (docs/reference-renderer.md, "Translucent objects").
struct Medium {
    float extinction = 0.0f;  // 1/m at density 1
    glm::vec3 albedo{1.0f};
    std::shared_ptr<const DensityGrid> density;  // null: density 1 everywhere inside
    glm::mat4 localFromWorld{1.0f};
    float ior = 1.0f;
    float majorant = 0.0f;  // >= sigmaT anywhere (1/m), for delta and ratio tracking
    bool homogeneous() const { return !density; }
    float sigmaT(const glm::vec3& pWorld) const {
        if (!density) return extinction;
        return extinction * density->density(glm::vec3(localFromWorld * glm::vec4(pWorld, 1.0f)));
    }
};

class RayTracingScene {
public:
    // Builds the Embree scene. Throws mirage::Error on malformed geometry (indices out of range,
    // non-finite positions) naming the mesh, and FileError when the environment image is missing.
    RayTracingScene(const Scene& scene, SceneSubset subset, const EmbreeDevice& device);

    RayTracingScene(RayTracingScene&&) noexcept = default;
    RayTracingScene& operator=(RayTracingScene&&) noexcept = default;

    // Closest hit along o + t d for t in (0, tMax). d need not be unit but the returned t is in
    // units of |d|.
    bool intersect(const glm::vec3& o, const glm::vec3& d, float tMax, SurfaceHit& hit) const;
    // Any hit for t in (0, tMax).
    bool occluded(const glm::vec3& o, const glm::vec3& d, float tMax) const;

    // Material parameters at a hit (base colour texture applied, decoded to linear).
    BsdfParams bsdfParams(const SurfaceHit& hit) const;
    glm::vec3 emission(const SurfaceHit& hit) const;  // linear radiance, both faces
    const ShadingMaterial& material(const SurfaceHit& hit) const;
    Origin origin(const SurfaceHit& hit) const { return geometries_[hit.geometry].origin; }
    // True when the geometry's material has a delta (perfectly specular) lobe: photon targets.
    bool isDeltaSpecular(uint32_t geometry) const { return geometries_[geometry].deltaSpecular; }

    // The medium inside a translucent geometry, null for every other geometry.
    const Medium* medium(uint32_t geometry) const {
        int m = geometries_[geometry].medium;
        return m >= 0 ? &media_[size_t(m)] : nullptr;
    }
    bool hasMedia() const { return !media_.empty(); }

    const std::vector<PunctualLight>& lights() const { return lights_; }
    const EnvironmentLight* environment() const { return environment_.get(); }
    // Replaces the environment light (nullptr: none) between renders: a per-frame environment
    // (a room light that moves, the environment camera's frame of that time).
    void setEnvironment(std::unique_ptr<EnvironmentLight> environment);
    // Width of the equirectangular map a fish-eye environment image is resampled onto.
    static constexpr int kFisheyeEnvironmentWidth = 1024;
    SceneSubset subset() const { return subset_; }

    struct BoundingSphere {
        glm::vec3 centre{0.0f};
        float radius = 0.0f;
    };
    // Bounding spheres of geometries with delta-specular materials (where caustics start).
    std::vector<BoundingSphere> deltaSpecularBounds() const;
    BoundingSphere sceneBounds() const { return sceneBounds_; }
    size_t geometryCount() const { return geometries_.size(); }
    RTCScene embreeScene() const { return scene_.get(); }

private:
    struct Geometry {
        std::vector<glm::vec3> positions, normals;
        std::vector<glm::vec2> uv0, uv1;
        std::vector<uint32_t> indices;
        int material = -1;  // index into materials_
        Origin origin = Origin::Virtual;
        bool deltaSpecular = false;
        int medium = -1;  // index into media_ (translucent materials)
        BoundingSphere bounds;
    };
    glm::vec3 sampleTexture(int texture, glm::vec2 uv) const;
    // The constructor's steps.
    void addLights(const Scene& scene);
    void attach(Geometry g);
    void loadEnvironment(const Environment& env);

    const EmbreeDevice* device_ = nullptr;
    EmbreeScene scene_;
    SceneSubset subset_ = SceneSubset::All;
    std::vector<Geometry> geometries_;
    std::vector<ShadingMaterial> materials_;
    std::vector<Medium> media_;  // scene materials + the glTF default at the end
    std::vector<Texture> textures_;
    std::vector<PunctualLight> lights_;
    std::unique_ptr<EnvironmentLight> environment_;
    BoundingSphere sceneBounds_;
};

}  // namespace mirage::raytrace
