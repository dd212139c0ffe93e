// `mirage replay SESSION --scene SCENE -o OUT`: composites a scene's virtual objects into a
// recorded (or synthetic) session with the real-time renderer (render/Renderer.h). The loop and
// its stages are app/replay/ReplaySession.h; this file is its command line.
//
// Output: OUT.mkv (MJPEG in Matroska, one cluster per frame: Ctrl-C or a crash leaves every
// finished frame playable) or, for any other OUT, a folder of PNG frames (frame_000000.png,
// sRGB 8-bit). Beside it a per-frame CSV (OUT with .csv, or OUT/frames.csv for a folder):
//   frame,t,state,reason,decode_ms,tracking_ms,<pass>_ms...,gpu_ms,readback_ms,encode_ms,
//   frame_ms,tx,ty,tz,qw,qx,qy,qz
// where <pass>_ms are the GL timer-query times of the renderer's passes (0 when skipped) and the
// pose is T_world_camera (OpenCV axes). Headless by default; --window shows the result as it goes.
//
// Camera poses, in this order: --poses POSES.csv (the `mirage track` format); --ground-truth (the
// session's frames.csv poses); otherwise live tracking (tracking::Tracker on the session's board
// and calibration) when the session has a board file, else the ground truth as a fallback. A frame
// without a pose is "lost": the camera frame passes through unchanged and temporal history is
// reset on the next tracked frame. An `uncertain` frame is composited with the last ok pose if
// that is at most 0.25 s old (the reason says so), else treated as lost.
//
// Environment (docs/environment.md): a session with an environment camera (role "environment",
// e.g. env.mkv) lights the scene with it, frame by frame (the renderer's environment pass runs
// when a new environment frame arrives); --static-env FILE uses that equirectangular image
// instead. An unusable environment camera (no calibration or extrinsics, a calibration of another
// size, a video that ends early) is reported and the replay continues with the scene's static
// environment; the CSV's last column, `environment`, says which one lit each frame.
// --estimate-lights places the dominant lights of each environment frame as shadow-casting real
// directional lights (render/EnvironmentLights.h); --report-lights only logs them.
#include "app/Command.h"
#include "app/EffectSwitches.h"
#include "app/KnobSettings.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/ShardOptions.h"
#include "app/replay/ReplaySession.h"

namespace mirage::app {
namespace {

const CommandRegistrar reg("replay", [](CLI::App& parent) {
    auto args = std::make_shared<ReplayOptions>();
    auto* cmd = parent.add_subcommand(
        "replay",
        "Composite a scene's virtual objects into a recorded session (real-time renderer)");
    cmd->add_option("session", args->session, "Session folder")
        ->required()
        ->check(CLI::ExistingDirectory);
    cmd->add_option("--scene", args->scene,
                    "Scene (.gltf/.glb) with real proxies and virtual objects")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", args->output, "OUT.mkv (MJPEG video) or a folder for PNG frames")
        ->required()
        ->check(outputPath(OutputShape::FileOrFolder));
    cmd->add_option("--poses", args->poses,
                    "Camera poses CSV from `mirage track` (default: live tracking on the session's "
                    "board; the ground truth when it has no board file)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--placement", args->placement,
                    "Where the virtual objects stand on the session's board (default: "
                    "SCENE.placement.json if it exists, as `mirage live` saves it)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--vpls", args->vpls, "Virtual point lights per frame")

        ->check(wholeIn(0, 16384));
    cmd->add_option("--frames", args->maxFrames, "Replay at most N frames")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("--start", args->start, "First frame")->check(wholeIn(0, 100000000));
    cmd->add_option("--warmup", args->warmup,
                    "Frames before the first written one that are tracked and rendered, not "
                    "written: temporal history is warm at the seam")
        ->capture_default_str()
        ->check(wholeIn(0, 100000));
    cmd->add_option("--shard", args->shard,
                    "Replay part I of N (I/N, 0-based: the I-th of N contiguous blocks of the "
                    "frames, each warmed up) into OUT.shards/; join with `mirage merge OUT`")
        ->check(shardSpecCheck());
    cmd->add_option("--exposure", args->exposure, "Rendered radiance -> camera linear units")
        ->check(finiteIn(0, 1e6, true));
    cmd->add_option("--shutter", args->shutter,
                    "The camera's exposure time in seconds for the motion blur of what the "
                    "renderer adds (0 = off; default: the session's, session.json "
                    "cameras[0].shutter)")
        ->check(finiteIn(0, 10));
    cmd->add_option("--static-env", args->staticEnv,
                    "Light with this equirectangular image (.exr/.hdr/.pfm, linear) instead of "
                    "the session's environment camera")
        ->check(CLI::ExistingFile);
    cmd->add_option("--off", args->effectsOff,
                    "Switch these effects off (comma-separated, as `mirage bench` names them): " +
                        effectSwitchNames())
        ->delimiter(',')
        ->check(effectSwitchName());
    cmd->add_option("--set", args->knobSettings,
                    "Set a pass knob, KNOB=VALUE (repeatable; the knobs and their values: "
                    "`mirage bench --list-knobs`), e.g. --set caustic_map=512")
        ->check(knobSetting());
    cmd->add_flag("--estimate-lights", args->estimateLights,
                  "Find the dominant lights of the environment camera's frames and place them as "
                  "shadow-casting real directional lights (their regions taken out of the "
                  "environment light); reports them whenever the environment changes");
    cmd->add_flag("--report-lights", args->reportLights,
                  "Report the dominant lights of the environment (direction, colour, intensity) "
                  "whenever it changes, without placing them");
    cmd->add_flag("--board-only", args->boardOnly,
                  "Track the board's tags only, no natural features (docs/tracking.md)");
    cmd->add_flag("--ground-truth", args->groundTruth,
                  "Use the session's ground-truth poses (frames.csv) instead of tracking");
    cmd->add_flag("--force", args->force,
                  "Replace an existing CSV beside the output (never an input of the replay)");
    cmd->add_flag("--window", args->window, "Show the result in a window (needs a display)");
    cmd->add_flag("-v,--verbose", args->verbose, "Log which passes ran and why");
    cmd->callback([args] {
        ReplaySession replay(*args);
        commandExitCode() = replay.run();
    });
});

}  // namespace
}  // namespace mirage::app
