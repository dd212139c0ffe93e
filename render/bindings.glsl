// Every texture unit, image unit and buffer binding point of the real-time renderer, named once.
// Valid GLSL and valid C++: shaders use the names in layout(binding = ...) (GLSL 4.40 constant
// expressions), passes in glBindTextureUnit / glBindImageTexture / glBindBufferBase
// (render/GpuTypes.h includes this file in namespace mirage::render). A unit's number only has to
// be unique among what one program samples; passes therefore reuse the low units.
#ifndef MIRAGE_BINDINGS_GLSL
#define MIRAGE_BINDINGS_GLSL

// Uniform / storage buffer binding points.
const int kBindingFrame = 0;          // FrameBlock (std140)
const int kBindingLights = 1;         // LightBlock (std140)
const int kBindingVpls = 2;           // GpuVpl[] (std430)
const int kBindingMaterials = 3;      // GpuMaterial[]
const int kBindingIsmPoints = 4;      // GpuSurfacePoint[] (ism.comp)
const int kBindingSpecularDraws = 5;  // GpuSpecularDraw[]
const int kBindingEnvironment = 8;      // EnvironmentBlock (std140; environment_sh.comp writes it)
// Translucent objects (render/passes/translucency, direct.frag), std430.
const int kBindingTranslucentVoxels = 9;       // per surface voxel: 2 vec4 (see translucency.comp)
const int kBindingTranslucentLut = 10;         // tau LUT, S x S half floats, 2 per uint
const int kBindingTranslucentIrradiance = 11;  // E per surface voxel: S vec4 (L_rv), S vec4 (L_r)
const int kBindingTranslucentRadiance = 12;    // same layout: radiance leaving each voxel
const int kBindingTranslucentGrid = 13;        // header + voxel number per grid cell
// The world-space photon grid (passes/caustic photon_grid.comp; specular_light.frag), std430.
const int kBindingPhotonGrid = 14;  // uint per hash cell: count (scratch), then the first photon
const int kBindingPhotons = 15;     // GpuPhoton[], sorted by cell
// Uniform block over the first 32 bytes of the impostor objects buffer (trace.glsl).
const int kBindingImpostorHeader = 16;  // GpuImpostorHeader (std140 = its std430 layout)
const int kBindingQueryRays = 4;        // query.comp (offline impostor queries, outside frames)
const int kBindingQueryHits = 5;

// Material textures of scene draws (gbuffer, shadow, impostor capture).
const int kUnitBaseColorMap = 7;
// The metallic-roughness texture (linear; G scales roughness, B metallic; white without one):
// bound with every material draw, so above every pass's own units.
const int kUnitMetallicRoughnessMap = 31;
// shadow.frag: the glass layer of the light layer being rendered (RSM flux behind glass).
const int kUnitShadowGlassLayer = 8;
// shadow_glass.frag: the density grid of the translucent draw being rendered.
const int kUnitShadowDensity = 9;

// specular_mask.frag (passes/gbuffer): the G-buffer's emissive target (its specular slot).
const int kUnitMaskEmissive = 0;

// direct.frag
const int kUnitDirectPosition = 0;
const int kUnitDirectNormal = 1;
const int kUnitDirectAlbedo = 2;
const int kUnitDirectEmissive = 3;
const int kUnitDirectShadowAll = 4;
const int kUnitDirectShadowReal = 5;
const int kUnitDirectGlassAll = 6;  // ShadowGlass / ShadowGlassReal (glass in the shadow maps)
const int kUnitDirectGlassReal = 7;
const int kUnitDirectGatherLight = 8;  // filter.frag's packed gather pixels (gi_upsample.glsl)
const int kUnitDirectBackPosition = 9;  // the back faces (rough_transmission.glsl)
const int kUnitDirectBackNormal = 10;

// translucency.comp: the shadow atlases
const int kUnitTranslucencyShadowAll = 0;
const int kUnitTranslucencyShadowReal = 1;
const int kUnitTranslucencyGlassAll = 2;
const int kUnitTranslucencyGlassReal = 3;

// environment pass: fisheye_to_equirect.frag, environment_sh.comp
const int kUnitEnvFisheye = 0;   // the environment camera's frame (sRGB8, sampled linear)
const int kUnitEnvShSource = 0;  // the equirectangular map (a small mip level)

// vpl.comp
const int kUnitVplRsmFlux = 0;
const int kUnitVplRsmNormal = 1;
const int kUnitVplRsmPosition = 2;
const int kUnitVplPhotonHitRefl = 3;  // photon G-buffers: VPLs that follow a specular bounce
const int kUnitVplPhotonPowerRefl = 4;
const int kUnitVplPhotonSurfaceRefl = 5;
const int kUnitVplPhotonHitRefr = 6;
const int kUnitVplPhotonPowerRefr = 7;
const int kUnitVplPhotonSurfaceRefr = 8;

// ism.comp (image units)
const int kImageIsmAll = 0;
const int kImageIsmReal = 1;
// ism_pullpush.comp: an atlas (kImageIsmAll's unit) and two levels of the hole-filling pyramid.
const int kImageIsmPyramidSrc = 1;
const int kImageIsmPyramidDst = 2;

// indirect.frag
const int kUnitIndirectPosition = 0;
const int kUnitIndirectNormal = 1;
const int kUnitIndirectAlbedo = 2;
const int kUnitIndirectIsmAll = 3;
const int kUnitIndirectIsmReal = 4;
const int kUnitIndirectVpls = 5;  // the VPL buffer as RGBA32F texels (common.glsl vplAt)

// gifilter: filter.frag (gather resolution)
const int kUnitFilterPosition = 0;
const int kUnitFilterNormal = 1;
const int kUnitFilterIndirectRv = 2;
const int kUnitFilterIndirectR = 3;
const int kUnitFilterHistoryRv = 4;
const int kUnitFilterHistoryR = 5;

// specular_gbuffer.frag
const int kUnitSpecGbufPosition = 0;
const int kUnitSpecGbufNormal = 1;
const int kUnitSpecGbufEmissive = 2;
const int kUnitSpecGbufBackPosition = 3;
const int kUnitSpecGbufBackNormal = 4;
const int kUnitSpecGbufMaterials = 5;      // samplerBuffer: GpuMaterial[] (common.glsl materialAt)
const int kUnitSpecGbufSpecularDraws = 6;  // samplerBuffer: GpuSpecularDraw[] (specularDrawAt)
// specular_trace_fill.frag (the half-resolution trace's fill, RendererOptions::specular.
// halfResolutionTrace): the half-resolution GBuf_refl then GBuf_refr (5 targets each), and the
// primary G-buffer's position, normal and emissive (a = specular slot + 1).
const int kUnitSpecFillHalfFirst = 0;  // .. + 9
const int kUnitSpecFillPosition = 10;
const int kUnitSpecFillNormal = 11;
const int kUnitSpecFillEmissive = 12;

// specular_light.frag: GBuf_refl then GBuf_refr (position, normal, albedo, emissive, weight)
const int kUnitSpecLightReflFirst = 0;  // .. + 4
const int kUnitSpecLightRefrFirst = 5;  // .. + 4
const int kUnitSpecLightShadowAll = 10;
const int kUnitSpecLightShadowReal = 11;
const int kUnitSpecLightIsmAll = 12;
const int kUnitSpecLightIsmReal = 13;
const int kUnitSpecLightPosition = 14;
const int kUnitEnvironmentMap = 15;
const int kUnitSpecLightGlassAll = 24;  // above the impostor units
const int kUnitSpecLightGlassReal = 25;
const int kUnitSpecLightHistoryRv = 26;    // last frame's smoothed L'_rv, L'_r and reflection
const int kUnitSpecLightHistoryR = 27;     // share (temporal history)
const int kUnitSpecLightHistoryRRefl = 28;
const int kUnitSpecLightHistoryHits = 29;  // the hits the history was lit at
const int kUnitSpecLightVpls = 30;         // the VPL buffer as RGBA32F texels (common.glsl vplAt)
// specular_resolve.frag (the half-resolution upsample): GBuf_refl / GBuf_refr at the units above,
// the half-resolution hit radiance (reflected L_rv, L_r, refracted L_rv, L_r) and the primary
// G-buffer's emissive (a = specular slot + 1).
const int kUnitSpecResolveHalfFirst = 10;  // .. + 3
const int kUnitSpecResolveSlot = 14;

// photon_gbuffer.frag (passes/caustic): the light's back faces of the specular objects and the
// shadow maps (light visibility of the photon's first surface); trace.glsl's units above.
const int kUnitPhotonBackPosition = 0;
const int kUnitPhotonBackNormal = 1;
const int kUnitPhotonShadowAll = 2;
const int kUnitPhotonShadowReal = 3;
const int kUnitPhotonMaterials = 4;      // samplerBuffer: GpuMaterial[] (common.glsl materialAt)
const int kUnitPhotonSpecularDraws = 5;  // samplerBuffer: GpuSpecularDraw[] (specularDrawAt)

// caustic_splat.comp: the photon G-buffers and the primary G-buffer; the fixed-point
// accumulation image (6 layers: L_rv rgb, L_r rgb irradiance).
const int kUnitSplatReflHit = 0;
const int kUnitSplatReflPower = 1;
const int kUnitSplatRefrHit = 2;
const int kUnitSplatRefrPower = 3;
const int kUnitSplatPosition = 4;
const int kUnitSplatNormal = 5;
const int kUnitSplatEmissive = 6;
const int kImageCausticAccum = 0;
// The caustic's canvas tiles (the splat marks them, the resolve draws them: CausticTiles.h):
// kCausticTileSize x kCausticTileSize pixels.
const int kCausticTileSize = 8;
// The canvas tiles a photon's kernel reaches (r32ui, 1 = reached).
const int kImageCausticPhotonTiles = 1;
// photon_grid.comp: the photon G-buffers (receiver hits, powers, receiver normals)
const int kUnitGridReflHit = 0;
const int kUnitGridReflPower = 1;
const int kUnitGridReflSurface = 2;
const int kUnitGridRefrHit = 3;
const int kUnitGridRefrPower = 4;
const int kUnitGridRefrSurface = 5;
// caustic_resolve.frag
const int kUnitResolveAccum = 0;
const int kUnitResolvePosition = 1;
const int kUnitResolveAlbedo = 2;
const int kUnitResolveEmissive = 3;
const int kUnitResolveHistoryRv = 4;  // last frame's caustic irradiance (temporal history)
const int kUnitResolveHistoryR = 5;
// Per tile of this frame's history (r32ui images, the next frame's choice of tiles): 1 where
// it is not 0; the nearest and farthest camera distance resolved there.
const int kImageCausticHistoryTiles = 0;
const int kImageCausticHistoryNear = 1;
const int kImageCausticHistoryFar = 2;

// composite.frag
const int kUnitCompositeCamera = 0;
const int kUnitCompositeLRv = 1;
const int kUnitCompositeLR = 2;
const int kUnitCompositePosition = 3;
const int kUnitCompositeRemap = 4;
const int kUnitCompositeEmissive = 5;
const int kUnitCompositeReflPosition = 6;
const int kUnitCompositeRefrPosition = 7;
const int kUnitCompositeReflWeight = 8;
const int kUnitCompositeRefrWeight = 9;
const int kUnitCompositeSpecRv = 10;
const int kUnitCompositeSpecR = 11;
const int kUnitCompositeSpecRRefl = 12;
const int kUnitCompositeLenv = 13;
const int kUnitCompositeRealSurfaces = 14;
const int kUnitCompositeCanvasToCamera = 15;
const int kUnitCompositeCausticRv = 16;  // CausticRv / CausticR (black without caustics)
const int kUnitCompositeCausticR = 17;
const int kUnitCompositeFuzzyRv = 18;  // the fuzzy pass's filtered buffers (rough metals)
const int kUnitCompositeFuzzyR = 19;
const int kUnitCompositeFuzzyRRefl = 20;
const int kUnitCompositeFuzzyLenv = 21;
const int kUnitCompositeFuzzyVideo = 22;
const int kUnitCompositeNormal = 23;  // the G-buffer normal (translucent pixels' reflection)
// The refracted path's second exit (passes/specular/second_exit.glsl) on glass pixels: the
// back-face buffer and the environment map (with the units above: the G-buffer's position,
// normal and emissive, the real surfaces).
const int kUnitCompositeBackPosition = 24;
const int kUnitCompositeBackNormal = 25;
const int kUnitCompositeEnvironment = 26;

// passes/exposure: exposure_samples.frag
const int kUnitExposureCamera = 0;  // the camera frame (sRGB8, sampled linear)
const int kUnitExposureLR = 1;
const int kUnitExposureCausticR = 2;  // black without caustics
const int kUnitExposurePosition = 3;  // w = origin
const int kUnitExposureEmissive = 4;  // a = specular slot + 1
const int kUnitExposureCanvasToCamera = 5;

// passes/motionblur: motion_velocity.frag, motion_tiles.frag, motion_neighbours.frag,
// motion_gather.frag
const int kUnitMotionPosition = 0;   // the G-buffer position (canvas), w = origin
const int kUnitMotionRemap = 1;      // camera pixel -> canvas pixel (lens distortion)
const int kUnitMotionVelocity = 2;   // MotionVelocity: rg half motion (px), b depth (m)
const int kUnitMotionTiles = 3;      // tile / neighbourhood maxima
const int kUnitMotionComposite = 4;  // the composite (linear, a = coverage)
const int kUnitMotionFootage = 5;    // CompositeFootage: rgb footage part, a = layer

// passes/aa: antialias.frag
const int kUnitAntialiasComposite = 0;  // the composite, linear RGBA32F (bilinear sampler)
const int kUnitAntialiasCamera = 1;     // the camera frame (sRGB8, sampled linear, bilinear)

// passes/grain: grain_samples.frag, grain_apply.frag
const int kUnitGrainCamera = 0;  // the camera frame (sRGB8, sampled linear)
const int kUnitGrainLR = 1;
const int kUnitGrainCausticR = 2;  // black without caustics
const int kUnitGrainPosition = 3;  // w = origin
const int kUnitGrainEmissive = 4;  // a = specular slot + 1
const int kUnitGrainCanvasToCamera = 5;
const int kUnitGrainComposite = 6;  // the composite (linear, a = coverage)
const int kUnitGrainFootageShare = 7;  // the composite's footage share (CompositePass)

// passes/fuzzy: fuzzy_resolve.frag and fuzzy_filter.frag (separable, one program per pass)
const int kUnitFuzzyPosition = 0;
const int kUnitFuzzyEmissive = 1;
const int kUnitFuzzyReflHit = 2;
const int kUnitFuzzyReflWeight = 3;
const int kUnitFuzzyCamera = 4;
const int kUnitFuzzyRealSurfaces = 5;
const int kUnitFuzzyCanvasToCamera = 6;
const int kUnitFuzzySpecRRefl = 7;
const int kUnitFuzzyInputFirst = 8;  // .. + 4: L'_rv, L'_r, reflection share, L_env, video
const int kUnitFuzzyRefrHit = 13;
const int kUnitFuzzyRefrWeight = 14;
const int kUnitFuzzySpecR = 15;
const int kUnitFuzzyNormal = 16;

// passes/rough: rough_prefilter.frag, rough_refraction.frag
const int kUnitRoughPosition = 0;
const int kUnitRoughNormal = 1;
const int kUnitRoughEmissive = 2;
const int kUnitRoughReflHit = 3;
const int kUnitRoughReflWeight = 4;
const int kUnitRoughRefrHit = 5;
const int kUnitRoughRefrWeight = 6;
const int kUnitRoughRealSurfaces = 7;
const int kUnitRoughCanvasToCamera = 8;
const int kUnitRoughCamera = 9;             // the camera frame (sRGB8, sampled linear)
const int kUnitRoughLeanFirst = 12;         // .. + 2: LEAN moment chains of the back-face normals
const int kUnitRoughPrefilteredFirst = 15;  // .. + 4: coverage-weighted L'_rv, L'_r, reflection
                                            // share, L_env, video term
const int kUnitRoughInputFirst = 20;  // .. + 4: what passes through (fuzzy's or the sharp ones)
const int kUnitRoughBackPosition = 25;
const int kUnitRoughBackNormal = 26;
const int kUnitRoughSpecFirst = 27;  // .. + 3: L'_rv, L'_r, reflection share, L_env (prefilter)

// Reflected-scene impostors (trace.glsl): the ONLY units traceSurroundings() uses, above every
// pass's own units so a consumer shader can sample both.
const int kUnitImpostorCubePosition = 16;  // sampler2DArray, RGBA32F
const int kUnitImpostorCubeNormal = 17;    // sampler2DArray, RGBA16F
const int kUnitImpostorCubeAlbedo = 18;    // sampler2DArray, RGBA8
const int kUnitImpostorCubeEmissive = 19;  // sampler2DArray, RGBA16F
const int kUnitImpostorDepth = 20;         // sampler2DArray, RG32F
const int kUnitImpostorNormal = 21;        // sampler2DArray, RGBA16F
const int kUnitImpostorAlbedo = 22;        // sampler2DArray, RGBA8
const int kUnitImpostorEmissive = 23;      // sampler2DArray, RGBA16F
const int kUnitImpostorRecords = 24;       // samplerBuffer, RGBA32F: GpuImpostor[] (5 texels each)
const int kUnitImpostorObjects = 25;       // samplerBuffer, RGBA32F: header, GpuImpostorObject[]

#endif
