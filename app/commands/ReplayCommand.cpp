// `mirage replay SESSION --scene SCENE -o OUT`: composites a scene's virtual objects into a
// recorded (or synthetic) session with the real-time renderer (render/Renderer.h).
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
#include <unistd.h>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "app/BoardPlane.h"
#include "app/Command.h"
#include "app/EffectSwitches.h"
#include "app/FrameCompositor.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "app/OutputKind.h"
#include "app/commands/ShardMerge.h"
#include "core/Csv.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/Shards.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/gl/Objects.h"
#include "core/image/ImageIO.h"
#include "core/scene/Scene.h"
#include "core/scene/ScenePlacement.h"
#include "core/session/MatroskaWriter.h"
#include "core/session/PosesCsv.h"
#include "core/session/Session.h"
#include "core/session/SessionReadOptions.h"
#include "render/LightEstimation.h"
#include "render/Renderer.h"
#include "render/SessionEnvironment.h"
#include "tracking/Tracker.h"

namespace mirage::app {
namespace {

bool gWindowClosed = false;
bool stopped() {
    return gWindowClosed || stopRequested();
}

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void progress(int done, int total, double fps) {
    if (!isatty(STDERR_FILENO)) {
        if (total > 0 && (done % std::max(1, total / 10) == 0 || done == total))
            spdlog::info("replay: {}/{} frames, {:.1f} frames/s", done, total, fps);
        return;
    }
    const int width = 30;
    const int filled = total > 0 ? width * done / total : 0;
    std::fprintf(stderr, "\r[%s%s] %d/%d frames  %.1f frames/s ",
                 std::string(size_t(filled), '#').c_str(),
                 std::string(size_t(width - filled), '-').c_str(), done, total, fps);
    std::fflush(stderr);
}

struct ReplayArgs {
    std::string session, scene, output, poses, shard, placement, staticEnv;
    std::vector<std::string> effectsOff;  // bench knob names of effects switched off
    int vpls = 256;
    int maxFrames = -1;
    int start = 0;
    // Frames before the first written one that are tracked and rendered but not written, so that
    // the temporal history (indirect light, the tracker's motion model) is warm at the seam of a
    // range or shard. 8: the seam measured in docs/scale.md.
    int warmup = 8;
    float exposure = 1.0f;
    int jpegQuality = 92;
    bool window = false;
    bool verbose = false;
    bool groundTruth = false;
    bool boardOnly = false;  // no natural features (extended tracking off)
    bool force = false;
    bool estimateLights = false;  // place the environment's lights (and report them)
    bool reportLights = false;    // report them only
};

// One log line per light found in the environment of frame `index`.
void logEnvironmentLights(int index, const std::vector<render::EstimatedLight>& lights,
                          const char* what) {
    if (lights.empty())
        spdlog::info("frame {}: environment lights: none (no bright compact region)", index);
    for (size_t k = 0; k < lights.size(); ++k) {
        const render::EstimatedLight& l = lights[k];
        const glm::vec3 d = l.direction, c = l.color();
        spdlog::info(
            "frame {}: environment light {}: direction {:.4f} {:.4f} {:.4f} (elevation {:.1f} deg, "
            "azimuth {:.1f} deg from -Z towards +X), colour {:.3f} {:.3f} {:.3f}, intensity "
            "{:.4g} W/m^2, {:.1f} % of the environment's light; {}",
            index, k + 1, d.x, d.y, d.z, glm::degrees(std::asin(d.y)),
            glm::degrees(std::atan2(d.x, -d.z)), c.r, c.g, c.b, l.intensity(), 100.0 * l.share,
            what);
    }
}

void runReplay(const ReplayArgs& a) {
    SessionReadReport readReport;
    // Rows need only the main camera: an environment video that ends early does not shorten the
    // replay (the static environment takes over).
    Session session = readSession(a.session, &readReport, SessionReadOptions{true});
    for (const auto& w : readReport.warnings) spdlog::warn("session: {}", w);
    const SessionCamera* main = nullptr;
    for (const auto& c : session.cameras)
        if (c.role == "main") main = &c;
    if (!main && !session.cameras.empty()) main = &session.cameras.front();
    if (!main) throw FileError(a.session, "the session lists no camera");

    // Outputs are checked before any work: never one of the inputs, never an unnamed existing
    // file without --force; written under temporary names and renamed when finished.
    const std::filesystem::path userOut = a.output;
    const bool split = !a.shard.empty();
    const ShardSpec shard = split ? parseShardSpec(a.shard) : ShardSpec{};
    const bool userMkv = isVideoOutput(userOut, "mirage replay");
    OutputRule rule{sessionInputs(session), a.force, "mirage replay"};
    rule.inputs.push_back(a.scene);
    if (!a.poses.empty()) rule.inputs.push_back(a.poses);
    if (!a.staticEnv.empty()) rule.inputs.push_back(a.staticEnv);
    // A shard (--shard I/N: the I-th of N contiguous blocks of the frames) writes PNG frames and
    // its CSV rows into OUT.shards/I-of-N; `mirage merge OUT` makes OUT of them.
    std::optional<StagedPath> staged;
    if (split) {
        checkOutput(userOut, OutputOrigin::Named, rule, /*outIsFolder=*/!userMkv);
        const auto dir = shardFolder(userOut, shard);
        if (std::filesystem::exists(dir / "shard.json") && !a.force)
            throw FileError(dir.string(),
                            "this shard is already complete; pass --force to replay it again");
        staged.emplace(dir);
        std::filesystem::create_directories(staged->temp());
    }
    const std::filesystem::path out = split ? staged->temp() : userOut;
    const bool mkv = split ? false : userMkv;
    std::optional<OutputFile> videoOut;
    std::filesystem::path csvPath;
    if (mkv) {
        videoOut.emplace(out, OutputOrigin::Named, rule);
        csvPath = std::filesystem::path(out).replace_extension(".csv");
    } else {
        if (!split) checkOutput(out, OutputOrigin::Named, rule, /*outIsFolder=*/true);
        csvPath = out / "frames.csv";
    }
    OutputFile csvOut(csvPath, OutputOrigin::Derived, rule);
    if (main->calibration.empty())
        throw FileError(a.session, "camera '" + main->name +
                                       "' has no calibration file; calibrate it (mirage calibrate) "
                                       "and name the YAML in session.json");
    const CameraCalibration calib = loadCalibration(session.path(main->calibration));
    checkLooksLikeGltf(a.scene);
    Scene scene = loadScene(a.scene);
    // The virtual objects where a live session placed them (SCENE.placement.json), on the plane
    // of the session's board.
    const std::filesystem::path placementFile =
        a.placement.empty() ? placementPath(a.scene) : std::filesystem::path(a.placement);
    if (const auto placement = loadPlacement(placementFile);
        placement && !placement->isIdentity()) {
        if (session.board.empty() || !std::filesystem::exists(session.path(session.board)))
            throw FileError(placementFile.string(),
                            "places the virtual objects on the tag board, but the session has "
                            "no board file");
        applyPlacement(scene, *placement,
                       boardPlane(tracking::Board::load(session.path(session.board))));
        spdlog::info("replay: virtual objects placed as {} says", placementFile.string());
    }
    if (!a.staticEnv.empty()) {
        // The given map replaces the scene's environment image; a scene's equirectangular
        // intensity and rotation are kept (they describe the room, not the file).
        readLinearRgb(a.staticEnv);  // a clear FileError now rather than at the renderer
        if (scene.environment.kind != Environment::Kind::Equirectangular) {
            scene.environment.intensity = 1.0f;
            scene.environment.rotationYDeg = 0.0;
        }
        scene.environment.kind = Environment::Kind::Equirectangular;
        scene.environment.image = std::filesystem::absolute(a.staticEnv);
        scene.environment.origin = Origin::Real;
    }
    if (!scene.hasVirtual())
        spdlog::warn("scene {} has no virtual object: the output will equal the footage", a.scene);

    std::map<int, PoseRow> poses;
    const bool useTracked = !a.poses.empty();
    std::unique_ptr<tracking::Tracker> tracker;
    if (useTracked) {
        poses = readPosesCsv(a.poses);
    } else if (!a.groundTruth && !session.board.empty() &&
               std::filesystem::exists(session.path(session.board))) {
        tracking::TrackerOptions trackerOptions;
        trackerOptions.features.enabled = !a.boardOnly;
        tracker = std::make_unique<tracking::Tracker>(
            tracking::Board::load(session.path(session.board)), calib.intrinsics, trackerOptions);
        spdlog::info("replay: tracking the camera on {}", session.path(session.board).string());
    } else {
        spdlog::info("replay: camera poses from the session's ground truth (frames.csv){}",
                     a.groundTruth ? "" : " (the session has no board file to track)");
    }

    gl::ContextOptions copt;
    copt.width = calib.intrinsics.width;
    copt.height = calib.intrinsics.height;
    copt.title = "mirage replay";
    gl::Context ctx = a.window ? gl::Context::window(copt) : gl::Context::headless(copt);
    render::RendererOptions ropt;
    ropt.vplCount = a.vpls;
    ropt.exposure = a.exposure;
    switchEffectsOff(a.effectsOff, ropt);
    if (a.estimateLights) {
        // As many as light estimation reports, within the renderer's light budget.
        const int room = render::kMaxLights - int(scene.lightInstances().size());
        if (room <= 0)
            throw Error(fmt::format(
                "mirage replay --estimate-lights: scene {} already has {} lights, the real-time "
                "renderer's limit; remove one or use --report-lights",
                a.scene, render::kMaxLights));
        ropt.environmentLights = std::min(render::LightEstimationOptions{}.maxLights, room);
    }
    render::Renderer renderer(scene, calib.intrinsics, ropt);

    // The environment camera, unless --static-env overrides it.
    std::optional<render::SessionEnvironment> env;
    std::string envState = "static";
    auto fallBack = [&](const std::string& why) {
        spdlog::warn(
            "replay: environment camera: {}; the replay continues with the scene's static "
            "environment",
            why);
        renderer.useStaticEnvironment();
        env.reset();
        envState = "static";
    };
    if (a.staticEnv.empty()) {
        std::string why;
        env = render::SessionEnvironment::open(session, a.exposure, why);
        if (env) {
            renderer.setEnvironmentCamera(env->setup());
            spdlog::info(
                "replay: the environment is camera '{}' ({}), updated with each of its frames",
                env->cameraName(), env->videoName());
            if (!env->hasRadiometry())
                spdlog::warn(
                    "replay: the environment camera's calibration has no radiometry_to_main: its "
                    "pixels are taken to be in the main camera's units (docs/environment.md)");
        } else if (!why.empty()) {
            fallBack(why);
        }
    } else {
        for (const SessionCamera& c : session.cameras)
            if (c.role == "environment")
                spdlog::info("replay: --static-env {} is the environment; camera '{}' is not used",
                             a.staticEnv, c.name);
    }

    // Output.
    std::unique_ptr<MatroskaWriter> video;
    if (mkv) video = std::make_unique<MatroskaWriter>(videoOut->temp(), session.fps, a.jpegQuality);
    std::ofstream csv(csvOut.temp());
    if (!csv) throw FileError(csvPath.string(), "cannot create the timing CSV");
    const std::vector<std::string> passes = renderer.passNames();  // the frame graph's order
    csv << "frame,t,state,reason,decode_ms,tracking_ms";
    for (const std::string& p : passes) csv << "," << p << "_ms";
    csv << ",gpu_ms,readback_ms,encode_ms,frame_ms,tx,ty,tz,qw,qx,qy,qz,environment\n";

    auto frames = openCameraFrames(session, main->name);
    const int listed = int(session.frames.size());
    if (a.start >= listed)
        throw Error(fmt::format("mirage replay: --start {} is beyond the session's {} frames",
                                a.start, listed));
    const int wanted =
        a.maxFrames >= 0 ? std::min(a.maxFrames, listed - a.start) : listed - a.start;
    // The frames written: [begin, begin + total) of the session's list; a shard's block of them.
    const std::vector<int> block = selectBlock(listed, ItemRange{a.start, a.start + wanted}, shard);
    if (block.empty())
        throw Error(
            fmt::format("mirage replay: shard {}/{} holds none of the {} frames; use at "
                        "most as many shards as frames",
                        shard.index, shard.count, wanted));
    const int begin = block.front();
    const int total = int(block.size());
    const int first = std::max(0, begin - a.warmup);  // warm-up frames are not written
    installStopSignals();
    cv::Mat bgr;
    for (int i = 0; i < first && frames->read(bgr); ++i) {
    }
    const auto tStart = Clock::now();
    FrameCompositor compositor(renderer, tracker.get());
    int done = 0;
    int processed = 0;
    std::vector<std::pair<int, double>> written;  // a shard's frames with an image, and times
    for (int pos = first; pos < begin + total && !stopped(); ++pos) {
        const FrameRecord& rec = session.frames[size_t(pos)];
        const bool emit = pos >= begin;
        const auto t0 = Clock::now();
        if (!frames->read(bgr)) {
            spdlog::warn("replay: the video ends after {} frames", pos);
            break;
        }
        const double decodeMs = msSince(t0);
        const double tFrame = rec.timestamps.empty() ? pos / session.fps : rec.timestamps.front();
        const std::string problem = frames->lastProblem();
        std::optional<PoseRow> given;  // nullopt: tracked (or lost) by the compositor
        if (bgr.empty() || tracker) {
        } else if (useTracked) {
            auto it = poses.find(rec.index);
            PoseRow row =
                it != poses.end() ? it->second : PoseRow{"lost", "no row in the poses file", {}};
            if (row.state != "ok" && row.state != "tracking") row.pose.reset();
            given = row;
        } else if (rec.groundTruth) {
            given = PoseRow{"ground_truth", "", rec.groundTruth};
        } else {
            given = PoseRow{"lost", "no ground-truth pose in frames.csv", std::nullopt};
        }
        if (env) {
            cv::Mat envFrame;
            double envT = 0;
            std::string envProblem;
            switch (env->next(rec, envFrame, envT, envProblem)) {
                case render::SessionEnvironment::Status::Frame:
                    try {
                        renderer.updateEnvironment(envFrame, envT);
                        envState = "camera";
                    } catch (const Error& e) {
                        fallBack(e.what());
                    }
                    break;
                case render::SessionEnvironment::Status::Lost:
                    spdlog::warn("replay: {}; the last environment frame is kept", envProblem);
                    envState = "camera (held)";
                    break;
                case render::SessionEnvironment::Status::None:
                    envState = "camera (held)";
                    break;
                case render::SessionEnvironment::Status::Ended:
                    fallBack(envProblem);
                    break;
            }
        }
        CompositedFrame cf = compositor.process(bgr, tFrame, problem, given);
        const PoseRow& pr = cf.pose;
        if (bgr.empty()) spdlog::warn("replay: {}", pr.reason);
        const double trackingMs = cf.trackingMs;
        std::map<std::string, double>& passMs = cf.passMs;
        const double gpuMs = cf.gpuMs, readbackMs = cf.readbackMs;
        const cv::Mat& result = cf.image;
        if ((a.estimateLights || a.reportLights) && cf.report && cf.report->ran("environment")) {
            if (a.estimateLights && renderer.environmentLive())
                logEnvironmentLights(rec.index, renderer.environmentLights().lights,
                                     "placed as a shadow-casting light, its region taken out of "
                                     "the environment light");
            else
                logEnvironmentLights(rec.index,
                                     render::estimateLights(renderer.readEnvironmentMap()),
                                     renderer.environmentLive()
                                         ? "reported, not placed (--estimate-lights places it)"
                                         : "reported, not placed (lights are placed from an "
                                           "environment camera only)");
        }
        if (cf.report && a.verbose && processed == 0)
            spdlog::info("frame {}:\n{}", rec.index, cf.report->summary());
        if (cf.report && a.window)
            compositor.blitToWindow(calib.intrinsics.width, calib.intrinsics.height);
        ++processed;
        if (!emit) continue;  // warm-up: history and tracking only
        const auto t3 = Clock::now();
        const double t = tFrame;
        if (!result.empty()) {  // a lost frame has no image: only its CSV row is written
            if (split) written.push_back({rec.index, t});
            if (video)
                video->append(result, t);
            else
                writeBgr8(out / cv::format("frame_%06d.png", rec.index), result);
        }
        const double encodeMs = msSince(t3);
        if (a.window) {
            ctx.swapBuffers();
            ctx.pollEvents();
            if (ctx.shouldClose()) gWindowClosed = true;
        }
        std::string reason = pr.reason;  // keep the CSV's columns: no commas or newlines inside
        for (char& ch : reason)
            if (ch == ',' || ch == '\n') ch = ';';
        csv << rec.index << "," << t << "," << pr.state << "," << reason << "," << decodeMs << ","
            << trackingMs;
        for (const std::string& p : passes) csv << "," << passMs[p];
        csv << "," << gpuMs << "," << readbackMs << "," << encodeMs << "," << msSince(t0);
        if (pr.pose) {
            const Pose& p = *pr.pose;
            csv << "," << p.translation.x << "," << p.translation.y << "," << p.translation.z << ","
                << p.rotation.w << "," << p.rotation.x << "," << p.rotation.y << ","
                << p.rotation.z;
        } else {
            csv << ",,,,,,,";
        }
        csv << "," << envState << "\n";
        csv.flush();
        ++done;
        progress(done, total, done / std::max(1e-9, msSince(tStart) * 1e-3));
    }
    if (isatty(STDERR_FILENO)) std::fprintf(stderr, "\n");
    // Interrupted or not, the frames done so far become the outputs (a playable video and its
    // CSV); an interruption still exits non-zero so that scripts do not take it for a full run.
    if (video) video->close();
    closeChecked(csv, csvPath);
    if (videoOut) videoOut->commit();
    csvOut.commit();
    restoreStopSignals();
    if (split && !stopRequested()) {
        ReplayShard rs;
        rs.shard = shard;
        rs.listed = listed;
        rs.range = ItemRange{a.start, a.start + wanted};
        rs.frames = block;
        rs.output = userOut;
        rs.video = userMkv;
        rs.fps = session.fps;
        rs.jpegQuality = a.jpegQuality;
        rs.warmup = begin - first;
        rs.written = written;
        rs.fingerprint = hex64(fingerprint64(fmt::format(
            "{} {} {} {} {} {:.9g} {} {} {} {} {}", std::filesystem::absolute(a.session).string(),
            a.poses, a.vpls, a.groundTruth, a.warmup, a.exposure, hex64(fileFingerprint(a.scene)),
            userMkv,
            std::filesystem::exists(placementFile) ? hex64(fileFingerprint(placementFile))
                                                   : std::string(),
            a.staticEnv.empty() ? "" : hex64(fileFingerprint(a.staticEnv)), a.estimateLights)));
        finishReplayShard(*staged, rs);
        return;
    }
    if (stopRequested()) {
        spdlog::warn("replay: interrupted after {} frames; {} is playable", done, a.output);
        commandExitCode() = 128 + stopSignal();
    }
    spdlog::info("replay: {} frames -> {} (timings: {})", done, a.output, csvPath.string());
}

const CommandRegistrar reg("replay", [](CLI::App& parent) {
    auto args = std::make_shared<ReplayArgs>();
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
        ->required();
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
                    "frames, each warmed up) into OUT.shards/; join with `mirage merge OUT`");
    cmd->add_option("--exposure", args->exposure, "Rendered radiance -> camera linear units")
        ->check(finiteIn(0, 1e6, true));
    cmd->add_option("--static-env", args->staticEnv,
                    "Light with this equirectangular image (.exr/.hdr/.pfm, linear) instead of "
                    "the session's environment camera")
        ->check(CLI::ExistingFile);
    cmd->add_option("--off", args->effectsOff,
                    "Switch these effects off (comma-separated, as `mirage bench` names them): " +
                        effectSwitchNames())
        ->delimiter(',')
        ->check(effectSwitchName());
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
    cmd->callback([args] { runReplay(*args); });
});

}  // namespace
}  // namespace mirage::app
