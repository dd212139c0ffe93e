#pragma once
// `mirage live --scan SECONDS` (docs/live.md, "Scan"): the real proxies from the user's own
// footage instead of a hand-made model. Three steps, each the code the single commands run:
//   1. scan: `mirage live` with the given scene for SECONDS, recording the processed frames,
//      their live poses and the environment camera into the scan folder (a session);
//   2. rebuild: `mirage proxies` of that session (app/ProxiesBuild.h) into SCAN/scene.gltf, the
//      scene's virtual objects with the rebuilt real proxies and lights;
//   3. live: `mirage live` with the rebuilt scene (the virtual objects where the original
//      scene's placement file puts them), with every other option as given.
// A scan the reconstruction refuses (too few tracked frames, no parallax) ends with what to
// record instead and a non-zero exit; the scan folder is kept either way, so the user can
// rebuild it by hand or replay it.
#include "app/live/LiveOptions.h"

namespace mirage::app {

// The scan folder for these options: --scan-dir, else OUT.scan beside -o OUT, else a new
// time-stamped folder in the working directory.
std::string scanFolder(const LiveOptions& options);

// Runs the three steps; returns the exit code (0, or 128 + the signal that stopped a step).
int runLiveWithScan(const LiveOptions& options);

}  // namespace mirage::app
