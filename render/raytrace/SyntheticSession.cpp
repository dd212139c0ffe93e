#include "render/raytrace/SyntheticSession.h"

#include <chrono>
#include <ctime>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/session/Session.h"
#include "render/evaluation/GroundTruthComposite.h"
#include "render/raytrace/ReferenceRenderer.h"

namespace mirage::raytrace {
namespace {

namespace fs = std::filesystem;

std::string isoNow() {
    std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return buf;
}

struct LinearFrame {
    cv::Mat radiance;  // CV_32FC3 linear
    cv::Mat coverage;  // CV_32F virtual coverage in [0, 1]
};

}  // namespace

void writeSyntheticSession(const Scene& scene, const fs::path& out,
                           const SyntheticSessionOptions& optionsIn,
                           const SynthProgress& progress) {
    SyntheticSessionOptions a = optionsIn;
    if (!(a.fps > 0) || !(a.seconds > 0))
        throw Error("synthetic session: --fps and --seconds must be positive");
    if (a.samplesPerPixel < 1) throw Error("synthetic session: --spp must be >= 1");
    if (a.shutter < 0 || a.shutter > 1)
        throw Error("synthetic session: --shutter must be in [0, 1] (fraction of a frame)");
    if (a.groundTruthComposite && !scene.hasVirtual())
        throw Error(
            "synthetic session: the scene has no virtual object, so there is no ground-truth "
            "composite to write (it would equal the footage); drop --ground-truth-composite or "
            "use a scene with virtual nodes");

    EmbreeDevice device(a.threads > 0 ? fmt::format("threads={}", a.threads) : "");
    // The footage shows the real world only: L_r's scene (real geometry, real lights, environment).
    RayTracingScene realScene(scene, SceneSubset::RealOnly, device);
    std::unique_ptr<RayTracingScene> mixedScene;
    if (a.groundTruthComposite)
        mixedScene = std::make_unique<RayTracingScene>(scene, SceneSubset::All, device);

    const CameraIntrinsics mainK = pinholeFromHorizontalFov(a.width, a.height, a.hfovDeg);
    const CameraIntrinsics envK = equidistantFisheye(a.envSize, a.envFovDeg);
    // The environment camera sits behind the board at table height, looking straight up
    // (OpenCV axes: +Z = world +Y, +X = world +X, image down = world -Z).
    const Pose T_world_env = Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, 0, -1, 0, 1, 0),
                                                           glm::dvec3(0.0, 0.02, -0.40));

    Session meta;
    meta.fps = a.fps;
    const std::string ext = a.imageSequence ? "" : ".mkv";
    meta.cameras.push_back({"main", "main" + ext, "main.yaml", "main"});
    if (a.environmentCamera)
        meta.cameras.push_back({"env", "env" + ext, "env.yaml", "environment"});
    meta.board = a.boardFile.empty() ? "" : "board.json";
    meta.createdBy = fmt::format("mirage synth {} ({}x{}, {} spp, seed {})",
                                 fs::path(a.sceneName).filename().string(), a.width, a.height,
                                 a.samplesPerPixel, a.seed);
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
    if (a.environmentCamera) {
        CameraCalibration envCal;
        envCal.intrinsics = envK;
        envCal.avgReprojectionError = 0.0;
        envCal.T_parent_camera = T_world_env;
        envCal.extrinsicParent = "world";
        saveCalibration(out / "env.yaml", envCal);
    }
    if (!a.boardFile.empty())
        fs::copy_file(a.boardFile, out / "board.json", fs::copy_options::overwrite_existing);

    RenderSettings st;
    st.samplesPerPixel = a.samplesPerPixel;
    st.threads = a.threads;
    const int frames = std::max(1, int(std::lround(a.seconds * a.fps)));
    const double duration = frames / a.fps;
    a.path.duration = duration;
    a.path.seed = a.seed;

    mirage::render::GroundTruthInfo gtInfo;
    gtInfo.scene = a.sceneName;
    gtInfo.influenceThreshold = a.influenceThreshold;
    gtInfo.samplesPerPixel = a.samplesPerPixel;
    gtInfo.seed = a.seed;
    if (a.groundTruthComposite) writeGroundTruthInfo(out, gtInfo);

    cv::Mat envLinear;
    if (a.environmentCamera) {
        // The scene is static, so one environment render serves every frame (sensor noise differs).
        RenderSettings es = st;
        es.seed = a.seed + 7777;
        envLinear = render(realScene, RenderCamera{envK, T_world_env}, es).radiance;
    }

    // One frame of a scene subset at time t, exactly as the footage is made: the same seeds for
    // L_r and L_rv, so where no path touches a virtual object the two renders are identical.
    auto renderFrame = [&](const RayTracingScene& rt, int f, double t) {
        LinearFrame lf;
        if (a.shutter > 0 && a.blurSubframes > 1) {
            // Motion blur: average renders over the open shutter, centred on t (the ground truth).
            lf.radiance = cv::Mat::zeros(a.height, a.width, CV_32FC3);
            lf.coverage = cv::Mat::zeros(a.height, a.width, CV_32F);
            RenderSettings sub = st;
            sub.samplesPerPixel = std::max(1, a.samplesPerPixel / a.blurSubframes);
            for (int s = 0; s < a.blurSubframes; ++s) {
                const double ts = t + ((s + 0.5) / a.blurSubframes - 0.5) * a.shutter / a.fps;
                sub.seed = a.seed + uint64_t(f) * 1000 + uint64_t(s);
                RenderResult r = render(rt, RenderCamera{mainK, cameraPathPose(a.path, ts)}, sub);
                lf.radiance += r.radiance / double(a.blurSubframes);
                lf.coverage += r.virtualCoverage / double(a.blurSubframes);
            }
        } else {
            st.seed = a.seed + uint64_t(f) * 1000;
            RenderResult r = render(rt, RenderCamera{mainK, cameraPathPose(a.path, t)}, st);
            lf.radiance = std::move(r.radiance);
            lf.coverage = std::move(r.virtualCoverage);
        }
        return lf;
    };

    for (int f = 0; f < frames; ++f) {
        const double t = f / a.fps;
        const Pose gt = cameraPathPose(a.path, t);
        const LinearFrame real = renderFrame(realScene, f, t);
        const double exposure = exposureAt(a.sensor, t, duration);
        const uint64_t noiseSeed = a.seed * 31 + uint64_t(f);
        std::vector<cv::Mat> images{applySensor(real.radiance, a.sensor, exposure, noiseSeed)};
        std::vector<double> times{t};
        if (a.environmentCamera) {
            images.push_back(
                applySensor(envLinear, a.sensor, a.sensor.exposure, a.seed * 37 + uint64_t(f)));
            times.push_back(t);
        }
        if (a.groundTruthComposite) {
            // Ground truth: the camera filming the mixed world. The footage is CI = S(L_r) with
            // the sensor S (gain g = exposure x vignette, then noise and 8-bit sRGB encoding), so
            // the reference's differential composite CI + (CI / L_r)(L_rv - L_r) = g L_rv + noise
            // = S(L_rv) wherever the sensor is linear: the same sensor (same noise draws) applied
            // to L_rv is that composite, and where the sensor clips it is what a camera would show.
            const LinearFrame mixed = renderFrame(*mixedScene, f, t);
            mirage::render::GroundTruthFrame g;
            g.compositeSrgb = applySensor(mixed.radiance, a.sensor, exposure, noiseSeed);
            g.influence = mirage::render::influenceMask(
                real.radiance, mixed.radiance, mixed.coverage, exposure, a.influenceThreshold);
            // Frame f is row f of frames.csv (SessionWriter numbers frames from 0).
            writeGroundTruthFrame(out, gtInfo, f, g);
        }
        writer.append(images, times, gt);
        if (progress) progress(f + 1, frames, cameraPathSegment(a.path, t));
    }
    writer.close();
    spdlog::info("wrote session {} ({} frames at {} fps, {}x{}{}{})", out.string(), frames, a.fps,
                 a.width, a.height,
                 a.environmentCamera ? fmt::format(", fish-eye {}x{}", a.envSize, a.envSize) : "",
                 a.groundTruthComposite ? ", ground-truth composite" : "");
}

}  // namespace mirage::raytrace
