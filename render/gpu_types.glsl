// The GPU data layout of the real-time renderer, written once: valid GLSL (included by
// common.glsl) and valid C++ (render/GpuTypes.h includes it in namespace mirage::render with
// vec4 = glm::vec4 etc. and checks the sizes). std140 uniform blocks, std430 storage buffers; no
// bool (flags are ints); every field named (no packed vec4 components). Frames: world = glTF
// (metres, +Y up); camera = OpenCV (+X right, +Y down, +Z forward). Every radiance value is LINEAR
// RGB (W / (m^2 sr), with the scene's exposure convention that 1.0 is the camera's white).
#ifndef MIRAGE_GPU_TYPES_GLSL
#define MIRAGE_GPU_TYPES_GLSL

#include "bindings.glsl"

// A uniform block: in GLSL its members are globals of the shader; in C++ it is a struct.
#ifdef __cplusplus
#define MIRAGE_UNIFORM_BLOCK(blockName, structName, bindingPoint) struct alignas(16) structName
#else
#define MIRAGE_UNIFORM_BLOCK(blockName, structName, bindingPoint) \
    layout(std140, binding = bindingPoint) uniform blockName
#endif

const int kMaxLights = 8;
const int kMaxFocusMaps = 4;  // focused virtual-occluder maps per light (GpuLight::focusMaps)
// Hash cells of the world-space photon grid (a power of two; PhotonGridPass).
const int kPhotonGridCells = 65536;
// Nested subsets of the photon map within each grid bucket (PhotonGridPass, caustic.glsl
// photonLevel): level l holds the photon texels on the lattice of stride 2^(levels - 1 - l) that
// no coarser lattice holds, so that a capped gather reads whole levels, a set of photons fixed by
// their texels and not by the order the grid's scatter stored them in.
const int kPhotonGridLevels = 5;
// Counters (and first indices) of the grid: one per bucket and level.
const int kPhotonGridSlots = kPhotonGridCells * kPhotonGridLevels;
const int kLightPoint = 0;
const int kLightSpot = 1;
const int kLightDirectional = 2;
const int kOriginNone = 0;
const int kOriginReal = 1;
const int kOriginVirtual = 2;
// GpuSpecularDraw::rough: which surfaces the fuzzy filter (render/passes/fuzzy) blurs.
const int kRoughNone = 0;   // a mirror or smooth glass
const int kRoughMetal = 1;  // Material::isRoughReflector: the reflection
const int kRoughGlass = 2;  // Material::isRoughGlass: what is seen through it (and reflected)

struct GpuLight {
    mat4 viewProj[6];       // world -> light clip space, one per shadow layer (spot/dir use [0])
    vec3 position;          // world (metres); directional: the eye of its ortho frustum
    float range;            // metres (0 = infinite)
    vec3 direction;         // unit direction the light shines along (world)
    int type;               // kLightPoint, kLightSpot or kLightDirectional
    vec3 radiantIntensity;  // colour * intensity: W/sr (point, spot) or W/m^2 (directional)
    float frustumSize;      // tan(half fov) (spot), 1 (point), ortho half extent (m, dir.)
    float cosOuter;         // spot cone: cos(outer angle), cos(inner angle), and the falloff
    float cosInner;         // clamp(cos * coneScale + coneOffset, 0, 1)^2
    float coneScale;
    float coneOffset;
    int firstShadowLayer;  // first layer in the shadow atlases
    int shadowLayers;      // layer count (0 = no shadow map)
    int realOnlyMap;       // 1 if the real-only map differs from the all-occluder map
    int isReal;            // 1 if the light is real
    int glassShadow;       // 1 if glass transmits this light (its ShadowGlass layers are drawn)
    // Focused virtual-occluder maps (ShadowPass): when > 0, the virtual occluders are in
    // focusMaps maps of their own, each fitted to a group of them (all-occluder atlas layers
    // firstFocusLayer.., rendered through focusViewProj[k]), and the light's layers of the
    // real-only atlas hold the real ones.
    int focusMaps;
    int firstFocusLayer;
    // 1 if some virtual occluders are in no focused map (glass that this light's caustics carry
    // the light through): they are in the light's own layers of the all-occluder atlas.
    int unfocusedVirtual;
    // Per focused map: tan(half fov) (point, spot) or the orthographic half extent (m, dir.).
    vec4 focusFrustumSize;
    mat4 focusViewProj[kMaxFocusMaps];  // world -> clip of each focused map
};

MIRAGE_UNIFORM_BLOCK(FrameBlock, GpuFrame, kBindingFrame) {
    mat4 viewMatrix;    // world -> OpenCV camera
    mat4 projMatrix;    // OpenCV camera -> GL clip (render canvas, undistorted)
    mat4 viewProj;
    mat4 prevViewProj;  // last frame's, for temporal reprojection
    vec4 cameraPos;     // xyz world (metres)
    vec4 prevCameraPos;  // xyz world (metres)
    vec4 canvas;         // render canvas width, height, 1/width, 1/height (pixels)
    int lightCount;
    int vplCount;
    int interleave;  // K: the interleaved-sampling tile size
    int frameIndex;
    int envOrigin;       // environment light: kOriginNone (off), kOriginReal, kOriginVirtual
    int historyValid;    // 1 if the frame keeps temporal history (FrameContext::historyValid)
    int ismTileSize;     // texels per side of one VPL's imperfect shadow map tile
    int ismTilesPerRow;  // tiles per row of the ISM atlas
    float vplDistanceClamp;  // metres: VPL distance below this is clamped
    float shadowBias;        // metres: RendererOptions::shadowBias, constant (lighting.glsl adds
                             // the texel footprint)
    float temporalBlend;     // history weight of the VPL lighting (0 = off)
    float ismPointsPerVpl;
    // Rendered linear radiance -> camera linear units, per channel (R, G, B): the exposure and
    // white balance (RendererOptions::composite.exposure, or this frame's estimate: passes/exposure).
    vec3 exposure;
    float alphaMax;     // cap of alpha = CI / L_r
    float alphaFadeLr;  // L_r below which alpha fades to 1
    float framePad0;    // std140: the block is a multiple of 16 bytes
    float framePad1;
    float framePad2;
};

// The environment light (kBindingEnvironment): written by the environment pass
// (render/passes/environment) from the scene's static map or, per environment-camera frame, by
// environment_sh.comp (which declares the same layout as a std430 storage block: vec4 arrays and
// scalars have the same offsets in both). Read by every shader that lights with the environment.
MIRAGE_UNIFORM_BLOCK(EnvironmentBlock, GpuEnvironment, kBindingEnvironment) {
    vec4 envSH[9];          // radiance SH9 (rgb, linear, intensity / gain applied), world axes
    float envRotation;      // environment map rotation about +Y (radians); 0 for a live map
    float envSeenFraction;  // solid-angle fraction of the live map the camera saw (1: static)
    float envPad0;
    float envPad1;
};

MIRAGE_UNIFORM_BLOCK(LightBlock, GpuLightBlock, kBindingLights) {
    GpuLight lights[kMaxLights];
};

// One virtual point light (std430, kBindingVpls).
struct GpuVpl {
    vec3 position;  // world position of the surface point q (metres)
    int isReal;     // 1 if the light and q are real, else 0
    vec3 normal;    // unit normal at q (facing the light)
    int valid;      // 1 valid, 0 unused slot
    vec3 flux;      // reflected power (W) the VPL emits (cosine lobe)
    float pad0;     // std430: vec3 fields start at 16-byte offsets
    vec3 tangent;   // unit tangent; with cross(normal, tangent): the ISM paraboloid frame
    float pad1;
};

// Materials (std430, kBindingMaterials): glTF metallic-roughness with KHR_materials_transmission,
// _ior and _volume (docs/scene.md).
struct GpuMaterial {
    vec4 baseColor;             // linear RGBA
    vec3 emissive;              // linear emitted radiance
    float roughness;            // perceptual roughness, 0..1
    float metallic;             // 0..1
    float transmission;         // 0..1
    float ior;                  // index of refraction (> 0)
    float attenuationDistance;  // metres light travels inside before falling to
                                // attenuationColor (Beer-Lambert); 0 = no absorption
    vec3 attenuationColor;      // linear, 0..1
    int mirror;                 // 1 for a perfect mirror (docs/scene.md), else 0
    float thickness;            // KHR_materials_volume thickness (mesh units, informational)
    int specular;               // 1: a specular object here (mirror, rough reflector, glass)
    int translucent;            // 1: a participating medium (docs/translucency.md), else 0
    float pad2;
};

// Specular draw table (std430, kBindingSpecularDraws), indexed by specular slot (GpuScene::
// specularDraws() order). The G-buffer stores slot + 1 in gEmissive.a (0 = not specular).
struct GpuSpecularDraw {
    vec3 centre;    // world bounding sphere: centre, radius (metres)
    float radius;
    int material;   // index into the material table
    int origin;     // kOriginReal / kOriginVirtual
    int drawIndex;       // index into GpuScene::draws()
    int rough;           // kRoughNone, kRoughMetal or kRoughGlass (the fuzzy filter's input)
};

// One photon of the world-space photon grid (std430, kBindingPhotons; render/passes/caustic
// photon_grid.comp builds it, the specular light pass gathers it): the photon's receiver hit and
// its disc kernel's radius, its power for L_rv and for L_r (Eqs. 12-14, as the caustic splat).
struct GpuPhoton {
    vec3 position;  // world receiver hit (metres)
    float radius;   // kernel radius (metres): causticQuadScale x the photon spacing, capped
    vec3 powerRv;   // W: power x visibility through all occluders
    int normal;     // the receiver's unit normal facing the photon: packSnorm2x16 (octahedral)
    vec3 powerR;    // W: power x real-path visibility (0 unless light and object are real)
    float pad0;
};

// A surface sample for imperfect shadow maps (std430, kBindingIsmPoints).
struct GpuSurfacePoint {
    vec3 position;  // world (metres)
    int isReal;     // 1 if the geometry is real, 0 if virtual
};

#endif
