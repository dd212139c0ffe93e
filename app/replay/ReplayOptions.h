#pragma once
// What `mirage replay` is asked to do (its command-line options, docs/replay.md).
#include <optional>
#include <string>
#include <vector>

namespace mirage::app {

struct ReplayOptions {
    std::string session, scene, output, poses, shard, placement, staticEnv;
    std::vector<std::string> effectsOff;    // bench knob names of effects switched off
    std::vector<std::string> knobSettings;  // --set KNOB=VALUE, applied after effectsOff
    int vpls = 256;
    int maxFrames = -1;
    int start = 0;
    // Frames before the first written one that are tracked and rendered but not written, so that
    // the temporal history (indirect light, the tracker's motion model) is warm at the seam of a
    // range or shard. 8: the seam measured in docs/scale.md.
    int warmup = 8;
    float exposure = 1.0f;
    // The camera's exposure time for the motion blur, seconds (--shutter; 0 = off); unset: the
    // session's (session.json cameras[0].shutter), else off.
    std::optional<double> shutter;
    int jpegQuality = 92;
    bool window = false;
    bool verbose = false;
    bool groundTruth = false;
    bool boardOnly = false;  // no natural features (extended tracking off)
    bool force = false;
    bool estimateLights = false;  // place the environment's lights (and report them)
    bool reportLights = false;    // report them only
};

}  // namespace mirage::app
