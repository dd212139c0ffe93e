#pragma once
// Options of the motion blur (render/passes/motionblur, docs/camera-matching.md): what the
// renderer adds to the footage is blurred along its screen-space motion over the camera's
// exposure, as the footage itself is.
#include "render/PassOptions.h"

namespace mirage::render {

struct MotionBlurOptions {
    // The main camera's exposure time (seconds): how long the shutter is open per frame. 0 = off
    // (no motion blur, the pass does not run). It comes from the session (session.json's
    // cameras[].shutter) or the command line (`--shutter SECONDS`).
    double shutterSeconds = 0.0;
    // Tile size of the reconstruction filter (McGuire et al. 2012), camera pixels: also the
    // largest blur half-length. A pixel's motion over the exposure is clamped to 2 x this.
    int tileSize = 20;
    // Taps of the gather along the tile neighbourhood's dominant motion (odd values keep the
    // centre sample off the grid's middle; the jitter covers it).
    int samples = 15;
    // Metres: the soft depth comparison's ramp (which of two samples is in front).
    float softDepthExtent = 0.05f;
    // Seconds: a previous frame further back than this (a seek, a long tracking loss) gives no
    // motion: the frame is not blurred, as the first frame.
    double maxFrameGap = 0.5;

    bool enabled() const { return shutterSeconds > 0.0; }
    void validate() const {
        checkOption(shutterSeconds >= 0.0 && shutterSeconds <= 10.0, "motionBlur.shutterSeconds",
                    "in [0, 10] seconds", shutterSeconds);
        checkOption(tileSize >= 2 && tileSize <= 128, "motionBlur.tileSize", "2..128", tileSize);
        checkOption(samples >= 3 && samples <= 63, "motionBlur.samples", "3..63", samples);
        checkOption(softDepthExtent > 0.0f && softDepthExtent <= 10.0f,
                    "motionBlur.softDepthExtent", "in (0, 10] metres", softDepthExtent);
        checkOption(maxFrameGap > 0.0 && maxFrameGap <= 10.0, "motionBlur.maxFrameGap",
                    "in (0, 10] seconds", maxFrameGap);
    }
};

}  // namespace mirage::render
