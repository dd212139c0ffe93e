#pragma once
// Options of translucent objects (render/passes/translucency, docs/translucency.md).
#include <string>

#include "render/PassOptions.h"

namespace mirage::render {

struct TranslucencyOptions {
    // A voxel number map per translucent object (up to 8), vnmResolution voxels along its longest
    // side (the tau LUT grows with the square of the surface voxels, ~36 n^4 bytes for a cube),
    // its LUT cached in vnmCacheDir (empty: precomputed every time a renderer is created). false:
    // translucent objects are drawn as opaque surfaces of their base colour.
    bool enabled = true;
    // A translucent object lets light through in the shadow maps (Fresnel at each crossing, its
    // optical thickness along the light's ray; docs/translucency.md "Shadows"); false: it is an
    // opaque occluder.
    bool shadows = true;
    int vnmResolution = 16;
    std::string vnmCacheDir;
    // The voxel number map's approximations, each measured against the reference on the sample
    // scene (docs/translucency.md "Error budget"). diffusionKernel: the kernel e^{-k tau},
    // k = min(1, sqrt(3 (1 - albedo))) (false, the default: the seed's e^{-tau}). meshSurface:
    // surface voxels' normals and areas from the mesh (false, the default: from the voxels'
    // occupancy). smoothLookup: the smooth reconstruction, each voxel's near field normalised
    // (SurfaceVoxel::nearScale) and a translucent pixel blending the surface voxels within 1.5
    // voxels (false: neither, the nearest voxel alone: the voxels' stripes). measuredAlbedo: the
    // kernel's total is the share of scattered light that leaves the object, measured by random
    // walks through its voxels (false, the default: Hapke's albedo of a thick half-space, which a
    // front-lit cube's reference bears out and the walks overshoot).
    bool diffusionKernel = false;
    bool meshSurface = false;
    bool smoothLookup = true;
    bool measuredAlbedo = false;
    // A translucent pixel also lets through what lies behind its object along the camera ray:
    // the chord's e^{-tau} (from the voxel number map's LUT) times F_t at both boundaries, of the
    // footage at that pixel (the boundary does not bend the ray), beside its scattered light, as
    // renderVnm adds the background (docs/translucency.md "See-through"). false: every
    // translucent pixel is opaque (its scattered light only).
    bool seeThrough = true;
    // A translucent object's boundary reflects the share F_r = 1 - F_t of the light arriving
    // along the camera ray's mirror direction (smooth, as the reference's boundary): the surface
    // the ray meets, found by marching it over the G-buffer (the footage of a real surface, with
    // its differential light), else the environment (docs/translucency.md "Reflection"). false:
    // no reflection (the scattered light and the see-through only).
    bool surfaceReflection = true;

    void validate() const {
        checkOption(vnmResolution >= 2 && vnmResolution <= 512, "translucency.vnmResolution",
                    "2..512", vnmResolution);
    }
};

}  // namespace mirage::render
