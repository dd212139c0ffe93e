#pragma once
// Options of the grain pass (render/passes/grain, docs/camera-matching.md): the footage's noise
// added to the pixels the renderer changed, and the camera's vignetting applied to the virtual
// objects' pixels, both estimated from the footage (or the vignetting given).
#include <cstdint>
#include <optional>

#include "render/passes/grain/CameraGrain.h"

namespace mirage::render {

struct NoiseMatchOptions {
    // Off: the renderer's pixels stay clean (the renderer as a model; tests). `mirage replay`
    // and `mirage live` switch it on by default.
    bool enabled = false;
    // Sample blocks an intensity level needs for its noise level to be measured (the others
    // follow the Poisson-Gaussian line through the measured ones).
    int minBlocksPerLevel = 6;
    // The draw: the footage's own grain (each camera pixel's residual from an edge-preserving
    // mean, so the added noise has the camera's texture and changes with its frames), or
    // Gaussian noise synthesised from the seed (also where the footage's draw cannot be
    // measured: at its edges and clipped pixels).
    bool footageGrain = true;
    // Mixed with the renderer's frame count into each frame's noise: the same seed and frame
    // give the same noise (replays and tests reproduce).
    uint32_t seed = 1;
};

struct VignetteMatchOptions {
    bool enabled = false;  // off: the virtual pixels are not darkened; on in replay and live
    // The camera's vignetting, when known (the calibration's, or the user's): used as it is,
    // nothing is estimated. Not set: estimated from the footage.
    std::optional<VignetteProfile> profile;
    // The fit (fitVignetteAcrossFrames) takes the sample blocks of the last `frames` frames and
    // needs `minBlocks` of them on surface points (world cells of `cellSize` m) seen in two
    // frames or more, at image radii (r^2) spread by `minSpread` (RMS) about each point's mean:
    // a camera that has not moved gives no estimate (one frame cannot tell the lens from the
    // model's own error).
    int frames = 8;
    // Refitted every `refitInterval` frames once there is an estimate (every frame before): the
    // fit is CPU work over all the frames' samples, and the lens does not change.
    int refitInterval = 4;
    float cellSize = 0.02f;
    int minBlocks = 150;
    float minSpread = 0.01f;
};

struct GrainOptions {
    NoiseMatchOptions noise;
    VignetteMatchOptions vignette;
    // The sample blocks (as the exposure pass's: sampleColumns across the canvas) and the
    // smoothness of L_r a block needs (max / min luminance of its taps).
    int sampleColumns = 80;
    float maxBlockVariation = 1.25f;
    // Weight of the earlier frames in the noise and vignetting estimates (0: each frame's own).
    float history = 0.8f;
    // Throws mirage::Error naming the first field out of range.
    void validate() const;
};

}  // namespace mirage::render
