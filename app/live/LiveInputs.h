#pragma once
// The cameras of a live session as opened before the loop starts (docs/live.md): the main
// camera (a V4L2 webcam, or a recorded session or video standing in for one, paced at its frame
// rate) with the calibration and board found for it, and the optional fish-eye environment
// camera with its calibration as the renderer's environment camera.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/live/LiveOptions.h"
#include "core/capture/LatestFrameCapture.h"
#include "core/math/Pose.h"
#include "core/session/FrameSource.h"
#include "render/Renderer.h"

namespace mirage::app {

// The camera: what it is, where its frames come from, how they are paced, and the calibration
// and board found beside a recorded stand-in.
struct CameraInput {
    std::unique_ptr<FrameSource> source;
    LatestFrameCapture::Options pacing;
    std::string description;
    std::filesystem::path calibration, board;  // defaults from a session stand-in
    double fps = 30;                           // nominal rate (recorded into session.json)
    std::string exposureText = "as recorded (a stand-in)";  // for the HUD
    std::vector<std::string> exposureWarnings;
    std::string calibrationHint, boardHint;  // where a webcam's defaults were looked for
    std::vector<std::filesystem::path> inputs;
    // A recorded session standing in with ground-truth poses: frame i's T_world_camera
    // (nullopt where unknown) and when the stand-in releases it, seconds after frame 0 (its
    // own times, or i / fps when paced at a rate). Empty otherwise.
    std::vector<std::optional<Pose>> groundTruth;
    std::vector<double> releaseSeconds;
};

// The environment camera of a live session: its frames (a capture thread of its own, paced as
// the main camera's) and its calibration as the renderer's environment camera.
struct EnvironmentInput {
    std::unique_ptr<FrameSource> source;
    LatestFrameCapture::Options pacing;
    render::EnvironmentCameraSetup setup;
    std::string description;
    std::filesystem::path calibration;
    std::vector<std::filesystem::path> inputs;
    double fps = 30;  // nominal frame rate (pairing with the main camera's frames)
};

// Opens --camera (default: the first V4L2 camera). Throws mirage::Error saying what to do when
// there is none.
CameraInput openCamera(const LiveOptions& options);
// Opens --env-camera with its calibration (--env-calibration, or the session's).
EnvironmentInput openEnvironmentCamera(const LiveOptions& options);
// --list-cameras: every V4L2 node, its modes and controls, and which calibration matches.
void listCameras();
// "<prefix>YYYYmmdd-HHMMSS<ext>" in local time: names of recordings and screenshots.
std::string timestampName(const char* prefix, const char* ext);

}  // namespace mirage::app
