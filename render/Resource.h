#pragma once
// The named resources of a frame (render/FrameGraph.h): every texture and buffer one pass hands
// to another, each attachment on its own. Buffers named *Rv / *R hold linear HDR radiance
// (RGBA16F, rgb used) for L_rv (real + virtual) and L_r (real only).
#include <epoxy/gl.h>

namespace mirage::render {

enum class Resource {
    // Imported from outside the frame.
    CameraImage,          // the camera frame, sRGB8 texture sampled as linear (camera image size)
    SceneEnvironmentMap,  // the scene's static equirectangular map, linear (1x1 black: none)
    EnvironmentCamera,    // the environment (fish-eye) camera's newest frame, sRGB8; imported only
                          // while a live environment is set (Renderer::setEnvironmentCamera)
    // The environment light (render/passes/environment): the map every environment lookup uses
    // (equirectangular RGBA16F, rgb linear radiance, a = 1 where the camera saw the direction,
    // 0 where the unseen part was filled in; mip-mapped when live) and its SH9 (EnvironmentBlock).
    EnvironmentMap,
    EnvironmentLight,
    // Primary G-buffer (canvas size).
    GBufferPosition,  // xyz world (m), w = origin (ORIGIN_REAL / ORIGIN_VIRTUAL, 0 = empty)
    GBufferNormal,    // xyz unit world normal, w = roughness
    GBufferAlbedo,    // rgb linear base colour, a = metallic
    GBufferEmissive,  // rgb linear emitted radiance, a = specular slot + 1 (0 = not specular,
                      // -1 = translucent)
    // Per light layer (shadow atlas: shadowMapSize^2 x layers).
    ShadowMaps,               // distance to the nearest occluder (m), all geometry
    ShadowMapsReal,           // the same with real occluders only (aliases ShadowMaps where equal)
    ShadowGlass,              // glass between light and texel: rgb = sum of ln(transmittance)
                              // terms (Fresnel, colour, Beer-Lambert), a = nearest glass (m)
    ShadowGlassReal,          // the same with real glass only (aliases ShadowGlass where equal)
    RsmFlux,                  // reflective shadow map: rgb reflected intensity, a = real
    RsmNormal,                // xyz normal facing the light
    RsmPosition,              // xyz world (m), w = 1 where covered
    Vpls,                     // SSBO of GpuVpl (vplCount entries)
    ImperfectShadowMaps,      // r32ui atlas, one paraboloid tile per VPL (all occluders)
    ImperfectShadowMapsReal,  // the same with real points only (aliases the first without them)
    // Translucent objects (voxel number map, docs/translucency.md): SSBOs of the first
    // translucent object. TranslucentGrid: header + the voxel number of every grid cell
    // (persistent, uploaded once); TranslucentRadiance: per surface voxel the radiance
    // (1/pi) a_eff sum E A c e^{-tau} leaving it before the exit F_t, S vec4 for L_rv then S
    // vec4 for L_r.
    TranslucentGrid,
    TranslucentRadiance,
    DirectRv,  // direct + environment + emission (canvas size): LRv itself in frames without VPL
               // light, else written apart only with RendererOptions::keepDirectLight
    DirectR,
    IndirectRv,  // interleaved VPL gather, deinterleaved and unfiltered (gather size)
    IndirectR,
    GiHistoryRv,  // filtered indirect light at gather resolution, a = camera distance (m); kept
    GiHistoryR,   // by gifilter as the next frame's temporal history (persistent)
    GatherLight,  // the filtered indirect light packed per gather pixel for the upsample: L_rv,
                  // L_r as halves, camera-frame depth as a half, 8-bit oct normal (RGBA32UI)
    LRv,          // the two GI solutions: direct + filtered, upsampled indirect (canvas size);
    LR,           // LRv.a = the pixel's origin (ORIGIN_*; 0 on the specular pixels it skips)
    // Reflected-scene impostors of the specular objects' surroundings (persistent: built once
    // per scene; render/passes/impostor/trace.glsl reads them).
    ImpostorCubePosition,  // G-buffer cube maps, 12 layers per specular object
    ImpostorCubeNormal,
    ImpostorCubeAlbedo,
    ImpostorCubeEmissive,
    ImpostorDepth,  // depth impostors, one layer each
    ImpostorNormal,
    ImpostorAlbedo,
    ImpostorEmissive,
    ImpostorRecords,  // SSBO of GpuImpostor
    ImpostorObjects,  // SSBO: header + GpuImpostorObject per specular object
    // Specular objects (Knecht 2013 Sec. 4.1 / 5.1; docs/specular.md), canvas size.
    BackFacePosition,    // specular objects' back faces: xyz world, w = slot + 1
    BackFaceNormal,      // xyz outward unit normal
    RealSurfaces,        // nearest REAL surface per pixel: xyz world, w = origin
    ReflectionGBuffer,   // GBuf_refl: reflected-ray hit position + origin (or the ray on a miss)
    ReflectionNormal,    // xyz normal, w = roughness
    ReflectionAlbedo,    // rgb base colour, a = metallic
    ReflectionEmissive,  // rgb emission, a = specular-pixel flag
    ReflectionWeight,    // rgb Fresnel weight, a = distance inside
    RefractionGBuffer,   // GBuf_refr: two-interface refracted-ray hits (Wyman 2005), as above
    RefractionNormal,
    RefractionAlbedo,
    RefractionEmissive,
    RefractionWeight,
    SpecularMask,  // depth 0 on specular pixels, 1 elsewhere: the passes that shade only
                   // those test against it (early depth test skips the rest)
    // L'_rv (Eq. 3, Fresnel-weighted), L'_r (Eq. 4) and the reflection's share of L'_r, after
    // temporal smoothing; the specular light pass keeps them as the next frame's history
    // (persistent, RGBA32F). SpecularRv.a = the specular surface's camera distance (m, 0: none);
    // SpecularR.a and SpecularRReflection.a = y and z of the refracted ray's hit (world, m),
    // whose x and the reflected ray's hit the pass keeps beside them (specular_light.frag).
    SpecularRv,
    SpecularR,
    SpecularRReflection,
    Lenv,  // L_env: environment seen where a ray leaves the modelled scene
    // Fuzzy reflections of rough metals (render/passes/fuzzy): the four above filtered over each
    // rough pixel's reflection cone, and the filtered video term of the reflection (rgb camera
    // units: eta1 CI_r(p_refl) or the rendered real share; a = 1 on a rough-metal pixel).
    FuzzySpecularRv,
    FuzzySpecularR,
    FuzzySpecularRReflection,
    FuzzyLenv,
    FuzzyReflectionVideo,
    // Rough refraction (render/passes/rough, docs/specular.md): the same five buffers with the
    // rough-glass pixels replaced by the LEAN or GSR lobe's blurred lookups (a = 1 in
    // RoughVideo on a filtered pixel); every other pixel passes the fuzzy pass's (or the sharp)
    // values through.
    RoughSpecularRv,
    RoughSpecularR,
    RoughSpecularRReflection,
    RoughLenv,
    RoughVideo,
    // Caustics (Knecht 2013 Sec. 5.2; docs/caustics.md). Photon G-buffers, one layer per caustic
    // spot light (causticMapSize^2): per texel of the specular objects seen from the light, the
    // receiver hit of the reflected / refracted photon (xyz world; w = 4 x hit origin + the
    // photon's real-path visibility, 0 = no photon) and its power (rgb W, a = visibility from
    // the light through all occluders).
    PhotonHitRefl,
    PhotonPowerRefl,
    PhotonHitRefr,
    PhotonPowerRefr,
    // The receiver of each photon for reflected / refracted VPLs: packHalf2x16 of (normal.xy),
    // (normal.z, diffuse albedo r), (albedo g, b); the normal faces the arriving photon.
    PhotonSurfaceRefl,
    PhotonSurfaceRefr,
    // The world-space photon grid (render/passes/caustic PhotonGridPass): a hashed uniform grid
    // of the photons' receiver hits, for the caustics seen in reflections and refractions.
    // PhotonGrid: uint per hash cell (kPhotonGridCells counts, then kPhotonGridCells + 1 first
    // indices); PhotonRecords: GpuPhoton per photon, sorted by cell.
    PhotonGrid,
    PhotonRecords,
    CausticRv,  // caustic radiance reflected by the receiver towards the camera (Eq. 12)
    CausticR,   // the same for L_r: light, specular object and receiver real (Eqs. 13-14)
    // The caustic irradiance (rgb W/m^2, before the receiver's albedo) for L_rv / L_r after
    // temporal smoothing, a = camera distance (m) of the receiver (0: none); kept by the
    // caustic pass as the next frame's temporal history (persistent, canvas size).
    CausticHistoryRv,
    CausticHistoryR,
    Composite,      // the output (camera image size): linear RGBA32F, a = coverage
    CompositeSrgb,  // the same, sRGB8
    Count
};
inline constexpr int kResourceCount = int(Resource::Count);

const char* resourceName(Resource r);

// How a resource's size follows the frame (checked when a pass publishes a texture).
enum class SizeRule {
    Canvas,       // the render canvas (CameraProjection::canvasWidth/Height)
    Camera,       // the camera image
    Gather,       // canvas / RendererOptions::indirectScale per axis, rounded up
    GatherTiles,  // Gather rounded up to a multiple of the interleave K (deinterleaved tiles)
    ShadowAtlas,  // shadowMapSize^2, one layer per shadow layer of the frame plan
    IsmAtlas,     // tilesPerRow(vplCount) * ismTileSize, square
    Impostor,     // impostorResolution^2, layers per specular object / impostor
    CausticMap,   // causticMapSize^2, one layer per caustic spot light of the frame plan
    Vpl,          // buffer: vplCount entries
    Scene,        // sized by the scene (imports, impostor tables)
};
const char* sizeRuleName(SizeRule s);

// GL internal format as text ("RGBA16F"; buffers: "SSBO").
const char* formatName(GLenum format);

}  // namespace mirage::render
