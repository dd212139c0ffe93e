// `mirage track`: camera poses (T_world_camera) per frame from a session or a plain video, to CSV,
// with a summary (docs/tracking.md). Wiring only: the work is in tracking/.
#include <chrono>
#include <filesystem>
#include <memory>

#include "app/Command.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/session/Session.h"
#include "tracking/Board.h"
#include "tracking/Tracker.h"
#include "tracking/TrackingReport.h"

namespace mirage::app {
namespace {

struct TrackArgs {
    std::string session, video, calib, board, output, camera = "main";
    double fps = 30.0;
    bool noFilter = false;
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
    const CameraCalibration calib = loadCalibration(calibPath);
    const tracking::Board board = tracking::Board::load(boardPath);
    tracking::TrackerOptions opt = a.options;
    opt.filterEnabled = !a.noFilter;
    tracking::Tracker tracker(board, calib.intrinsics, opt);
    tracking::TrackingReport report(a.output, boardCentre(board));
    if (fromSession) report.addUnreadable(readReport.framesListed - readReport.framesReadable);

    int i = 0;
    for (;; ++i) {
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
        if (bgr.cols != calib.intrinsics.width || bgr.rows != calib.intrinsics.height) {
            f = tracker.markLost(t, "frame size " + std::to_string(bgr.cols) + "x" +
                                        std::to_string(bgr.rows) + " differs from the calibration");
        } else {
            f = tracker.process(bgr, t);
        }
        report.add(frameIndex, f, gt, decodeMs);
    }
    if (report.frames() == 0 && i == 0) spdlog::warn("no frame could be read");
    spdlog::info("wrote {}\n{}", a.output, report.summary());
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
        ->capture_default_str();
    cmd->add_flag("--no-filter", a->noFilter, "Report the raw per-frame poses");
    cmd->add_option("--decimate", a->options.detector.decimate, "Detector quad decimation")
        ->capture_default_str();
    cmd->add_option("--threads", a->options.detector.threads, "Detector threads")
        ->capture_default_str();
    cmd->add_option("--min-tag-px", a->options.pose.minTagSidePx, "Smallest usable tag side")
        ->capture_default_str();
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
