#pragma once
// Options of the differential composite (render/passes/composite, docs/realtime-renderer.md).
#include "core/camera/CameraResponse.h"
#include "render/PassOptions.h"

namespace mirage::render {

struct CompositeOptions {
    // Rendered linear radiance -> camera linear units: the gain of every frame, or with
    // RendererOptions::exposureMatch.enabled the prior of the per-frame estimate
    // (docs/camera-matching.md).
    float exposure = 1.0f;
    float alphaMax = 8.0f;      // cap of alpha = CI / L_r
    float alphaFadeLr = 0.02f;  // where L_r (linear) is below this, alpha fades to 1
    // Where the lens remap is the identity (no distortion, a canvas of the camera's size) the
    // composite reads each canvas buffer at its own pixel (CompositePass::isIdentityRemap).
    // false: it reads through the remap table there too (tests compare the two).
    bool identityRemap = true;
    // false: the composite is the footage unchanged, as if no virtual object existed (the live
    // view's "hide" key; the bench's `virtual=off` sanity point, which must score as the footage).
    bool showVirtual = true;
    // The main camera's response (docs/camera-matching.md, "Camera response"): the footage is
    // linearised with it and Renderer::compositeCameraCoded() encodes with it. sRGB: the camera
    // frame is an sRGB texture, decoded by the sampler; another response: the frame is
    // linearised on upload into a half-float texture (8-bit sRGB codes would merge the darkest
    // codes of a gamma-2.6 camera).
    CameraResponse cameraResponse;

    void validate() const {
        checkOption(exposure >= 1e-4f && exposure <= 1e4f, "composite.exposure", "in [1e-4, 1e4]",
                    exposure);
        checkOption(alphaMax >= 1.0f && alphaMax <= 1e3f, "composite.alphaMax", "in [1, 1000]",
                    alphaMax);
        checkOption(alphaFadeLr >= 0.0f && alphaFadeLr <= 1.0f, "composite.alphaFadeLr",
                    "in [0, 1]", alphaFadeLr);
    }
};

}  // namespace mirage::render
