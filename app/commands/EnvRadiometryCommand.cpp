// `mirage env-radiometry SESSION --scene SCENE`: the environment camera's gain and white balance
// relative to the main camera (radiometry_to_main, docs/environment.md "Radiometry"), estimated
// from the session's footage where both cameras see the same part of the room
// (render/EnvironmentRadiometry.h). Prints the ratio; --write stores it in the environment
// camera's calibration file (the rest of the file is kept).
//
// Main-camera poses: --poses POSES.csv (the `mirage track` format; rows that are not ok are
// skipped), else the session's ground truth (frames.csv). A session without either is refused
// (run `mirage track` first). Exit status 1, with what to do, when the cameras' views do not
// overlap enough for an estimate.
#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/Radiometry.h"
#include "core/scene/Scene.h"
#include "core/session/PosesCsv.h"
#include "core/session/Session.h"
#include "core/session/SessionReadOptions.h"
#include "render/EnvironmentRadiometry.h"
#include "render/SessionEnvironment.h"

namespace mirage::app {
namespace {

struct EnvRadiometryArgs {
    std::string session, scene, poses;
    int maxFrames = -1;
    int stride = 2;
    int minSamples = 200;
    bool write = false;
};

void runEnvRadiometry(const EnvRadiometryArgs& a) {
    SessionReadReport readReport;
    const Session session = readSession(a.session, &readReport, SessionReadOptions{true});
    for (const auto& w : readReport.warnings) spdlog::warn("session: {}", w);
    const SessionCamera* main = nullptr;
    const SessionCamera* envCam = nullptr;
    for (const auto& c : session.cameras) {
        if (c.role == "main" && !main) main = &c;
        if (c.role == "environment" && !envCam) envCam = &c;
    }
    if (!main && !session.cameras.empty()) main = &session.cameras.front();
    if (!main) throw FileError(a.session, "the session lists no camera");
    if (!envCam)
        throw FileError((session.dir / "session.json").string(),
                        "the session has no camera with role \"environment\"; there is nothing "
                        "to relate to the main camera");
    if (main->calibration.empty())
        throw FileError(a.session, "camera '" + main->name +
                                       "' has no calibration file; calibrate it (mirage "
                                       "calibrate) and name the YAML in session.json");
    const CameraCalibration calib = loadCalibration(session.path(main->calibration));
    std::string why;
    std::optional<render::SessionEnvironment> env =
        render::SessionEnvironment::open(session, 1.0f, why);
    if (!env) throw Error("mirage env-radiometry: environment camera: " + why);
    const std::filesystem::path envCalibration = session.path(envCam->calibration);

    std::map<int, PoseRow> poses;
    if (!a.poses.empty()) {
        poses = readPosesCsv(a.poses);
        checkPoseFrames(poses, session, a.poses);
    } else {
        bool anyGroundTruth = false;
        for (const FrameRecord& r : session.frames)
            anyGroundTruth = anyGroundTruth || r.groundTruth;
        if (!anyGroundTruth)
            throw FileError(
                (session.dir / "frames.csv").string(),
                "the session has no ground-truth poses; track the main camera first (mirage "
                "track SESSION -o POSES.csv) and pass --poses POSES.csv");
    }
    checkLooksLikeGltf(a.scene);
    const Scene scene = loadScene(a.scene);
    render::EnvironmentRadiometryEstimator estimator(scene, calib.intrinsics, env->setup());
    estimator.setStride(a.stride);

    auto frames = openCameraFrames(session, main->name);
    const int wanted = a.maxFrames >= 0 ? std::min<int>(a.maxFrames, int(session.frames.size()))
                                        : int(session.frames.size());
    cv::Mat bgr, envFrame;
    int used = 0;
    for (int i = 0; i < wanted; ++i) {
        const FrameRecord& rec = session.frames[size_t(i)];
        if (!frames->read(bgr)) break;
        double envT = 0;
        std::string problem;
        if (env->next(rec, envFrame, envT, problem) != render::SessionEnvironment::Status::Frame) {
            if (!problem.empty()) spdlog::warn("env-radiometry: frame {}: {}", rec.index, problem);
            continue;
        }
        std::optional<Pose> pose;
        if (!a.poses.empty()) {
            const auto it = poses.find(rec.index);
            if (it != poses.end() && (it->second.state == "ok" || it->second.state == "tracking"))
                pose = it->second.pose;
        } else {
            pose = rec.groundTruth;
        }
        if (!pose || bgr.empty()) continue;
        const int n = estimator.addFrame(bgr, *pose, envFrame);
        spdlog::debug("env-radiometry: frame {}: {} direction(s) both cameras see", rec.index, n);
        ++used;
    }
    const render::RadiometryEstimate r = estimator.estimate(a.minSamples);
    if (!r.ratio)
        throw Error(
            fmt::format("mirage env-radiometry: no estimate from {} frame(s): {}", used, r.whyNot));
    const glm::dvec3 q = *r.ratio;
    std::printf(
        "radiometry_to_main: %.5g %.5g %.5g (R, G, B; environment-camera linear value -> main "
        "camera's) from %d directions in %d of %d frames; spread (half IQR / median) %.1f %.1f "
        "%.1f %%\n",
        q.r, q.g, q.b, r.samples, r.frames, used, 100 * r.spread.r, 100 * r.spread.g,
        100 * r.spread.b);
    if (const auto stored = loadRadiometryToMain(envCalibration))
        std::printf("the calibration %s holds %.5g %.5g %.5g (estimate / stored: %.3f %.3f %.3f)\n",
                    envCalibration.string().c_str(), stored->r, stored->g, stored->b,
                    q.r / stored->r, q.g / stored->g, q.b / stored->b);
    if (a.write) {
        saveRadiometryToMain(envCalibration, q);
        spdlog::info("env-radiometry: radiometry_to_main written into {}", envCalibration.string());
    }
}

const CommandRegistrar reg("env-radiometry", [](CLI::App& parent) {
    auto a = std::make_shared<EnvRadiometryArgs>();
    auto* cmd = parent.add_subcommand(
        "env-radiometry",
        "Estimate the environment camera's gain and white balance relative to the main camera "
        "(radiometry_to_main) from directions both cameras see");
    cmd->add_option("session", a->session, "Session folder with a main and an environment camera")
        ->required()
        ->check(CLI::ExistingDirectory);
    cmd->add_option("--scene", a->scene,
                    "Scene (.gltf/.glb): its real proxies tell which main-camera pixels see the "
                    "room beyond the modelled scene")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--poses", a->poses,
                    "Main-camera poses CSV from `mirage track` (default: the session's ground "
                    "truth)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--frames", a->maxFrames, "Use at most the first N frames")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("--stride", a->stride, "Try every N-th main-camera pixel in each direction")
        ->capture_default_str()
        ->check(wholeIn(1, 64));
    cmd->add_option("--min-samples", a->minSamples,
                    "Directions needed for an estimate (fewer: no estimate, exit 1)")
        ->capture_default_str()
        ->check(wholeIn(1, 100000000));
    cmd->add_flag("--write", a->write,
                  "Store the estimate as radiometry_to_main in the environment camera's "
                  "calibration file");
    cmd->callback([a] { runEnvRadiometry(*a); });
});

}  // namespace
}  // namespace mirage::app
