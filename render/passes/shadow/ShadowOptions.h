#pragma once
// Options of the shadow maps and reflective shadow maps (render/passes/shadow).
#include "render/PassOptions.h"

namespace mirage::render {

// How the shadow maps are looked up (lighting.glsl; docs/realtime-renderer.md, "Shadow edges").
enum class ShadowFilter {
    Bilinear,  // the 2x2 texels around the lookup, bilinear weights: 1-texel stair steps
    Pcf,       // 4x4 texels, a 2-texel box over the bilinear test: straight edges stay straight
};
const char* shadowFilterName(ShadowFilter f);  // "off" (bilinear), "pcf"

struct ShadowOptions {
    int mapSize = 512;  // texels per side of each shadow-map layer (occluder distance only)
    // Texels per side of each reflective-shadow-map layer (what the VPLs are sampled from: flux,
    // normal, position). Apart from mapSize so that a fine shadow map for sharp edges does not
    // also raise the four-target RSM raster; equal to mapSize, both are written in one raster.
    int rsmSize = 512;
    float bias = 0.001f;  // metres: constant depth bias of the shadow-map test
                          // (lighting.glsl adds the filter's reach in texel footprints / cos:
                          // 1.5 bilinear, 2.5 PCF)
    // The lookup of the lights' own maps: PCF over 4x4 texels (a point or spot light's hard
    // shadow edge without the texel grid's stair steps) or the 2x2 bilinear lookup alone.
    // Bilinear by default: at 512 texels a texel spans more than a pixel of the tabletop's
    // shadow, and PCF's 2-texel ramp is then further from the reference's hard edge than the
    // stair steps are (over one map of every occluder its penumbra error is halved only with
    // mapSize 2048, ~10x the shadow raster). The virtual occluders' focused maps (`focus`) are
    // filtered over the camera pixel's footprint whatever this says (docs/realtime-renderer.md,
    // "Shadow edges").
    ShadowFilter filter = ShadowFilter::Bilinear;
    // Glass transmits light in the shadow maps (coloured, Fresnel and Beer-Lambert weighted);
    // false: glass is an opaque occluder, as mirrors are.
    bool glass = true;
    // Virtual occluders in a real light's cone get maps of their own (at most kMaxFocusMaps),
    // fitted to their bounds and filtered over the camera pixel's footprint
    // (docs/realtime-renderer.md, "Focused maps for the virtual occluders"): the virtual
    // objects' shadow edges at the texel density of a much larger map, for one raster of the
    // virtual objects alone per map. Used where every fitted frustum is at most half the
    // light's; false: one map of every occluder over the light's whole frustum.
    bool focus = true;
    // The focused maps' filter follows the camera pixel's footprint in the map (a box of the
    // pixel's width convolved with the bilinear hat); false: the 2-texel PCF, as for points
    // that are not a camera pixel (hits seen in a mirror, photons). Compiled in
    // (MIRAGE_SHADOW_NO_PIXEL_FOOTPRINT), like `filter`.
    bool pixelFootprint = true;

    void validate() const {
        checkOption(mapSize >= 16 && mapSize <= 4096, "shadow.mapSize", "16..4096", mapSize);
        checkOption(rsmSize >= 16 && rsmSize <= 4096, "shadow.rsmSize", "16..4096", rsmSize);
        checkOption(bias >= 0.0f && bias <= 1.0f, "shadow.bias", "in [0, 1] metres", bias);
    }
};

}  // namespace mirage::render
