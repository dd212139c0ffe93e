#pragma once
// The small synthetic session the camera-matching ground-truth tests render their scenes into:
// 160 x 120 pinhole (63.2 degrees), 6 frames at 6 frames/s on an orbit of 2.5 m radius and
// height, an image sequence with the reference renderer's composite per frame, no environment
// camera. Each test sets what it judges (sensor, shutter, path) on the returned options.
#include <cstdint>
#include <string>

#include "render/raytrace/SyntheticSession.h"

namespace mirage::test {

inline raytrace::SyntheticSessionOptions smallSyntheticSession(const std::string& sceneName,
                                                               int samplesPerPixel, uint64_t seed) {
    raytrace::SyntheticSessionOptions o;
    o.width = 160;
    o.height = 120;
    o.hfovDeg = 63.2;
    o.fps = 6.0;
    o.seconds = 1.0;  // 6 frames
    o.samplesPerPixel = samplesPerPixel;
    o.threads = 2;
    o.seed = seed;
    o.environmentCamera = false;
    o.imageSequence = true;
    o.groundTruthComposite = true;
    o.path.radius = 2.5;
    o.path.height = 2.5;
    o.sceneName = sceneName;
    return o;
}

}  // namespace mirage::test
