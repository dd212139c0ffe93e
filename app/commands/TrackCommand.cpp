// `mirage track`: camera poses (T_world_camera) per frame from a session or a plain video, to CSV,
// with a summary (docs/tracking.md). Wiring only: the work is in tracking/.
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include <opencv2/imgproc.hpp>

#include "app/Command.h"
#include "app/NumberChecks.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CalibrationFile.h"
#include "core/image/ImageIO.h"
#include "core/session/Session.h"
#include "tracking/Board.h"
#include "tracking/EnvironmentMap.h"
#include "tracking/Tracker.h"
#include "tracking/TrackingReport.h"

namespace mirage::app {
namespace {

struct TrackArgs {
    std::string session, video, calib, board, output, camera = "main";
    std::string envmap, envCamera;  // environment map output and the session's fish-eye camera
    int envmapWidth = 512;
    double fps = 30.0;
    bool noFilter = false;
    bool noTagTracking = false;
    bool noTextureRegion = false;
    bool noCoarseFirst = false;
    bool noFullResolutionFallback = false;
    bool force = false;
    std::string filter = "predictive";
    tracking::TrackerOptions options;
};

glm::dvec3 boardCentre(const tracking::Board& b) {
    glm::dvec3 c(0.0);
    for (const auto& t : b.tags) c += t.T_world_tag.translation;
    return c / double(b.tags.size());
}

void run(const TrackArgs& a) {
    const bool fromSession = !a.session.empty();
    if (fromSession == !a.video.empty())
        throw Error(
            "mirage track: give either SESSION or --video V --calib CAM.yaml --board B.json");
    Session session;
    SessionReadReport readReport;
    std::unique_ptr<FrameSource> frames;
    std::filesystem::path calibPath, boardPath;
    if (fromSession) {
        session = readSession(a.session, &readReport);
        for (const auto& w : readReport.warnings) spdlog::warn("session: {}", w);
        const SessionCamera* cam = session.camera(a.camera);
        if (!cam) throw FileError(a.session, "session has no camera '" + a.camera + "'");
        if (!a.calib.empty())
            calibPath = a.calib;
        else if (cam->calibration.empty())
            throw FileError(a.session,
                            "camera '" + a.camera + "' has no calibration file; pass --calib");
        else
            calibPath = session.path(cam->calibration);
        boardPath = a.board.empty() ? session.path(session.board) : std::filesystem::path(a.board);
        frames = openCameraFrames(session, a.camera);
    } else {
        if (a.calib.empty() || a.board.empty())
            throw Error("mirage track --video needs --calib CAM.yaml and --board BOARD.json");
        calibPath = a.calib;
        boardPath = a.board;
        frames = openFrames(a.video);
    }
    // Outputs are checked before any work (never an input; written under a temporary name and
    // renamed when done), see core/OutputFile.h.
    OutputRule rule{
        fromSession ? sessionInputs(session) : std::vector<std::filesystem::path>{a.video}, a.force,
        "mirage track"};
    rule.inputs.push_back(calibPath);
    rule.inputs.push_back(boardPath);
    OutputFile posesOut(a.output, OutputOrigin::Named, rule);
    std::optional<OutputFile> envmapOut, validOut;
    if (!a.envmap.empty()) {
        auto validPath = std::filesystem::path(a.envmap);
        validPath.replace_filename(validPath.stem().string() + "_valid.png");
        envmapOut.emplace(a.envmap, OutputOrigin::Named, rule);
        validOut.emplace(validPath, OutputOrigin::Derived, rule);
    }

    const CameraCalibration calib = loadCalibration(calibPath);
    const tracking::Board board = tracking::Board::load(boardPath);
    tracking::TrackerOptions opt = a.options;
    opt.filterEnabled = !a.noFilter;
    opt.tagTracking = !a.noTagTracking;
    opt.textureRegion = !a.noTextureRegion;
    opt.coarseFirst = !a.noCoarseFirst;
    opt.fullResolutionFallback = !a.noFullResolutionFallback;
    if (a.filter == "one-euro")
        opt.filterKind = tracking::FilterKind::OneEuro;
    else if (a.filter != "predictive")
        throw Error("mirage track --filter: expected predictive or one-euro, got '" + a.filter +
                    "'");
    tracking::Tracker tracker(board, calib.intrinsics, opt);
    tracking::TrackingReport report(posesOut.temp(), boardCentre(board));
    if (fromSession) report.addUnreadable(readReport.framesListed - readReport.framesReadable);

    // Optional environment map from the session's fish-eye camera, posed by its extrinsic: fixed in
    // the world, or relative to the main camera (T_world_env = T_world_main * T_main_env, only in
    // frames where the main camera is tracked ok).
    std::unique_ptr<FrameSource> envFrames;
    std::optional<CameraCalibration> envCalib;
    std::optional<tracking::EnvironmentMap> envMap;
    int envUpdates = 0;
    if (!a.envmap.empty()) {
        if (!fromSession)
            throw Error("mirage track --envmap needs a session with a fish-eye camera");
        std::string name = a.envCamera;
        if (name.empty())
            for (const auto& c : session.cameras)
                if (c.role == "environment") name = c.name;
        const SessionCamera* ec = session.camera(name);
        if (!ec)
            throw FileError(a.session,
                            "no environment camera (role \"environment\" or --env-camera)");
        if (ec->calibration.empty())
            throw FileError(a.session, "environment camera '" + name + "' has no calibration file");
        envCalib = loadCalibration(session.path(ec->calibration));
        if (!envCalib->T_parent_camera)
            throw FileError(
                session.path(ec->calibration).string(),
                "T_parent_camera missing: the fish-eye's pose (parent main or world) is needed");
        envFrames = openCameraFrames(session, name);
        envMap.emplace(a.envmapWidth);
        // Beyond the calibration data's reach the fish-eye model is extrapolated: not sampled.
        if (envCalib->reachDeg > 0) {
            envMap->setReachDeg(envCalib->reachDeg);
            spdlog::warn(
                "{}: the calibration reaches {:.1f} deg off-axis; environment-map directions "
                "beyond it are not sampled (left unseen in the validity map). Calibrate with "
                "boards nearer the rim to widen it.",
                session.path(ec->calibration).string(), envCalib->reachDeg);
        }
    }

    installStopSignals();
    int repeats = 0;
    int i = 0;
    for (; !stopRequested(); ++i) {
        cv::Mat bgr;
        const auto t0 = std::chrono::steady_clock::now();
        bool got = false;
        try {
            got = frames->read(bgr);
        } catch (const Error& e) {
            // A frame that cannot be decoded ends what this source can deliver.
            spdlog::warn("frame {}: {}; stopping here", i, e.what());
            const int total = frames->frameCount();
            report.addUnreadable(total > i ? total - i : 1);
            break;
        }
        if (!got) break;
        const double decodeMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        const double t = frames->lastTimestamp().value_or(i / a.fps);
        std::optional<Pose> gt;
        int frameIndex = i;
        if (fromSession && size_t(i) < session.frames.size()) {
            gt = session.frames[size_t(i)].groundTruth;
            frameIndex = session.frames[size_t(i)].index;
        }
        tracking::TrackedFrame f;
        const std::string problem = frames->lastProblem();
        if (bgr.empty()) {
            // Lost with its reason (damaged bytes): never tracked from a concealed image.
            f = tracker.markLost(t, problem.empty() ? "frame not decodable" : problem);
            report.addUnreadableFrame(frameIndex, f);
            spdlog::warn("{}", f.estimate.reason);
            continue;
        }
        if (!problem.empty()) {
            ++repeats;
            spdlog::warn("{}", problem);
        }
        if (bgr.cols != calib.intrinsics.width || bgr.rows != calib.intrinsics.height) {
            f = tracker.markLost(t, "frame size " + std::to_string(bgr.cols) + "x" +
                                        std::to_string(bgr.rows) + " differs from the calibration");
        } else {
            f = tracker.process(bgr, t);
        }
        report.add(frameIndex, f, gt, decodeMs);
        if (envFrames) {
            cv::Mat env;
            if (envFrames->read(env) && !env.empty()) {
                std::optional<Pose> T_world_env;
                if (envCalib->extrinsicParent == "world")
                    T_world_env = *envCalib->T_parent_camera;
                else if (f.estimate.state == tracking::TrackingState::Ok)
                    T_world_env = *f.estimate.pose * *envCalib->T_parent_camera;
                if (T_world_env) {
                    envMap->update(env, envCalib->intrinsics, *T_world_env);
                    ++envUpdates;
                }
            }
        }
    }
    restoreStopSignals();
    if (envMap) {
        writeLinearRgb(envmapOut->temp(), envMap->radiance());
        cv::Mat valid;
        cv::cvtColor(envMap->validity(), valid, cv::COLOR_GRAY2BGR);
        writeBgr8(validOut->temp(), valid);
        envmapOut->commit();
        validOut->commit();
        spdlog::info("environment map {} ({} frames, {:.1f} % of directions seen; validity {})",
                     a.envmap, envUpdates, 100 * envMap->validFraction(),
                     validOut->path().string());
    }
    report.close();
    posesOut.commit();
    if (repeats > 0)
        spdlog::warn("{} frame(s) repeat the previous frame exactly (frozen or duplicated)",
                     repeats);
    if (report.frames() == 0 && i == 0) spdlog::warn("no frame could be read");
    spdlog::info("wrote {}\n{}", a.output, report.summary());
    if (stopRequested()) {
        spdlog::warn("track: interrupted after {} frames; {} holds them", i, a.output);
        commandExitCode() = 128 + stopSignal();
    }
}

const CommandRegistrar reg("track", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand(
        "track", "Camera pose per frame (T_world_camera) from AprilTag boards, to CSV");
    auto a = std::make_shared<TrackArgs>();
    cmd->add_option("session", a->session, "Session folder (uses its board and calibration)");
    cmd->add_option("--video", a->video, "A video file or image folder instead of a session");
    cmd->add_option("--calib", a->calib, "OpenCV calibration YAML (overrides the session's)");
    cmd->add_option("--board", a->board, "Board file (overrides the session's)");
    cmd->add_option("--camera", a->camera, "Session camera to track")->capture_default_str();
    cmd->add_option("-o,--output", a->output, "POSES.csv")->required();
    cmd->add_option("--fps", a->fps, "Frame rate for sources without timestamps")
        ->capture_default_str()
        ->check(finiteIn(0, 1e6, true));
    cmd->add_flag("--force", a->force,
                  "Replace an existing file written beside an output (never an input)");
    cmd->add_flag("--no-filter", a->noFilter, "Report the raw per-frame poses");
    cmd->add_option("--filter", a->filter,
                    "Temporal filter: predictive (adaptive constant velocity) or one-euro")
        ->capture_default_str();
    cmd->add_option("--envmap", a->envmap,
                    "Also build an environment map from the session's fish-eye camera "
                    "(.exr/.pfm/.hdr linear; validity mask beside it as <name>_valid.png)");
    cmd->add_option("--env-camera", a->envCamera,
                    "Session camera for --envmap (default: the "
                    "one with role environment)");
    cmd->add_option("--envmap-width", a->envmapWidth, "Equirectangular width (height = width/2)")
        ->capture_default_str()
        ->check(wholeIn(8, 16384));
    cmd->add_option("--decimate", a->options.detector.decimate, "Detector quad decimation")
        ->capture_default_str()
        ->check(finiteIn(1, 64));
    cmd->add_option("--threads", a->options.detector.threads, "Detector threads")
        ->capture_default_str()
        ->check(wholeIn(1, 4096));
    cmd->add_option("--min-tag-px", a->options.pose.minTagSidePx, "Smallest usable tag side")
        ->capture_default_str()
        ->check(finiteIn(0, 1e5));
    cmd->add_flag("--no-tag-tracking", a->noTagTracking,
                  "Search every frame with libapriltag (region of interest) instead of finding "
                  "the tags where the predicted pose puts them (docs/tracking.md, Tracking mode)");
    cmd->add_flag("--no-texture-region", a->noTextureRegion,
                  "Without a recent pose, search the whole image instead of first the region "
                  "with the tags' contrast (docs/tracking.md, Single frames)");
    cmd->add_flag("--no-coarse-first", a->noCoarseFirst,
                  "Without a recent pose, do not pick a coarse-to-fine decimation from the "
                  "size of the textured region (docs/tracking.md, Single frames: coarse-first)");
    cmd->add_flag("--no-full-resolution-fallback", a->noFullResolutionFallback,
                  "Do not search again at full resolution for the board tags the decimated "
                  "search missed (docs/tracking.md, Adaptive detection)");
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
