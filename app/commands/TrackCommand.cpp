// `mirage track`: camera poses (T_world_camera) per frame from a session or a plain video, to CSV,
// with a summary (docs/tracking.md). Wiring only: the work is in tracking/.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include <opencv2/imgproc.hpp>

#include "app/Command.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CalibrationFile.h"
#include "core/image/ImageIO.h"
#include "core/plot/SvgPlot.h"
#include "core/session/Session.h"
#include "core/session/SessionReadOptions.h"
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
    bool noWindowSearch = false;
    bool boardOnly = false;
    std::string driftSvg;  // drift of extended tracking against the time without the board
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

// What `track` reads: the frames, the calibration and board files, and for a session its
// metadata and what reading it found wrong.
struct TrackInputs {
    bool fromSession = false;
    Session session;
    SessionReadReport readReport;
    std::unique_ptr<FrameSource> frames;
    std::filesystem::path calibPath, boardPath;
    std::vector<std::string> missingVideos;  // session cameras whose video is not there
};

TrackInputs openInputs(const TrackArgs& a) {
    TrackInputs in;
    in.fromSession = !a.session.empty();
    if (in.fromSession == !a.video.empty())
        throw Error(
            "mirage track: give either SESSION or --video V --calib CAM.yaml --board B.json");
    if (!in.fromSession) {
        if (a.calib.empty() || a.board.empty())
            throw Error("mirage track --video needs --calib CAM.yaml and --board BOARD.json");
        in.calibPath = a.calib;
        in.boardPath = a.board;
        in.frames = openFrames(a.video);
        return in;
    }
    // The environment camera is needed only for --envmap: without it, the main camera's rows
    // are kept where the environment video is missing or short.
    SessionReadOptions options;
    options.environmentOptional = a.envmap.empty();
    in.session = readSession(a.session, &in.readReport, options);
    for (const auto& w : in.readReport.warnings) spdlog::warn("session: {}", w);
    for (const SessionCamera& c : in.session.cameras)
        if (!std::filesystem::exists(in.session.path(c.video)))
            in.missingVideos.push_back("camera '" + c.name + "': " + c.video + " is missing");
    const SessionCamera* cam = in.session.camera(a.camera);
    if (!cam) throw FileError(a.session, "session has no camera '" + a.camera + "'");
    if (!a.calib.empty())
        in.calibPath = a.calib;
    else if (cam->calibration.empty())
        throw FileError(a.session,
                        "camera '" + a.camera + "' has no calibration file; pass --calib");
    else
        in.calibPath = in.session.path(cam->calibration);
    in.boardPath =
        a.board.empty() ? in.session.path(in.session.board) : std::filesystem::path(a.board);
    if (in.session.frames.empty())
        throw FileError(
            a.session,
            "no frame to track: " + std::to_string(in.readReport.framesListed) +
                " frames listed, none readable in every camera it needs" +
                (in.readReport.warnings.empty() ? std::string()
                                                : " (" + in.readReport.warnings.front() + ")"));
    in.frames = openCameraFrames(in.session, a.camera);
    return in;
}

// The optional environment map from the session's fish-eye camera, posed by its extrinsic: fixed
// in the world, or relative to the main camera (T_world_env = T_world_main * T_main_env, only in
// frames where the main camera is tracked ok).
struct EnvironmentInput {
    std::unique_ptr<FrameSource> frames;
    CameraCalibration calib;
    std::optional<tracking::EnvironmentMap> map;
    int updates = 0;

    void update(const tracking::TrackedFrame& f) {
        cv::Mat env;
        if (!frames->read(env) || env.empty()) return;
        std::optional<Pose> T_world_env;
        if (calib.extrinsicParent == "world")
            T_world_env = *calib.T_parent_camera;
        else if (f.estimate.state == tracking::TrackingState::Ok)
            T_world_env = *f.estimate.pose * *calib.T_parent_camera;
        if (T_world_env) {
            map->update(env, calib.intrinsics, *T_world_env);
            ++updates;
        }
    }
};

std::unique_ptr<EnvironmentInput> openEnvironment(const TrackArgs& a, const TrackInputs& in) {
    if (a.envmap.empty()) return nullptr;
    if (!in.fromSession)
        throw Error("mirage track --envmap needs a session with a fish-eye camera");
    const Session& session = in.session;
    std::string name = a.envCamera;
    if (name.empty())
        for (const auto& c : session.cameras)
            if (c.role == "environment") name = c.name;
    const SessionCamera* ec = session.camera(name);
    if (!ec)
        throw FileError(a.session, "no environment camera (role \"environment\" or --env-camera)");
    if (ec->calibration.empty())
        throw FileError(a.session, "environment camera '" + name + "' has no calibration file");
    auto env = std::make_unique<EnvironmentInput>();
    env->calib = loadCalibration(session.path(ec->calibration));
    if (!env->calib.T_parent_camera)
        throw FileError(
            session.path(ec->calibration).string(),
            "T_parent_camera missing: the fish-eye's pose (parent main or world) is needed");
    env->frames = openCameraFrames(session, name);
    env->map.emplace(a.envmapWidth);
    // Beyond the calibration data's reach the fish-eye model is extrapolated: not sampled.
    if (env->calib.reachDeg > 0) {
        env->map->setReachDeg(env->calib.reachDeg);
        spdlog::warn(
            "{}: the calibration reaches {:.1f} deg off-axis; environment-map directions "
            "beyond it are not sampled (left unseen in the validity map). Calibrate with "
            "boards nearer the rim to widen it.",
            session.path(ec->calibration).string(), env->calib.reachDeg);
    }
    return env;
}

// Rotation error and translation error (percent of the distance) of the poses not from the board
// alone, against the seconds since the last board pose.
void writeDriftPlot(const tracking::TrackingReport& report, const std::filesystem::path& svg,
                    const std::string& source) {
    plot::LinePlot p;
    p.title = "Extended tracking: error without the board (" +
              std::filesystem::path(source).filename().string() + ")";
    p.xLabel = "seconds since the last pose from the board";
    p.yLabel = "error (deg, % of distance)";
    plot::Series rot{"rotation error (deg)", {}}, pos{"translation error (% of distance)", {}};
    for (const auto& d : report.drift()) {
        rot.points.push_back({d.secondsWithoutBoard, d.rotErrDeg, ""});
        pos.points.push_back({d.secondsWithoutBoard, 100 * d.posErrRel, ""});
    }
    p.series = {rot, pos};
    std::ofstream out(svg);
    out << plot::svgLines(p);
    if (!out) throw FileError(svg.string(), "cannot write the drift plot");
}

tracking::TrackerOptions trackerOptions(const TrackArgs& a) {
    tracking::TrackerOptions opt = a.options;
    opt.filterEnabled = !a.noFilter;
    opt.tagTracking = !a.noTagTracking;
    opt.textureRegion = !a.noTextureRegion;
    opt.coarseFirst = !a.noCoarseFirst;
    opt.windowRetry = opt.coarseFirstCascade = !a.noWindowSearch;
    opt.features.enabled = !a.boardOnly;
    opt.fullResolutionFallback = !a.noFullResolutionFallback;
    if (a.filter == "one-euro")
        opt.filterKind = tracking::FilterKind::OneEuro;
    else if (a.filter != "predictive")
        throw Error("mirage track --filter: expected predictive or one-euro, got '" + a.filter +
                    "'");
    return opt;
}

struct TrackLoopCounts {
    int framesRead = 0;  // frames the source delivered (lost ones included)
    int repeats = 0;     // frames that repeat the previous one exactly
};

// Tracks every frame of `in.frames` into `report` (and `env`, if given) until the end or a stop
// signal. A frame of another size than the calibration's is an error before anything is written.
TrackLoopCounts trackFrames(const TrackArgs& a, TrackInputs& in, const CameraCalibration& calib,
                            tracking::Tracker& tracker, tracking::TrackingReport& report,
                            EnvironmentInput* env) {
    TrackLoopCounts n;
    for (int& i = n.framesRead; !stopRequested(); ++i) {
        cv::Mat bgr;
        const auto t0 = std::chrono::steady_clock::now();
        bool got = false;
        try {
            got = in.frames->read(bgr);
        } catch (const Error& e) {
            // A frame that cannot be decoded ends what this source can deliver.
            spdlog::warn("frame {}: {}; stopping here", i, e.what());
            const int total = in.frames->frameCount();
            report.addUnreadable(total > i ? total - i : 1);
            break;
        }
        if (!got) break;
        const double decodeMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        const double t = in.frames->lastTimestamp().value_or(i / a.fps);
        std::optional<Pose> gt;
        int frameIndex = i;
        if (in.fromSession && size_t(i) < in.session.frames.size()) {
            gt = in.session.frames[size_t(i)].groundTruth;
            frameIndex = in.session.frames[size_t(i)].index;
        }
        const std::string problem = in.frames->lastProblem();
        if (bgr.empty()) {
            // Lost with its reason (damaged bytes): never tracked from a concealed image.
            const tracking::TrackedFrame f =
                tracker.markLost(t, problem.empty() ? "frame not decodable" : problem);
            report.addUnreadableFrame(frameIndex, f);
            spdlog::warn("{}", f.estimate.reason);
            continue;
        }
        if (!problem.empty()) {
            ++n.repeats;
            spdlog::warn("{}", problem);
        }
        if (bgr.cols != calib.intrinsics.width || bgr.rows != calib.intrinsics.height)
            throw FileError(in.calibPath.string(),
                            "is for " + std::to_string(calib.intrinsics.width) + "x" +
                                std::to_string(calib.intrinsics.height) +
                                " images, but the frames are " + std::to_string(bgr.cols) + "x" +
                                std::to_string(bgr.rows) +
                                "; pass the calibration of this camera at this resolution");
        const tracking::TrackedFrame f = tracker.process(bgr, t);
        report.add(frameIndex, f, gt, decodeMs);
        if (env) env->update(f);
    }
    return n;
}

// The exit status says whether the job was done: 0 when every frame was read and some tracked;
// 2 when poses were written but part of the input could not be read (the counts say how much);
// an error (exit 1) when no frame has a pose.
void reportOutcome(const TrackArgs& a, const TrackInputs& in,
                   const tracking::TrackingReport& report, const TrackLoopCounts& n) {
    if (n.repeats > 0)
        spdlog::warn("{} frame(s) repeat the previous frame exactly (frozen or duplicated)",
                     n.repeats);
    spdlog::info("wrote {}\n{}", a.output, report.summary());
    if (stopRequested()) {
        spdlog::warn("track: interrupted after {} frames; {} holds them", n.framesRead, a.output);
        commandExitCode() = 128 + stopSignal();
        return;
    }
    // Frames the input lists but could not deliver: lost to damage, or dropped by the session
    // reader (missing from a video, bad rows).
    const int unreadable = report.unreadable();
    const int total = report.frames() + unreadable;
    const std::string counts =
        std::to_string(report.okFrames()) + " of " + std::to_string(total) + " frames tracked";
    if (report.okFrames() == 0)
        throw Error("track: nothing tracked (" + counts + ", " + std::to_string(unreadable) +
                    " unreadable); " + a.output + " lists each frame's reason");
    if (unreadable > 0 || !in.missingVideos.empty()) {
        std::string why = std::to_string(unreadable) + " frame(s) of the input could not be read";
        for (const std::string& m : in.missingVideos) why += "; " + m;
        spdlog::warn("track: {}; {} (see the warnings above); exit status 2", counts, why);
        commandExitCode() = 2;
        return;
    }
    spdlog::info("track: {}", counts);
}

void run(const TrackArgs& a) {
    TrackInputs in = openInputs(a);
    // Outputs are checked before any work (never an input; written under a temporary name and
    // renamed when done), see core/OutputFile.h.
    OutputRule rule{
        in.fromSession ? sessionInputs(in.session) : std::vector<std::filesystem::path>{a.video},
        a.force, "mirage track"};
    rule.inputs.push_back(in.calibPath);
    rule.inputs.push_back(in.boardPath);
    OutputFile posesOut(a.output, OutputOrigin::Named, rule);
    std::optional<OutputFile> envmapOut, validOut, driftOut;
    if (!a.driftSvg.empty()) driftOut.emplace(a.driftSvg, OutputOrigin::Named, rule);
    if (!a.envmap.empty()) {
        auto validPath = std::filesystem::path(a.envmap);
        validPath.replace_filename(validPath.stem().string() + "_valid.png");
        envmapOut.emplace(a.envmap, OutputOrigin::Named, rule);
        validOut.emplace(validPath, OutputOrigin::Derived, rule);
    }

    const CameraCalibration calib = loadCalibration(in.calibPath);
    const tracking::Board board = tracking::Board::load(in.boardPath);
    tracking::Tracker tracker(board, calib.intrinsics, trackerOptions(a));
    tracking::TrackingReport report(posesOut.temp(), boardCentre(board));
    if (in.fromSession)
        report.addUnreadable(in.readReport.framesListed - in.readReport.framesReadable);
    const std::unique_ptr<EnvironmentInput> env = openEnvironment(a, in);

    installStopSignals();
    const TrackLoopCounts n = trackFrames(a, in, calib, tracker, report, env.get());
    restoreStopSignals();
    if (n.framesRead == 0 && !stopRequested())
        throw Error("track: no frame could be read from " + (in.fromSession ? a.session : a.video));
    if (env) {
        writeLinearRgb(envmapOut->temp(), env->map->radiance());
        cv::Mat valid;
        cv::cvtColor(env->map->validity(), valid, cv::COLOR_GRAY2BGR);
        writeBgr8(validOut->temp(), valid);
        envmapOut->commit();
        validOut->commit();
        spdlog::info("environment map {} ({} frames, {:.1f} % of directions seen; validity {})",
                     a.envmap, env->updates, 100 * env->map->validFraction(),
                     validOut->path().string());
    }
    report.close();
    posesOut.commit();
    if (driftOut) {
        writeDriftPlot(report, driftOut->temp(), a.session.empty() ? a.video : a.session);
        driftOut->commit();
    }
    reportOutcome(a, in, report, n);
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
    cmd->add_option("-o,--output", a->output, "POSES.csv (or /dev/stdout, a FIFO: written through)")
        ->required()
        ->check(outputPath(OutputShape::File));
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
                    "(.exr/.pfm/.hdr linear; validity mask beside it as <name>_valid.png)")
        ->check(outputPath(OutputShape::File));
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
    cmd->add_flag("--no-window-search", a->noWindowSearch,
                  "Without a recent pose, when the decimated search finds no tag do not search "
                  "the coarse-first window at finer decimations first (docs/tracking.md, Single "
                  "frames: the window at finer decimations)");
    cmd->add_flag("--board-only", a->boardOnly,
                  "Poses from the board's tags only: no natural features (docs/tracking.md, "
                  "Extended tracking)");
    cmd->add_option("--drift-svg", a->driftSvg,
                    "Plot the error of the poses from natural features against the time "
                    "without the board (needs ground truth) to this SVG file")
        ->check(outputPath(OutputShape::File));
    cmd->add_flag("--no-full-resolution-fallback", a->noFullResolutionFallback,
                  "Do not search again at full resolution for the board tags the decimated "
                  "search missed (docs/tracking.md, Adaptive detection)");
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
