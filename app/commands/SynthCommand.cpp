// `mirage synth SCENE -o SESSION`: synthetic footage with exact ground truth, rendered by the
// reference renderer from the scene's REAL parts only (what a real camera would film), along a
// camera path (orbit, hand-held shake, fast pan), with optional sensor effects, plus the fish-eye
// environment camera. Writes the session format of docs/session.md (docs/reference-renderer.md).
#include <chrono>
#include <ctime>
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/commands/TerminalProgress.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/scene/Scene.h"
#include "core/session/Session.h"
#include "render/raytrace/ReferenceRenderer.h"
#include "render/raytrace/SyntheticFootage.h"
#include "tracking/Board.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;

struct SynthArgs {
    std::string scene, output, board;
    int width = 640, height = 480, spp = 16, threads = 0, envSize = 320;
    double fps = 15.0, seconds = 3.0, hfov = 60.0, envFov = 190.0;
    double shutter = 0.0;  // fraction of the frame interval the shutter is open (motion blur)
    int blurSubframes = 4;
    uint64_t seed = 1;
    bool noEnv = false, imageSequence = false, force = false;
    raytrace::SensorOptions sensor;
    raytrace::CameraPathOptions path;
};

std::string isoNow() {
    std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return buf;
}

cv::Mat renderFrame(const raytrace::RayTracingScene& rt, const CameraIntrinsics& k,
                    const Pose& pose, const raytrace::RenderSettings& st) {
    return raytrace::render(rt, raytrace::RenderCamera{k, pose}, st).radiance;
}

void run(SynthArgs a) {
    const fs::path out(a.output);
    if (fs::exists(out / "session.json")) {
        if (!a.force)
            throw FileError(
                out.string(),
                "already holds a session; choose another folder or pass --force to replace it");
        fs::remove_all(out);
    }
    if (!(a.fps > 0) || !(a.seconds > 0))
        throw Error("mirage synth: --fps and --seconds must be positive");
    if (a.spp < 1) throw Error("mirage synth: --spp must be >= 1");
    if (a.shutter < 0 || a.shutter > 1)
        throw Error("mirage synth: --shutter must be in [0, 1] (fraction of a frame)");

    Scene scene = loadScene(a.scene);
    fs::path boardPath =
        a.board.empty() ? fs::path(a.scene).parent_path() / "board.json" : fs::path(a.board);
    if (!fs::exists(boardPath))
        throw FileError(
            boardPath.string(),
            "board file not found; pass --board BOARD.json (the board the scene shows)");
    tracking::Board board = tracking::Board::load(boardPath);

    raytrace::EmbreeDevice device(a.threads > 0 ? fmt::format("threads={}", a.threads) : "");
    // The footage shows the real world only: L_r's scene (real geometry, real lights, environment).
    raytrace::RayTracingScene rt(scene, raytrace::SceneSubset::RealOnly, device);

    const CameraIntrinsics mainK = raytrace::pinholeFromHorizontalFov(a.width, a.height, a.hfov);
    const CameraIntrinsics envK = raytrace::equidistantFisheye(a.envSize, a.envFov);
    a.path.duration = a.seconds;
    a.path.seed = a.seed;
    // The environment camera sits behind the board at table height, looking straight up
    // (OpenCV axes: +Z = world +Y, +X = world +X, image down = world -Z).
    const Pose T_world_env = Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, 0, -1, 0, 1, 0),
                                                           glm::dvec3(0.0, 0.02, -0.40));

    Session meta;
    meta.fps = a.fps;
    const std::string ext = a.imageSequence ? "" : ".mkv";
    meta.cameras.push_back({"main", "main" + ext, "main.yaml", "main"});
    if (!a.noEnv) meta.cameras.push_back({"env", "env" + ext, "env.yaml", "environment"});
    meta.board = "board.json";
    meta.createdBy =
        fmt::format("mirage synth {} ({}x{}, {} spp, seed {})",
                    fs::path(a.scene).filename().string(), a.width, a.height, a.spp, a.seed);
    meta.createdAt = isoNow();
    SessionWriter::Options wopts;
    wopts.fps = a.fps;
    wopts.imageSequence = a.imageSequence;
    wopts.jpegQuality = 92;
    SessionWriter writer(out, meta, wopts);

    CameraCalibration mainCal;
    mainCal.intrinsics = mainK;
    mainCal.avgReprojectionError = 0.0;  // exact by construction
    saveCalibration(out / "main.yaml", mainCal);
    if (!a.noEnv) {
        CameraCalibration envCal;
        envCal.intrinsics = envK;
        envCal.avgReprojectionError = 0.0;
        envCal.T_parent_camera = T_world_env;
        envCal.extrinsicParent = "world";
        saveCalibration(out / "env.yaml", envCal);
    }
    board.save(out / "board.json");

    raytrace::RenderSettings st;
    st.samplesPerPixel = a.spp;
    st.threads = a.threads;
    const int frames = std::max(1, int(std::lround(a.seconds * a.fps)));
    const double duration = frames / a.fps;
    a.path.duration = duration;

    cv::Mat envLinear;
    if (!a.noEnv) {
        // The scene is static, so one environment render serves every frame (sensor noise differs).
        raytrace::RenderSettings es = st;
        es.seed = a.seed + 7777;
        envLinear = renderFrame(rt, envK, T_world_env, es);
    }

    TerminalProgress bar("synth");
    auto start = std::chrono::steady_clock::now();
    for (int f = 0; f < frames; ++f) {
        const double t = f / a.fps;
        const Pose gt = raytrace::cameraPathPose(a.path, t);
        cv::Mat linear;
        if (a.shutter > 0 && a.blurSubframes > 1) {
            // Motion blur: average renders over the open shutter, centred on t (the ground truth).
            linear = cv::Mat::zeros(a.height, a.width, CV_32FC3);
            raytrace::RenderSettings sub = st;
            sub.samplesPerPixel = std::max(1, a.spp / a.blurSubframes);
            for (int s = 0; s < a.blurSubframes; ++s) {
                double ts = t + ((s + 0.5) / a.blurSubframes - 0.5) * a.shutter / a.fps;
                sub.seed = a.seed + uint64_t(f) * 1000 + uint64_t(s);
                linear += renderFrame(rt, mainK, raytrace::cameraPathPose(a.path, ts), sub) /
                          double(a.blurSubframes);
            }
        } else {
            st.seed = a.seed + uint64_t(f) * 1000;
            linear = renderFrame(rt, mainK, gt, st);
        }
        const double exposure = raytrace::exposureAt(a.sensor, t, duration);
        std::vector<cv::Mat> images{
            raytrace::applySensor(linear, a.sensor, exposure, a.seed * 31 + uint64_t(f))};
        std::vector<double> times{t};
        if (!a.noEnv) {
            images.push_back(raytrace::applySensor(envLinear, a.sensor, a.sensor.exposure,
                                                   a.seed * 37 + uint64_t(f)));
            times.push_back(t);
        }
        writer.append(images, times, gt);
        double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        bar.update(f + 1, frames,
                   fmt::format("frame {}/{} ({}), {:.0f} s", f + 1, frames,
                               raytrace::cameraPathSegment(a.path, t), elapsed));
    }
    bar.finish();
    writer.close();
    spdlog::info("wrote session {} ({} frames at {} fps, {}x{}{})", out.string(), frames, a.fps,
                 a.width, a.height,
                 a.noEnv ? "" : fmt::format(", fish-eye {}x{}", a.envSize, a.envSize));
}

const CommandRegistrar reg("synth", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand("synth",
                                      "Render a synthetic session (real parts of a scene, exact "
                                      "ground-truth poses) with the reference renderer");
    auto a = std::make_shared<SynthArgs>();
    cmd->add_option("scene", a->scene, "Scene (.gltf/.glb) with REAL nodes, a board plane, lights")
        ->required();
    cmd->add_option("-o,--output", a->output, "Session folder to create")->required();
    cmd->add_option("--board", a->board,
                    "Board file the scene shows (default: board.json beside the scene)");
    cmd->add_option("--width", a->width, "Main camera width (pixels)")->capture_default_str();
    cmd->add_option("--height", a->height, "Main camera height (pixels)")->capture_default_str();
    cmd->add_option("--hfov", a->hfov, "Main camera horizontal field of view (degrees)")
        ->capture_default_str();
    cmd->add_option("--fps", a->fps, "Frame rate")->capture_default_str();
    cmd->add_option("--seconds", a->seconds, "Length of the footage")->capture_default_str();
    cmd->add_option("--spp", a->spp, "Samples per pixel per frame")->capture_default_str();
    cmd->add_option("--seed", a->seed, "Random seed (render noise, sensor noise, shake)")
        ->capture_default_str();
    cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")
        ->capture_default_str();
    cmd->add_option("--orbit-radius", a->path.radius, "Orbit radius (metres)")
        ->capture_default_str();
    cmd->add_option("--orbit-height", a->path.height, "Camera height above the target (metres)")
        ->capture_default_str();
    cmd->add_option("--pan-deg", a->path.panDeg, "Yaw of the final fast pan (degrees)")
        ->capture_default_str();
    cmd->add_option("--shake-mm", a->path.shakeTranslation, "Hand-held shake amplitude (metres)")
        ->capture_default_str();
    cmd->add_option("--exposure", a->sensor.exposure, "Exposure (multiplies linear radiance)")
        ->capture_default_str();
    cmd->add_flag("--exposure-change", a->sensor.exposureChange,
                  "Auto-exposure step (x0.55) at 60 % of the footage");
    cmd->add_option("--vignette", a->sensor.vignette, "Corner darkening (0 = none)")
        ->capture_default_str();
    cmd->add_option("--noise", a->sensor.noise,
                    "Sensor noise (Poisson-Gaussian, linear units; 0 = none)")
        ->capture_default_str();
    cmd->add_option("--shutter", a->shutter,
                    "Motion blur: shutter open time as a fraction of the frame interval")
        ->capture_default_str();
    cmd->add_option("--blur-subframes", a->blurSubframes,
                    "Sub-frame renders averaged for motion blur")
        ->capture_default_str();
    cmd->add_option("--env-size", a->envSize,
                    "Fish-eye environment camera image size (square, pixels)")
        ->capture_default_str();
    cmd->add_option("--env-fov", a->envFov, "Fish-eye field of view (degrees)")
        ->capture_default_str();
    cmd->add_flag("--no-env", a->noEnv, "Do not render the environment camera");
    cmd->add_flag("--image-sequence", a->imageSequence, "PNG folders instead of MKV videos");
    cmd->add_flag("--force", a->force, "Replace an existing session in the output folder");
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
