#pragma once
// A synthetic session (docs/reference-renderer.md, docs/session.md): the scene's REAL parts
// rendered by the reference renderer along a camera path with exact ground-truth poses, with
// sensor effects, plus the fish-eye environment camera — and optionally, per frame, the ground-
// truth composite (the real AND virtual parts rendered the same way) that real-time composites are
// judged against (render/raytrace/GroundTruthComposite.h). `mirage synth` is this plus argument
// parsing; tests call it with scenes built in memory.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/Shards.h"
#include "core/scene/Scene.h"
#include "render/raytrace/SyntheticFootage.h"

namespace mirage::raytrace {

struct SyntheticSessionOptions {
    int width = 640, height = 480;  // main camera (pixels)
    double hfovDeg = 60.0;          // main camera horizontal field of view
    double fps = 15.0, seconds = 3.0;
    int samplesPerPixel = 16;  // reference renderer passes per frame
    int threads = 0;           // 0 = all cores
    uint64_t seed = 1;         // render noise, sensor noise, shake
    double shutter = 0.0;      // motion blur: open fraction of the frame interval (0 = none)
    int blurSubframes = 4;     // renders averaged over the open shutter
    bool environmentCamera = true;
    int envSize = 320;  // fish-eye image (square, pixels)
    double envFovDeg = 190.0;
    // The environment camera's own radiometry: its exposure and white balance (per channel
    // R, G, B) multiply the linear radiance it films. env.yaml states the resulting ratio to the
    // main camera (radiometry_to_main = main exposure / (envExposure x envWhiteBalance)).
    float envExposure = 0.5f;
    glm::vec3 envWhiteBalance{1.0f};
    // The room light moves: the scene's equirectangular environment turns about world +Y at this
    // rate (degrees per second) from its rotation_y_deg; every frame (footage, environment camera
    // and ground truth) is rendered with the rotation of its time. 0 = static.
    double envRotationDegPerSecond = 0.0;
    bool imageSequence = false;  // PNG folders instead of MKV videos
    SensorOptions sensor;
    CameraPathOptions path;  // duration and seed are set from `seconds` and `seed`
    // Also write the ground-truth composite and influence mask of every frame (needs virtual
    // objects in the scene). Threshold: linear camera units (after exposure), see influenceMask.
    bool groundTruthComposite = false;
    double influenceThreshold = 0.01;
    std::string sceneName;  // recorded in session.json's creation info and ground_truth.json
    std::filesystem::path boardFile;  // copied into the session as board.json (empty: none)
};

// Called after each frame: frames done, total, the path segment ("orbit", "shake", "pan").
using SynthProgress = std::function<void(int done, int total, const std::string& segment)>;

// Writes the session into `out`, which must not hold a session yet (SessionWriter refuses).
// Throws mirage::Error on bad options (non-positive fps, seconds, spp; shutter outside [0, 1];
// a ground-truth composite for a scene without virtual objects).
void writeSyntheticSession(const Scene& scene, const std::filesystem::path& out,
                           const SyntheticSessionOptions& options,
                           const SynthProgress& progress = {});

// Frames of the session: round(seconds x fps), at least 1.
int syntheticFrameCount(const SyntheticSessionOptions& options);

// Fingerprint of everything that changes the frames (options, the scene's and the board's
// bytes): shards of one run share it, so shards of different runs are never merged.
std::string syntheticFingerprint(const SyntheticSessionOptions& options, uint64_t sceneBytes,
                                 uint64_t boardBytes);

// A shard of the session (core/Shards.h): renders only `frames` (frame numbers of the whole
// session) into `dir`: calibration, board and ground_truth.json as the session has them, each
// camera's images as lossless PNG (<camera>/<frame>.png), the ground-truth composites under
// their frame numbers. Returns the manifest payload: the session's metadata and writer settings,
// and per frame its timestamps and ground-truth pose.
nlohmann::json writeSyntheticShard(const Scene& scene, const std::filesystem::path& dir,
                                   const SyntheticSessionOptions& options,
                                   const std::vector<int>& frames,
                                   const SynthProgress& progress = {});

// Joins the shards of a synth run (collectShards checked that they are complete) into the
// session `out` (which must not hold a session), in frame order, encoding each frame as the
// whole run does: every file but session.json's creation time equals the whole run's.
void mergeSyntheticShards(const ShardSet& shards, const std::filesystem::path& out,
                          const SynthProgress& progress = {});

}  // namespace mirage::raytrace
