// `mirage live`: a live AR session (docs/live.md). A camera (V4L2, or a recorded video or
// session standing in for one, paced at its frame rate) is captured on its own thread with a
// latest-frame hand-off; the GL thread takes the newest frame, tracks the camera on the tag
// board, renders and composites the scene's virtual objects (the per-frame code replay uses)
// and shows the result in a window, or with --headless writes it. The session and its stages
// are app/live/LiveSession.h; this file is its command line.
//
// Outputs (all optional): -o OUT.mkv or a folder of PNG frames, with a per-frame CSV beside it
// (app/live/LiveOutputs.h says its columns); --record SESSION: the processed frames with their
// live poses (core/capture/LiveRecording.h); --scan SECONDS: a scan of the room first, from which
// the real proxies are rebuilt (app/live/LiveScan.h).
#include "app/Command.h"
#include "app/EffectSwitches.h"
#include "app/KnobSettings.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/live/LiveInputs.h"
#include "app/live/LiveScan.h"
#include "app/live/LiveSession.h"

namespace mirage::app {
namespace {

const CommandRegistrar reg("live", [](CLI::App& parent) {
    auto args = std::make_shared<LiveOptions>();
    auto* cmd = parent.add_subcommand(
        "live", "Live AR session: track a camera, composite the scene's virtual objects, show it");
    cmd->add_option("--camera", args->camera,
                    "/dev/videoN (or N) for a webcam (default: the first camera); a session "
                    "folder or a video stands in for a camera, paced at its frame rate");
    cmd->add_option("--env-camera", args->envCamera,
                    "The fish-eye environment camera that lights the scene every frame: "
                    "/dev/videoN (or N), a video, or a session folder (its environment camera)");
    cmd->add_option("--env-calibration", args->envCalibration,
                    "The environment camera's calibration (fish-eye intrinsics, extrinsics, "
                    "radiometry_to_main; default for a session: the one session.json names)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--estimate-lights", args->estimateLights,
                  "Find the dominant lights of each environment-camera frame and place them as "
                  "shadow-casting real directional lights (their regions taken out of the "
                  "environment light)");
    cmd->add_option("--scene", args->scene,
                    "Scene (.gltf/.glb) with real proxies and virtual objects (required)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--placement", args->placement,
                    "Where the virtual objects stand (default: SCENE.placement.json if it exists; "
                    "the window's keys move them and save it there)");
    cmd->add_flag("--list-cameras", args->listCameras,
                  "List the cameras, their modes and controls, and which calibration matches");
    cmd->add_option("--calibration", args->calibration,
                    "The camera's calibration (OpenCV YAML from `mirage calibrate`; default: the "
                    "stand-in session's, or a webcam's in the camera folder: --list-cameras)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--board", args->board,
                    "Tag board file (default: the stand-in session's, or beside a webcam's "
                    "calibration)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--camera-fps", args->cameraFps,
                    "Frame rate asked of a webcam, or at which a stand-in delivers frames "
                    "(default: 30; a session's own times; a video's own clock, else 30)")
        ->check(finiteIn(0, 1000, true));
    cmd->add_option("--width", args->width, "Frame width asked of a webcam")
        ->capture_default_str()
        ->check(wholeIn(16, 16384));
    cmd->add_option("--height", args->height, "Frame height asked of a webcam")
        ->capture_default_str()
        ->check(wholeIn(16, 16384));
    cmd->add_flag("--camera-loop", args->loop,
                  "Play a stand-in session or video again from the start when it ends");
    cmd->add_flag("--headless", args->headless, "No window (EGL): for tests and benchmarks");
    cmd->add_flag("--no-pipeline", args->noPipeline,
                  "Track each frame on the GL thread before rendering it, instead of tracking the "
                  "next frame on a thread of its own while the frame before renders");
    cmd->add_flag("--no-predict", args->noPredict,
                  "Render with the pose as tracked at capture, instead of the pose predicted to "
                  "the frame's display time");
    cmd->add_flag("--board-only", args->boardOnly,
                  "Track the board's tags only, no natural features (docs/tracking.md)");
    cmd->add_option("--frames", args->maxFrames, "Stop after N processed frames")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("-o,--output", args->output,
                    "Write the composites: OUT.mkv (MJPEG video) or a folder of PNG frames, with "
                    "a per-frame CSV beside it")
        ->check(outputPath(OutputShape::FileOrFolder));
    cmd->add_option("--off", args->effectsOff,
                    "Start with these effects off (comma-separated, as `mirage bench` names "
                    "them; the HUD switches them): " +
                        effectSwitchNames())
        ->delimiter(',')
        ->check(effectSwitchName());
    cmd->add_option("--set", args->knobSettings,
                    "Set a pass knob, KNOB=VALUE (repeatable; the knobs and their values: "
                    "`mirage bench --list-knobs`), e.g. --set caustic_map=512")
        ->check(knobSetting());
    cmd->add_option("--record", args->record,
                    "Record the session (the camera's frames and the live poses) into this new "
                    "folder; replay it with `mirage replay`")
        ->check(outputPath(OutputShape::Folder));
    cmd->add_option("--scan", args->scanSeconds,
                    "First scan the room for this many seconds (walk the camera around the "
                    "table), rebuild the real proxies and lights from it (as `mirage proxies`), "
                    "then go on live with them: --scene needs the virtual objects only")
        ->check(finiteIn(0, 3600, true));
    cmd->add_option("--scan-dir", args->scanDir,
                    "Where --scan records the scan and writes the rebuilt scene (a new folder; "
                    "default: OUT.scan beside -o OUT, else live-scan-TIME)")
        ->check(outputPath(OutputShape::Folder));
    cmd->add_option("--vpls", args->vpls, "Virtual point lights per frame")
        ->check(wholeIn(0, 16384));
    cmd->add_option("--budget-ms", args->budgetMs,
                    "Frame-time budget of rendering and compositing in ms: each frame's quality "
                    "(specular resolution, caustic refresh, ...) is chosen to meet it with the "
                    "least error (default: the camera's frame interval; 0: off, full quality)")
        ->check(finiteIn(0, 60000));
    cmd->add_option("--budget-table", args->budgetTable,
                    "The speed-vs-error table the budget chooses from: a `mirage bench` "
                    "bench.csv (default: data/governor/tabletop_llvmpipe.csv, measured on "
                    "llvmpipe, 2 cores)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--exposure", args->exposure, "Rendered radiance -> camera linear units")
        ->check(finiteIn(0, 1e6, true));
    cmd->add_option("--shutter", args->shutter,
                    "The webcam's exposure time in seconds for the motion blur of what the "
                    "renderer adds (0 = off; default: the locked --camera-exposure, else off)")
        ->check(finiteIn(0, 10));
    cmd->add_flag("--force", args->force, "Replace an existing CSV beside the output");
    cmd->add_option("--screenshot", args->screenshot,
                    "Window: save a PNG of the window after --screenshot-after frames, then exit")
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--screenshot-after", args->screenshotAfter,
                    "Window: frames to process before --screenshot")
        ->capture_default_str()
        ->check(wholeIn(1, 100000000));
    auto setOpt = [](std::optional<int64_t>& o) { return [&o](int64_t v) { o = v; }; };
    cmd->add_option_function<int64_t>("--camera-exposure", setOpt(args->exposureLock.exposure),
                                      "Webcam exposure time (V4L2 units of 100 us; default: "
                                      "where automatic exposure settled, then locked)")
        ->check(wholeIn(1, 1000000));
    cmd->add_option_function<int64_t>("--camera-gain", setOpt(args->exposureLock.gain),
                                      "Webcam gain (device units; default: locked where it was)")
        ->check(wholeIn(0, 1000000));
    cmd->add_option_function<int64_t>(
           "--white-balance", setOpt(args->exposureLock.whiteBalanceK),
           "Webcam white balance, kelvin (default: locked where automatic white balance was)")
        ->check(wholeIn(1000, 20000));
    cmd->callback([args] {
        if (args->listCameras) return listCameras();
        if (args->scanSeconds > 0) {
            commandExitCode() = runLiveWithScan(*args);
            return;
        }
        LiveSession session(*args);
        commandExitCode() = session.run();
    });
});

}  // namespace
}  // namespace mirage::app
