#pragma once
// Options of the exposure pass (render/passes/exposure, docs/camera-matching.md): the main
// camera's exposure and white balance measured every frame from the footage against the
// rendered real surfaces, and applied to everything the renderer adds to the footage.
#include "render/ExposureTracker.h"

namespace mirage::render {

struct ExposureMatchOptions {
    // false: RendererOptions::composite.exposure is the fixed gain of every frame (the renderer as
    // a model; tests). true: it is only the prior, before the first measurement. `mirage replay`
    // and `mirage live` switch it on by default.
    bool enabled = false;
    // Sample blocks across the canvas width (their height follows the aspect ratio): each block
    // of canvas / sampleColumns pixels per side is summarised by at most 4 x 4 taps. 80 at
    // 640x480: 80 x 60 blocks of 8 x 8 pixels.
    int sampleColumns = 80;
    // Blocks whose rendered L_r varies by more than this factor (max / min luminance of its taps)
    // lie on an edge of the model (a small pose error moves it in the footage): not used.
    float maxBlockVariation = 1.25f;
    // Blocks whose footage mean is noisier than this (standard error over the mean, luminance)
    // are not used: dark, noisy footage.
    float maxBlockNoise = 0.05f;
    ExposureTrackerSettings tracker;
    // Throws mirage::Error naming the first field out of range.
    void validate() const;
};

}  // namespace mirage::render
