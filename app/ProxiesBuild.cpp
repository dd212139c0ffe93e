#include "app/ProxiesBuild.h"

#include <chrono>
#include <fstream>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "app/BoardPlane.h"
#include "app/InputChecks.h"
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
#include "render/reconstruction/ScanMap.h"
#include "tracking/Tracker.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;
namespace rc = reconstruction;

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
rc::Footage readFootage(const ProxiesRequest& a, const Session& session, const SessionCamera& main,
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

}  // namespace

void buildProxies(const ProxiesRequest& a) {
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
    fs::path mapPath = out;
    mapPath.replace_extension(".scan.svg");
    OutputFile mapOut(mapPath, OutputOrigin::Derived, rule);

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
    report["copied_files"] = written.copiedFiles;
    for (const std::string& f : written.copiedFiles)
        spdlog::info("proxies: copied {} beside the scene (the virtual scene refers to it)", f);
    std::fputs(rc::reconstructionSummary(r).c_str(), stdout);
    if (!a.truth.empty()) report["truth"] = compareWithTruth(a.truth, out, r);
    {
        std::ofstream file(reportOut.temp());
        file << report.dump(2) << "\n";
        if (!file.flush()) throw FileError(reportPath.string(), "cannot write the report");
    }
    reportOut.commit();
    {
        std::ofstream file(mapOut.temp());
        file << rc::scanMapSvg(footage, r);
        if (!file.flush()) throw FileError(mapPath.string(), "cannot write the scan map");
    }
    mapOut.commit();
    spdlog::info(
        "proxies: wrote {} ({} real node(s) of {} replaced), {} and the scan seen from "
        "above, {}",
        out.string(), written.droppedNodes, a.scene, reportPath.string(), mapPath.string());
}

}  // namespace mirage::app
