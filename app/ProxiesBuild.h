#pragma once
// `mirage proxies` as a call (docs/reconstruction.md): rebuilds the real proxies (the table, the
// objects on it, their albedo) and the real spot light from a session's footage and writes them,
// with the virtual objects of a scene, as a new scene beside its report. The command
// (app/commands/ProxiesCommand.cpp) and `mirage live --scan` (a recorded scan, then live with
// the rebuilt scene) call it.
#include <string>

#include "render/reconstruction/ProxyReconstruction.h"

namespace mirage::app {

// What to rebuild from what. Camera poses, as the replay takes them: `poses` (`mirage track`'s
// CSV), else `groundTruth` (the session's frames.csv), else the tracker on the session's board.
struct ProxiesRequest {
    std::string session, scene, output, poses, truth;
    bool groundTruth = false, force = false;
    int maxFrames = -1;
    double minParallaxDeg = reconstruction::FootageCheckOptions{}.minParallaxDeg;
    int minFrames = reconstruction::FootageCheckOptions{}.minFrames;
    int triangleBudget = reconstruction::GeometryOptions{}.triangleBudgetPerObject;
    reconstruction::StereoOptions stereo;
    reconstruction::CarvingOptions carving;
    bool noCarving = false;
};

// Reads the session, rebuilds, writes `output` (.gltf) and OUTPUT.report.json, prints the
// summary. Throws mirage::Error / FileError for bad input, reconstruction::FootageRefused when
// the footage cannot support a reconstruction (what to record instead).
void buildProxies(const ProxiesRequest& request);

}  // namespace mirage::app
