#pragma once
// Options of the specular passes: reflections and refractions of mirrors and glass
// (render/passes/specular, docs/specular.md).
#include "render/PassOptions.h"

namespace mirage::render {

struct SpecularOptions {
    int refractionMarchSteps = 16;        // back-face depth march steps of the refracted ray
    float backProjectionEpsilon = 0.02f;  // depth validation: |d - d_gbuf| < eps * d + 0.005 m
    bool vpls = true;                     // light GBuf_refl / GBuf_refr hits with the VPLs too
    // Temporal smoothing of the light of the reflected / refracted hits, L'_rv and L'_r (gathered
    // caustic included; specular_light.frag), reprojected by the mirror / glass surface's
    // position and rejected also where either ray's hit distance changed (a reflection's hit
    // moves differently from the mirror under camera motion), with the caustic's reset rules.
    bool temporal = true;
    // 1, 4 or 16: each hit sums every stride-th VPL (x stride), interleaved over 2x2 / 4x4
    // pixels; each hit's VPL irradiance is then averaged over its 2x2 quad (specular_light.frag),
    // so a quad sums 4 subsets. 16 costs about half of 4's speclight time; the quad average keeps
    // its pattern weak enough for the specular tests' SSIM floors (docs/specular.md, "Cost").
    int vplStride = 16;
    // Specular lighting (speclight) at half the canvas resolution per axis: each 2x2 block's
    // first specular pixel is shaded (lights, VPLs, caustic photons at its hits) and the canvas
    // pixels take the hit radiance from the four half pixels around them, weighted by how well
    // the representatives' hits match theirs (same object, tangent plane, normal), multiplied
    // back by their own hit albedo, Fresnel weight and emission; L_env stays per pixel
    // (specular_resolve.frag, docs/specular.md "Cost"). false: every specular pixel is shaded.
    bool halfResolution = false;
    // The reflected / refracted rays (specgbuf) traced at half the canvas resolution per axis: one
    // ray pair per 2x2 block, from the block's first specular pixel, then every specular pixel
    // takes the hits of the block around it whose primary surface matches its own best (same
    // object, tangent plane, normal: specular_trace_fill.frag), so an object's edge keeps its
    // pixels. The ray search is a quarter of the work; the hits are 2x2 blocks. false: a ray pair
    // per pixel.
    bool halfResolutionTrace = false;
    // Build the programs of the governed settings (the half-resolution lighting and trace, the
    // composite without the second exit) when the renderer is made although they are off: a
    // frame-time governor may switch them on while it runs, and compiling them then stalls that
    // frame (about 0.5 s on llvmpipe).
    bool prepareGovernedVariants = false;
    // Temporal reuse of the hit light: 1 shades every specular pixel every frame; 2 or 4 shade the
    // 8x8-pixel tiles of one phase of N per frame, and the other tiles' pixels take last frame's
    // light where it was lit at this frame's hits, within 0.5 mm (specular_light.frag); a pixel
    // whose history does not hold (disocclusion, the hits moved) is shaded. Every pixel every frame
    // where the history is reset (first frame, a cut, tracking lost, an object or light moved) and
    // in the half-resolution variant (its hits are per 2x2 block).
    int refreshInterval = 1;
    // Tests only: false drops the upsample's geometry test (plain bilinear weights; halos at
    // depth steps in the reflections).
    bool upsampleGeometry = true;
    // The glass's refracted path followed past Fresnel's internal reflection at the back face
    // to its second exit (specular.glsl refractedSecondExit), whose environment light the
    // composite adds to the pixel's L_env after the rough pass (second_exit.glsl): on a sphere's
    // rim that share of the light is large. false: only the first exit.
    bool secondExit = true;
    // Tests only: false draws the specular passes over the one rectangle around every specular
    // object (FrameContext::specularScissor) instead of each object's own (the same images).
    bool rectsPerObject = true;

    void validate() const {
        checkOption(refractionMarchSteps >= 2 && refractionMarchSteps <= 128,
                    "specular.refractionMarchSteps", "2..128", refractionMarchSteps);
        checkOption(vplStride == 1 || vplStride == 4 || vplStride == 16, "specular.vplStride",
                    "1, 4 or 16", vplStride);
        checkOption(refreshInterval == 1 || refreshInterval == 2 || refreshInterval == 4,
                    "specular.refreshInterval", "1, 2 or 4 frames", refreshInterval);
        checkOption(backProjectionEpsilon > 0.0f && backProjectionEpsilon <= 1.0f,
                    "specular.backProjectionEpsilon", "in (0, 1] (relative depth tolerance)",
                    backProjectionEpsilon);
    }
};

}  // namespace mirage::render
