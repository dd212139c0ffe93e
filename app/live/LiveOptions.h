#pragma once
// What `mirage live` is asked to do (its command-line options, docs/live.md).
#include <optional>
#include <string>
#include <vector>

#include "core/capture/CameraControls.h"

namespace mirage::app {

struct LiveOptions {
    std::string camera, scene, calibration, board, output, record;
    std::vector<std::string> effectsOff;    // bench knob names of effects switched off
    std::vector<std::string> knobSettings;  // --set KNOB=VALUE, applied after effectsOff
    double cameraFps = 0;                   // 0: the stand-in's own rate
    int width = 640, height = 480;
    int maxFrames = -1;
    int vpls = 256;
    // Frame-time budget of the render stage, ms (--budget-ms): -1 the camera's frame interval, 0
    // off; and the speed-vs-error table it chooses from (--budget-table; empty: the table measured
    // on llvmpipe, kDefaultBudgetTable).
    double budgetMs = -1;
    std::string budgetTable;
    float exposure = 1.0f;
    // The webcam's exposure time for the motion blur, seconds (--shutter; 0 = off); unset: the
    // locked --camera-exposure, else off.
    std::optional<double> shutter;
    int jpegQuality = 92;
    bool headless = false;
    bool boardOnly = false;  // no natural features (extended tracking off)
    bool force = false;
    bool loop = false;  // a stand-in starts again at its end
    bool listCameras = false;
    std::string placement;          // default: <scene>.placement.json
    ExposureSettings exposureLock;  // webcam: exposure / gain / white balance to hold
    std::string screenshot;         // window: save a PNG after --screenshot-after frames, exit
    int screenshotAfter = 10;
    // The fish-eye environment camera (docs/environment.md): a webcam, a video or a session's
    // environment camera, and its calibration (intrinsics, extrinsics, radiometry_to_main).
    std::string envCamera, envCalibration;
    bool estimateLights = false;  // place the environment camera's dominant lights
    // By default the next frame is tracked on a thread of its own while the GL thread renders,
    // and rendered with the pose predicted to its display time (docs/live.md, "How it runs").
    bool noPipeline = false;  // track, then render, one after the other on the GL thread
    bool noPredict = false;   // render with the pose as tracked at capture
    // Stop after this many seconds of running (wall clock; 0: no limit).
    double maxSeconds = 0;
    // Start with the virtual objects hidden (the footage passes through, nothing is rendered):
    // the scan tracks and records as many frames as it can.
    bool hideVirtual = false;
    // --scan SECONDS: first record this long while the user walks the camera around the table
    // into scanDir (default: beside -o, else a time-stamped folder), rebuild the real proxies and
    // lights from it (`mirage proxies`), then go on live with the rebuilt scene
    // (app/live/LiveScan.h).
    double scanSeconds = 0;
    std::string scanDir;
};

}  // namespace mirage::app
