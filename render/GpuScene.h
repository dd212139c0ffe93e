#pragma once
// A mirage::Scene uploaded to the GPU for the real-time renderer: one vertex/index buffer for all
// meshes, one draw item per (mesh instance, primitive) with its world matrix and REAL/VIRTUAL
// origin, the materials as a storage buffer, the lights in world space (each REAL or VIRTUAL),
// a pool of surface sample points for imperfect shadow maps, and the environment light as SH9
// irradiance coefficients. World frame = glTF (metres, +Y up).
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "core/gl/Objects.h"
#include "core/scene/Scene.h"
#include "render/GpuTypes.h"

namespace mirage::render {

struct BoundingSphere {
    glm::vec3 center{0.0f};
    float radius = 0.0f;  // metres
};

// One vertex of GpuScene::vertexBuffer() (mesh-local; 32 bytes, tightly packed).
struct GpuSceneVertex {
    glm::vec3 position;  // mesh-local (metres)
    glm::vec3 normal;    // mesh-local
    glm::vec2 uv;        // the UV set the base colour texture uses
};
static_assert(sizeof(GpuSceneVertex) == 32);

struct DrawItem {
    std::string name;                   // node name, for reports
    glm::mat4 model{1.0f};              // world-from-mesh
    glm::mat4 normalMatrix{1.0f};       // inverse transpose of model (upper 3x3 used)
    int material = 0;                   // index into the material buffer (0 = glTF default)
    int baseColorTexture = -1;          // index into the uploaded textures, -1 = none
    int metallicRoughnessTexture = -1;  // the same (glTF: G = roughness, B = metallic factors)
    Origin origin = Origin::Virtual;
    // A specular object (mirror or glass): its pixels are shaded from the reflected / refracted
    // ray hits (GBuf_refl / GBuf_refr, Knecht 2013 Sec. 4.1), not from its own surface.
    bool specular = false;
    // Glass (transmission > 0, not a mirror): it transmits light in the shadow maps (coloured,
    // Fresnel- and absorption-weighted) instead of blocking it.
    bool transmissive = false;
    // A translucent object (Material::isTranslucent): its medium lets light through in the shadow
    // maps (GpuScene::medium(material)), attenuated by its optical thickness.
    bool translucent = false;
    // A rough metal (Material::isRoughReflector): specular, and its reflection is blurred by the
    // fuzzy-reflection filter (render/passes/fuzzy).
    bool roughReflector = false;
    // Rough glass (Material::isRoughGlass): what is seen through it is blurred by the same filter.
    bool roughGlass = false;
    GLint baseVertex = 0;
    GLuint firstIndex = 0;
    GLsizei indexCount = 0;
    BoundingSphere bounds;  // world
};

// The participating medium of a translucent material as the shadow maps need it (the light
// through the object, docs/translucency.md "Shadows"): sigma_t(x) = extinction * density(x_local),
// x_local = inverse(model) x, the density trilinear in a box of mesh-local units (1 everywhere
// without a grid).
struct GpuMedium {
    bool present = false;     // the material is translucent
    float extinction = 0.0f;  // 1/m at density 1
    glm::vec3 albedo{1.0f};   // single-scattering albedo
    float ior = 1.0f;
    bool hasDensity = false;
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // the density grid's box (mesh-local)
    glm::ivec3 gridSize{0};                      // samples per axis
    gl::Texture density;                         // R32F 3D, samples at the cell centres
};

struct SceneLight {
    std::string name;
    int type = kLightPoint;
    glm::vec3 position{0.0f};                // world (metres)
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // world unit vector the light shines along
    glm::vec3 radiantIntensity{1.0f};        // colour * intensity: W/sr (point, spot), W/m^2 (dir.)
    float range = 0.0f;                      // metres, 0 = infinite
    float cosOuter = 0.0f, cosInner = 1.0f;
    float outerAngle = 0.785398f;  // radians
    Origin origin = Origin::Virtual;
};

// The material and specular-draw tables as buffer textures of RGBA32F texels (their std430
// layout): llvmpipe reads a storage buffer lane by lane, a buffer texture with one gather per
// texel. A pass that reads the tables per pixel owns a set (a view only points at the buffers).
struct SceneTableViews {
    gl::Texture materials = gl::Texture::createBufferView("materials (texels)");
    gl::Texture specularDraws = gl::Texture::createBufferView("specular draws (texels)");
};

class GpuScene {
public:
    // Uploads everything; `surfacePoints` is the size of the ISM point pool. The environment map
    // (equirectangular, linear) is read from scene.environment.image when the scene has one;
    // throws mirage::FileError if it cannot be read.
    // `environmentLightSlots`: how many lights found in a live environment may be added to the
    // scene's lights (setEnvironmentLights); the lighting shaders are specialised for them too.
    // Throws mirage::Error when the scene's lights plus these exceed kMaxLights.
    explicit GpuScene(const Scene& scene, int surfacePoints = 16384, int environmentLightSlots = 0);

    const std::vector<DrawItem>& draws() const { return draws_; }
    // The scene's lights, then the environment's (setEnvironmentLights).
    const std::vector<SceneLight>& lights() const { return lights_; }
    int sceneLightCount() const { return sceneLightCount_; }
    // Replaces the lights found in the environment (REAL directional lights; at most
    // environmentLightSlots, MR_CHECK).
    void setEnvironmentLights(const std::vector<SceneLight>& lights);
    // GLSL #defines that specialise the lighting shaders to this scene's lights
    // (MIRAGE_MAX_SHADOW_FACES: 6 with a point light, 1 with spot / directional only, 0 without
    // lights; see lighting.glsl for why a constant loop bound matters on llvmpipe;
    // MIRAGE_GLASS_SHADOWS when some draw is glass or translucent: the shadow lookups read the
    // glass atlases).
    // withGlass false: without MIRAGE_GLASS_SHADOWS whatever the scene holds (the variant for
    // frames in which glass transmits no light).
    std::string lightingDefines(bool withGlass = true) const;
    // The shadow lookups' filter, compiled into every program that shades with lighting.glsl
    // (MIRAGE_SHADOW_PCF; RendererOptions::shadowFilter): a compile-time choice, because llvmpipe
    // pays for both sides of a branch on a uniform (measured: the bilinear frame 1.2x slower).
    // Set before the passes compile their programs.
    void setShadowPcf(bool pcf) { shadowPcf_ = pcf; }
    // The focused maps' pixel-footprint filter (ShadowOptions::pixelFootprint; off:
    // MIRAGE_SHADOW_NO_PIXEL_FOOTPRINT, the 2-texel PCF). Set before the passes compile.
    void setShadowPixelFootprint(bool on) { shadowPixelFootprint_ = on; }
    bool hasTransmissive() const;
    bool hasTranslucent() const;
    // Some draw has a base-colour / metallic-roughness texture (else the G-buffer skips the read).
    bool hasBaseColorTextures() const;
    bool hasMetallicRoughnessTextures() const;
    // The medium of GPU material index `material` (DrawItem::material); null unless translucent.
    const GpuMedium* medium(int material) const;
    // Indices into draws() of the specular (mirror / glass) items, in draw order.
    const std::vector<int>& specularDraws() const { return specularDraws_; }
    // How many specular draws are rough reflectors (fuzzy reflections) / rough glass.
    int roughReflectorCount() const;
    int roughGlassCount() const;
    const BoundingSphere& bounds() const { return bounds_; }
    bool hasVirtual() const;
    bool hasEnvironment() const { return hasEnvironment_; }
    Origin environmentOrigin() const { return environmentOrigin_; }
    // Radiance SH9 coefficients of the environment (linear RGB, intensity applied), in world axes.
    const std::vector<glm::vec3>& environmentSH() const { return envSH_; }
    int surfacePointCount() const { return surfacePointCount_; }
    bool surfacePointsHaveVirtual() const { return pointsHaveVirtual_; }
    float surfaceArea() const { return surfaceArea_; }  // m^2, all triangles

    // What updateTransforms() moved.
    struct TransformUpdate {
        int movedDraws = 0;   // draw items whose world matrix changed
        int movedLights = 0;  // scene lights whose position or direction changed
        // A translucent object would move: its voxel number map (TranslucencyPass) lies in the
        // world, so the renderer has to be built anew; nothing was changed.
        bool translucentMoved = false;
        bool any() const { return movedDraws > 0 || movedLights > 0; }
    };
    // Moves the uploaded scene to `scene`'s node transforms in place: `scene` is the scene this
    // was built from with other node matrices (a placement, an animation). Updates the draws'
    // world matrices and bounds, the specular table, the scene's lights and the ISM point pool
    // (each point keeps its place on its triangle; the pool's split between objects stays the
    // one of the first upload, so a scaled object keeps its share of points). Bumps
    // generation() when anything moved. Changes nothing when a translucent object would move
    // (TransformUpdate::translucentMoved). Throws mirage::Error, changing nothing, when `scene`
    // has other mesh or light instances than the uploaded scene, or a non-finite transform.
    TransformUpdate updateTransforms(const Scene& scene);
    // Bumped by every updateTransforms() that moved something: whatever was computed from where
    // the geometry stands (shadow maps, VPLs, ISMs, impostors) is stale when it changes.
    uint64_t generation() const { return generation_; }

    // Binds the vertex array and the material buffer; then drawItem() per item.
    void bindGeometry() const;
    // Binds the draw's base colour texture (or a white 1x1) to texture unit `unit`.
    void bindMaterialTextures(const DrawItem& d, GLuint unit) const;
    void drawItem(const DrawItem& d) const;
    const gl::Buffer& materialBuffer() const { return materials_; }
    const gl::Buffer& surfacePointBuffer() const { return points_; }
    // GpuSpecularDraw per specular slot (a single zero entry when there is none).
    const gl::Buffer& specularDrawBuffer() const { return specularBuffer_; }
    // Points `views` at the material and specular-draw tables and binds them to the two units,
    // for shaders that read them per pixel (common.glsl materialAt / specularDrawAt).
    void bindTableTexels(SceneTableViews& views, GLuint materialUnit,
                         GLuint specularDrawUnit) const;
    // The environment as an equirectangular linear RGBA16F texture (intensity applied; 1x1 black
    // without an environment). Direction l (world) -> u = 0.5 + atan2(l.x, -l.z) / 2pi after
    // undoing environmentRotation() about +Y, v = acos(l.y) / pi from the top row.
    const gl::Texture& environmentMap() const { return envMap_; }
    float environmentRotation() const { return envRotationRad_; }  // radians about +Y
    // Vertex buffer (GpuSceneVertex below, mesh-local) and uint32 index buffer of all draws, e.g.
    // for a pass that needs the geometry on the CPU once (impostor planes and boxes).
    const gl::Buffer& vertexBuffer() const { return vertices_; }
    const gl::Buffer& indexBuffer() const { return indices_; }

    // Radiance SH9 of an equirectangular linear RGB float image (CV_32FC3, top row = +Y up,
    // u = 0.5 looks down -Z, as in glTF/three.js). Exposed for tests.
    static std::vector<glm::vec3> projectEquirectToSH(const cv::Mat& linearRgb, float intensity,
                                                      double rotationYDeg);

private:
    // One primitive's slice of the shared vertex / index buffers (mesh-local bounding sphere).
    struct Range {
        GLint baseVertex;
        GLuint firstIndex;
        GLsizei count;
        int material;
        int texture;
        glm::vec3 center;
        float radius;
        bool specular;
        bool transmissive;
        bool roughReflector;
        bool roughGlass;
        bool translucent;
        int metallicRoughnessTexture = -1;
    };
    // The constructor's steps, in order.
    void uploadTextures(const Scene& scene);
    int uploadMaterials(const Scene& scene);
    std::vector<std::vector<Range>> uploadGeometry(const Scene& scene, int materialCount,
                                                   std::vector<GpuSceneVertex>& verts,
                                                   std::vector<uint32_t>& idx);
    void buildDraws(const Scene& scene, const std::vector<std::vector<Range>>& meshRanges);
    void buildLights(const Scene& scene);
    void uploadSpecularDraws();
    void buildSurfacePoints(const std::vector<GpuSceneVertex>& verts,
                            const std::vector<uint32_t>& idx, int surfacePoints);
    void uploadEnvironment(const Scene& scene);

    // Where a pool point lies: the draw and its mesh-local position (updateTransforms moves it).
    struct PointSource {
        int draw = 0;
        glm::vec3 local{0.0f};
    };
    // The lights of `scene` as buildLights() reads them (throws when there are too many).
    std::vector<SceneLight> readLights(const Scene& scene) const;

    std::vector<DrawItem> draws_;
    std::vector<BoundingSphere> localBounds_;  // per draw, mesh-local (scaled by the model)
    std::vector<int> instanceMeshes_;          // per mesh instance: its mesh (-1: not drawn)
    std::vector<int> drawInstances_;           // per draw: its mesh instance
    std::vector<PointSource> pointSources_;    // per ISM pool point
    uint64_t generation_ = 0;
    std::vector<SceneLight> lights_;
    int sceneLightCount_ = 0;
    int environmentLightSlots_ = 0;
    bool shadowPcf_ = false;
    bool shadowPixelFootprint_ = true;
    std::vector<int> specularDraws_;
    BoundingSphere bounds_;
    gl::Buffer vertices_, indices_, materials_, points_, specularBuffer_;
    gl::Texture envMap_;
    float envRotationRad_ = 0.0f;
    gl::VertexArray vao_;
    std::vector<GpuMedium> media_;       // per GPU material index (empty entries for the others)
    std::vector<gl::Texture> textures_;  // scene.textures: sRGB8_ALPHA8 or RGBA8, mipmapped
    gl::Texture white_;
    bool hasEnvironment_ = false;
    Origin environmentOrigin_ = Origin::Real;
    std::vector<glm::vec3> envSH_;
    int surfacePointCount_ = 0;
    bool pointsHaveVirtual_ = false;
    float surfaceArea_ = 0.0f;
};

// Draws scene items with their materials through a raster program that declares the per-draw
// uniforms `model`, `normalMatrix` (world), `materialIndex`, `origin` (kOriginReal /
// kOriginVirtual) and samples the base-colour map at kUnitBaseColorMap (the G-buffer, shadow
// and impostor-capture programs).
class MaterialDraw {
public:
    explicit MaterialDraw(const gl::Program& program);
    // Sets d's uniforms, binds its base-colour map and draws it. The program is in use and
    // GpuScene::bindGeometry() was called.
    void draw(const GpuScene& scene, const DrawItem& d) const;

private:
    GLint model_ = -1, normal_ = -1, material_ = -1, origin_ = -1;
};

}  // namespace mirage::render
