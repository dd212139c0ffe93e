// `mirage proxies SESSION --scene VIRTUAL.gltf -o SCENE.gltf`: rebuilds the real proxies (the
// table, the objects on it, their albedo) and the real spot light from a session's footage and
// writes them, with the virtual objects of VIRTUAL.gltf, as a scene for `mirage replay` and
// `mirage live` (docs/reconstruction.md). Beside it: SCENE.report.json (what was found, sizes,
// residuals), SCENE.proxies.bin and SCENE.table.png.
//
// Camera poses, as the replay takes them: --poses POSES.csv (`mirage track`'s rows), else
// --ground-truth (the session's frames.csv), else the tracker on the session's board. Only frames
// whose tracking state is ok are used; the others are counted and named in the log.
#include <chrono>
#include <fstream>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "app/BoardPlane.h"
#include "app/Command.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/commands/TerminalProgress.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CalibrationFile.h"
#include "core/scene/Scene.h"
#include "core/session/PosesCsv.h"
#include "core/session/Session.h"
#include "core/session/SessionReadOptions.h"
#include "render/SessionEnvironment.h"
#include "render/reconstruction/GeometryEvaluation.h"
#include "render/reconstruction/ProxyReconstruction.h"
#include "render/reconstruction/ProxyScene.h"
#include "tracking/Tracker.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;
namespace rc = reconstruction;

struct ProxiesArgs {
    std::string session, scene, output, poses, truth;
    bool groundTruth = false, force = false;
    int maxFrames = -1;
    double minParallaxDeg = rc::FootageCheckOptions{}.minParallaxDeg;
    int minFrames = rc::FootageCheckOptions{}.minFrames;
    int triangleBudget = rc::GeometryOptions{}.triangleBudgetPerObject;
    rc::StereoOptions stereo;
    rc::CarvingOptions carving;
    bool noCarving = false;
};

// The board's plane with the extent of its tags and page (what is known to lie flat).
rc::BoardPlane boardPlaneOf(const tracking::Board& board) {
    const PlacementPlane p = boardPlane(board);
    rc::BoardPlane b;
    b.point = p.point, b.normal = glm::normalize(p.normal), b.axisU = glm::normalize(p.axisU);
    b.halfU = b.halfV = 0;
    auto extend = [&](const glm::dvec3& w) {
        const glm::dvec3 uvh = b.toPlane(w);
        b.halfU = std::max(b.halfU, std::abs(uvh.x));
        b.halfV = std::max(b.halfV, std::abs(uvh.y));
    };
    for (const auto& t : board.tags)
        for (const auto& c : t.cornersInWorld()) extend(c);
    if (board.sheet)
        for (double sx : {-0.5, 0.5})
            for (double sy : {-0.5, 0.5})
                extend(board.sheet->T_world_sheet *
                       glm::dvec3(sx * board.sheet->width, sy * board.sheet->height, 0.0));
    return b;
}

// The main camera's frames with trusted poses.
rc::Footage readFootage(const ProxiesArgs& a, const Session& session, const SessionCamera& main,
                        const CameraCalibration& calib, const tracking::Board* board) {
    rc::Footage footage;
    footage.camera = calib.intrinsics;
    std::map<int, PoseRow> poses;
    std::unique_ptr<tracking::Tracker> tracker;
    if (!a.poses.empty()) {
        poses = readPosesCsv(a.poses);
        spdlog::info("proxies: camera poses from {}", a.poses);
    } else if (!a.groundTruth && board) {
        tracker = std::make_unique<tracking::Tracker>(*board, calib.intrinsics);
        spdlog::info("proxies: tracking the camera on {}", session.path(session.board).string());
    } else {
        spdlog::info("proxies: camera poses from the session's ground truth (frames.csv)");
    }
    auto frames = openCameraFrames(session, main.name);
    TerminalProgress bar("proxies");
    const int total = a.maxFrames > 0 ? std::min(a.maxFrames, int(session.frames.size()))
                                      : int(session.frames.size());
    int notOk = 0;
    for (int i = 0; i < total; ++i) {
        cv::Mat bgr;
        if (!frames->read(bgr)) break;
        const FrameRecord& row = session.frames[size_t(i)];
        const double t = frames->lastTimestamp().value_or(double(row.index) / session.fps);
        std::optional<Pose> pose;
        std::string state = "ok", reason;
        if (bgr.empty()) {
            state = "lost", reason = frames->lastProblem();
            if (tracker) tracker->markLost(t, reason);
        } else if (tracker) {
            const tracking::TrackedFrame f = tracker->process(bgr, t);
            state = tracking::trackingStateName(f.estimate.state), reason = f.estimate.reason;
            if (f.estimate.state == tracking::TrackingState::Ok) pose = f.estimate.pose;
        } else if (!a.poses.empty()) {
            const auto it = poses.find(row.index);
            if (it == poses.end())
                state = "missing", reason = "no row in the poses file";
            else if (it->second.state != "ok" || !it->second.pose)
                state = it->second.state, reason = it->second.reason;
            else
                pose = it->second.pose;
        } else {
            pose = row.groundTruth;
            if (!pose) state = "missing", reason = "frames.csv has no ground-truth pose";
        }
        if (pose && !bgr.empty()) {
            footage.frames.push_back({row.index, t, bgr, *pose});
        } else {
            ++notOk;
            spdlog::debug("proxies: frame {} not used: {} {}", row.index, state, reason);
        }
        bar.update(i + 1, total, fmt::format("reading and tracking frame {}/{}", i + 1, total));
    }
    bar.finish();
    spdlog::info("proxies: {} of {} frames tracked (state ok); {} not used", footage.frames.size(),
                 total, notOk);
    return footage;
}

// The environment camera's irradiance on the table, from its first frame.
std::optional<glm::dvec3> environmentOnTable(const Session& session, const rc::Footage& footage) {
    std::string whyNot;
    auto env = render::SessionEnvironment::open(session, float(footage.exposure), whyNot);
    if (!env) {
        if (!whyNot.empty()) spdlog::warn("proxies: environment camera not used: {}", whyNot);
        return std::nullopt;
    }
    for (const FrameRecord& row : session.frames) {
        cv::Mat frame;
        double t = 0;
        std::string problem;
        const auto status = env->next(row, frame, t, problem);
        if (status == render::SessionEnvironment::Status::Ended) break;
        if (status != render::SessionEnvironment::Status::Frame || frame.empty()) continue;
        const Pose mainPose =
            footage.frames.empty() ? Pose{} : footage.frames.front().T_world_camera;
        return rc::environmentIrradiance(frame, env->setup().intrinsics,
                                         env->setup().poseInWorld(mainPose), env->setup().gain,
                                         footage.board.normal);
    }
    return std::nullopt;
}

// --truth: the rebuilt scene against the scene the footage was synthesised from (geometry
// scores, the spot light's errors), into the report and the console.
nlohmann::json compareWithTruth(const fs::path& truthPath, const fs::path& rebuiltPath,
                                const rc::Reconstruction& r) {
    const Scene truth = loadScene(truthPath);
    const Scene rebuilt = loadScene(rebuiltPath);
    const rc::GeometryScore g = rc::evaluateGeometry(truth, rebuilt, r.geometry.table.plane);
    nlohmann::json j;
    j["objects"] = nlohmann::json::array();
    for (const auto& o : g.objects) {
        j["objects"].push_back({{"name", o.name},
                                {"completeness_1cm", o.completeness},
                                {"mean_mm", o.meanMm},
                                {"p95_mm", o.p95Mm}});
        std::printf(
            "truth %s: %.1f %% of its surface within 1 cm of the rebuilt geometry "
            "(mean %.1f mm, 95th percentile %.1f mm)\n",
            o.name.c_str(), 100 * o.completeness, o.meanMm, o.p95Mm);
    }
    j["accuracy_1cm"] = g.accuracy;
    j["accuracy_mean_mm"] = g.accuracyMeanMm;
    j["accuracy_p95_mm"] = g.accuracyP95Mm;
    std::printf(
        "rebuilt geometry above the table: %.1f %% within 1 cm of the truth (mean %.1f mm, "
        "95th percentile %.1f mm)\n",
        100 * g.accuracy, g.accuracyMeanMm, g.accuracyP95Mm);
    for (const LightInstance& li : truth.lightInstances()) {
        const Light& l = truth.lights[size_t(li.light)];
        if (li.origin != Origin::Real || l.type != Light::Type::Spot || !r.lighting.spot) continue;
        const rc::FittedSpotLight& s = *r.lighting.spot;
        const glm::dvec3 trueI = glm::dvec3(l.color) * double(l.intensity);
        const double positionCm = 100 * glm::length(s.position - li.position);
        const double directionDeg =
            glm::degrees(std::acos(std::clamp(glm::dot(s.direction, li.direction), -1.0, 1.0)));
        const double intensityPct =
            100 * (glm::dot(s.intensity, glm::dvec3(1)) / glm::dot(trueI, glm::dvec3(1)) - 1);
        j["spot"] = {{"position_error_cm", positionCm},
                     {"direction_error_deg", directionDeg},
                     {"outer_cone_error_deg", glm::degrees(s.outerConeRad - l.outerConeAngle)},
                     {"inner_cone_error_deg", glm::degrees(s.innerConeRad - l.innerConeAngle)},
                     {"intensity_error_pct", intensityPct}};
        std::printf(
            "spot light against the truth: position %.1f cm, direction %.1f deg, cones "
            "%+.1f/%+.1f deg, intensity %+.1f %%\n",
            positionCm, directionDeg, glm::degrees(s.innerConeRad - l.innerConeAngle),
            glm::degrees(s.outerConeRad - l.outerConeAngle), intensityPct);
        break;
    }
    return j;
}

void runProxies(const ProxiesArgs& a) {
    Session session = readSession(a.session, nullptr, SessionReadOptions{true});
    const SessionCamera* main = nullptr;
    for (const auto& c : session.cameras)
        if (c.role == "main") main = &c;
    if (!main && !session.cameras.empty()) main = &session.cameras.front();
    if (!main) throw FileError(a.session, "the session lists no camera");
    if (main->calibration.empty())
        throw FileError(a.session, "camera '" + main->name +
                                       "' has no calibration file; calibrate it (mirage "
                                       "calibrate) and name the YAML in session.json");
    if (session.board.empty() || !fs::exists(session.path(session.board)))
        throw FileError(a.session,
                        "has no board file: the table's plane comes from the tag board lying on "
                        "it; record with the board on the table and name board.json in "
                        "session.json");
    checkLooksLikeGltf(a.scene);
    OutputRule rule{sessionInputs(session), a.force, "mirage proxies"};
    rule.inputs.push_back(a.scene);
    if (!a.poses.empty()) rule.inputs.push_back(a.poses);
    const fs::path out(a.output);
    if (out.extension() != ".gltf")
        throw FileError(a.output, "the output must be a .gltf file (JSON, editable by hand)");
    checkOutput(out, OutputOrigin::Named, rule, /*outIsFolder=*/false);
    createParentFolders(out);
    // The report beside the scene, checked before any work and written under a temporary name.
    fs::path reportPath = out;
    reportPath.replace_extension(".report.json");
    OutputFile reportOut(reportPath, OutputOrigin::Derived, rule);

    const CameraCalibration calib = loadCalibration(session.path(main->calibration));
    const tracking::Board board = tracking::Board::load(session.path(session.board));
    rc::Footage footage = readFootage(a, session, *main, calib, &board);
    footage.board = boardPlaneOf(board);
    const std::optional<glm::dvec3> environment = environmentOnTable(session, footage);

    rc::ReconstructionOptions options;
    options.check.minFrames = a.minFrames;
    options.check.minParallaxDeg = a.minParallaxDeg;
    options.geometry.triangleBudgetPerObject = a.triangleBudget;
    options.stereo = a.stereo;
    options.carving = a.carving;
    options.carving.enabled = !a.noCarving;
    TerminalProgress bar("proxies");
    const rc::Reconstruction r =
        rc::reconstruct(footage, environment, options, [&](const std::string& stage, int d, int n) {
            bar.update(d, n, fmt::format("{} {}/{}", stage, d, n));
        });
    bar.finish();

    rc::ProxySceneContent content;
    content.geometry = &r.geometry;
    content.lighting = &r.lighting;
    content.camera = footage.frames.front().T_world_camera;
    content.yfov = 2.0 * std::atan(0.5 * calib.intrinsics.height / calib.intrinsics.fy);
    content.aspectRatio = double(calib.intrinsics.width) / calib.intrinsics.height;
    const rc::ProxySceneSummary written = rc::writeProxyScene(content, a.scene, out);
    nlohmann::json report = rc::reconstructionReport(r);
    report["session"] = a.session;
    report["virtual_scene"] = a.scene;
    report["dropped_real_nodes"] = written.droppedNodes;
    std::fputs(rc::reconstructionSummary(r).c_str(), stdout);
    if (!a.truth.empty()) report["truth"] = compareWithTruth(a.truth, out, r);
    {
        std::ofstream file(reportOut.temp());
        file << report.dump(2) << "\n";
        if (!file.flush()) throw FileError(reportPath.string(), "cannot write the report");
    }
    reportOut.commit();
    spdlog::info("proxies: wrote {} ({} real node(s) of {} replaced) and {}", out.string(),
                 written.droppedNodes, a.scene, reportPath.string());
}

const CommandRegistrar registrar("proxies", [](CLI::App& parent) {
    auto a = std::make_shared<ProxiesArgs>();
    auto* cmd = parent.add_subcommand(
        "proxies", "Rebuild the real proxies and lights of a session's footage as a scene");
    cmd->add_option("session", a->session, "Session folder (tracked main camera, board)")
        ->required();
    cmd->add_option("--scene", a->scene, "Scene (.gltf) whose virtual objects to keep")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", a->output, "Scene to write (.gltf)")
        ->required()
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--poses", a->poses, "Camera poses (mirage track's CSV) instead of tracking")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--ground-truth", a->groundTruth, "Use the session's ground-truth poses");
    cmd->add_option("--max-frames", a->maxFrames, "Use at most this many frames (-1: all)")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("--min-frames", a->minFrames, "Tracked frames needed")
        ->capture_default_str()
        ->check(wholeIn(1, 100000));
    cmd->add_option("--min-parallax", a->minParallaxDeg,
                    "Camera positions must span this angle seen from the board (degrees)")
        ->capture_default_str()
        ->check(finiteIn(0, 180));
    cmd->add_option("--triangles", a->triangleBudget, "Triangle budget per object")
        ->capture_default_str()
        ->check(wholeIn(12, 1000000));
    cmd->add_option("--stereo-partners", a->stereo.partnersPerFrame,
                    "Stereo partners per frame (depth maps of each frame at different baselines)")
        ->capture_default_str()
        ->check(wholeIn(1, 8));
    cmd->add_option("--stereo-baseline", a->stereo.preferredBaselineM,
                    "Preferred stereo baseline (metres, within 0.035-0.14)")
        ->capture_default_str()
        ->check(finiteIn(0.035, 0.14));
    cmd->add_option("--stereo-pairs", a->stereo.maxPairs, "Depth maps computed at most")
        ->capture_default_str()
        ->check(wholeIn(1, 10000));
    cmd->add_option("--stereo-smoothness", a->stereo.smoothness,
                    "SGBM's penalty for a depth jump (P2 per channel and window pixel; P1 is 8)")
        ->capture_default_str()
        ->check(wholeIn(9, 10000));
    cmd->add_option("--stereo-uniqueness", a->stereo.uniquenessRatio,
                    "SGBM's margin (percent) by which the best match must beat the second")
        ->capture_default_str()
        ->check(wholeIn(0, 100));
    cmd->add_option("--agreeing-maps", a->stereo.minAgreeingMaps,
                    "Other depth maps that must agree with a depth to keep it (0: keep all)")
        ->capture_default_str()
        ->check(wholeIn(0, 64));
    cmd->add_option("--agreement", a->stereo.agreementDepthFraction,
                    "Depth agreement tolerance as a share of the depth (plus 6 mm)")
        ->capture_default_str()
        ->check(finiteIn(0, 0.5));
    cmd->add_flag("--no-carving", a->noCarving,
                  "Objects from the fused stereo depth alone (no space carving against the table)");
    cmd->add_option("--carving-frames", a->carving.maxFrames,
                    "Frames the space carving uses at most (spread over the footage)")
        ->capture_default_str()
        ->check(wholeIn(2, 10000));
    cmd->add_option("--carving-tolerance", a->carving.colourTolerance,
                    "A pixel shows the table when its colour is within this share of the "
                    "table's there")
        ->capture_default_str()
        ->check(finiteIn(0.01, 2));
    cmd->add_option("--table-quantile", a->carving.diffuseQuantile,
                    "The table's diffuse colour per cell: this quantile of what the frames see "
                    "there (low: a glossy table's reflections add light in some views)")
        ->capture_default_str()
        ->check(finiteIn(0, 1));
    cmd->add_option("--truth", a->truth,
                    "The scene a synthetic session was made from: compare the rebuilt scene "
                    "with it (report and console)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--force", a->force, "Overwrite an existing output");
    cmd->callback([a] { runProxies(*a); });
});

}  // namespace
}  // namespace mirage::app
