#include "render/raytrace/SyntheticSession.h"

#include <chrono>
#include <ctime>
#include <memory>
#include <optional>

#include <opencv2/core.hpp>

#include <opencv2/imgcodecs.hpp>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Log.h"
#include "core/Timestamp.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/CameraResponse.h"
#include "core/camera/Radiometry.h"
#include "core/image/ImageIO.h"
#include "core/session/Session.h"
#include "render/raytrace/GroundTruthComposite.h"
#include "render/raytrace/ReferenceRenderer.h"

namespace mirage::raytrace {
namespace {

namespace fs = std::filesystem;

struct LinearFrame {
    cv::Mat radiance;  // CV_32FC3 linear
    cv::Mat coverage;  // CV_32F virtual coverage in [0, 1]
};

// Everything a synthetic run shares between its frames, and the rendering of one frame. Both the
// whole session and a shard of it are written from this, so a frame comes out the same either
// way: its seeds depend on the frame number only.
class SyntheticRun {
public:
    SyntheticRun(const Scene& scene, const SyntheticSessionOptions& optionsIn) : a_(optionsIn) {
        if (!(a_.fps > 0) || !(a_.seconds > 0))
            throw Error("synthetic session: --fps and --seconds must be positive");
        if (a_.samplesPerPixel < 1) throw Error("synthetic session: --spp must be >= 1");
        if (a_.shutter < 0 || a_.shutter > 1)
            throw Error("synthetic session: --shutter must be in [0, 1] (fraction of a frame)");
        if (a_.groundTruthComposite && !scene.hasVirtual())
            throw Error(
                "synthetic session: the scene has no virtual object, so there is no ground-truth "
                "composite to write (it would equal the footage); drop --ground-truth-composite "
                "or use a scene with virtual nodes");
        device_ = std::make_unique<EmbreeDevice>(
            a_.threads > 0 ? fmt::format("threads={}", a_.threads) : "");
        // The footage shows the real world only: L_r's scene (real geometry, real lights,
        // environment).
        realScene_ = std::make_unique<RayTracingScene>(scene, SceneSubset::RealOnly, *device_);
        if (a_.groundTruthComposite)
            mixedScene_ = std::make_unique<RayTracingScene>(scene, SceneSubset::All, *device_);

        mainK_ = pinholeFromHorizontalFov(a_.width, a_.height, a_.hfovDeg);
        envK_ = equidistantFisheye(a_.envSize, a_.envFovDeg);
        // The environment camera sits behind the board at table height, looking straight up
        // (OpenCV axes: +Z = world +Y, +X = world +X, image down = world -Z).
        T_world_env_ = Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, 0, -1, 0, 1, 0),
                                                     glm::dvec3(0.0, 0.02, -0.40));

        meta_.fps = a_.fps;
        const std::string ext = a_.imageSequence ? "" : ".mkv";
        // The main camera's exposure time: the open fraction of the frame interval.
        meta_.cameras.push_back({"main", "main" + ext, "main.yaml", "main", a_.shutter / a_.fps});
        if (a_.environmentCamera)
            meta_.cameras.push_back({"env", "env" + ext, "env.yaml", "environment"});
        meta_.board = a_.boardFile.empty() ? "" : "board.json";
        meta_.createdBy = fmt::format("mirage synth {} ({}x{}, {} spp, seed {})",
                                      fs::path(a_.sceneName).filename().string(), a_.width,
                                      a_.height, a_.samplesPerPixel, a_.seed);
        writerOptions_.fps = a_.fps;
        writerOptions_.imageSequence = a_.imageSequence;
        writerOptions_.jpegQuality = 92;

        st_.samplesPerPixel = a_.samplesPerPixel;
        st_.threads = a_.threads;
        frames_ = syntheticFrameCount(a_);
        duration_ = frames_ / a_.fps;
        a_.path.duration = duration_;
        a_.path.seed = a_.seed;

        gtInfo_.scene = a_.sceneName;
        gtInfo_.influenceThreshold = a_.influenceThreshold;
        gtInfo_.samplesPerPixel = a_.samplesPerPixel;
        gtInfo_.seed = a_.seed;

        if (!(a_.envExposure > 0) || !std::isfinite(a_.envExposure) ||
            !(a_.envWhiteBalance.r > 0 && a_.envWhiteBalance.g > 0 && a_.envWhiteBalance.b > 0))
            throw Error(
                "synthetic session: --env-exposure and --env-white-balance must be positive");
        if (a_.envRotationDegPerSecond != 0) {
            if (scene.environment.kind != Environment::Kind::Equirectangular)
                throw Error(
                    "synthetic session: --env-rotation needs a scene with an equirectangular "
                    "environment (docs/scene.md)");
            envImage_ = readLinearRgb(scene.environment.image);
            envIntensity_ = scene.environment.intensity;
            envRotation0_ = scene.environment.rotationYDeg;
        }
        if (a_.environmentCamera && a_.envRotationDegPerSecond == 0) {
            // The scene is static, so one environment render serves every frame (sensor noise
            // differs).
            envLinear_ = renderEnvironmentCamera();
        }
    }

    int frames() const { return frames_; }
    const Session& meta() const { return meta_; }
    const SessionWriter::Options& writerOptions() const { return writerOptions_; }
    const render::GroundTruthInfo& groundTruthInfo() const { return gtInfo_; }
    std::string segment(int f) const { return cameraPathSegment(a_.path, f / a_.fps); }

    // Calibration files, the board and ground_truth.json: the same for every frame.
    void writeStaticFiles(const fs::path& dir) const {
        CameraCalibration mainCal;
        mainCal.intrinsics = mainK_;
        mainCal.avgReprojectionError = 0.0;  // exact by construction
        saveCalibration(dir / "main.yaml", mainCal);
        if (a_.sensor.responseGamma > 0.0)
            saveCameraResponse(dir / "main.yaml", CameraResponse::gamma(a_.sensor.responseGamma));
        if (a_.environmentCamera) {
            CameraCalibration envCal;
            envCal.intrinsics = envK_;
            envCal.avgReprojectionError = 0.0;
            envCal.T_parent_camera = T_world_env_;
            envCal.extrinsicParent = "world";
            saveCalibration(dir / "env.yaml", envCal);
            // Exact by construction: the main camera's base exposure over the environment
            // camera's exposure and white balance.
            const glm::dvec3 wb(a_.envWhiteBalance);
            saveRadiometryToMain(dir / "env.yaml",
                                 double(a_.sensor.exposure) / (double(a_.envExposure) * wb));
        }
        if (!a_.boardFile.empty())
            fs::copy_file(a_.boardFile, dir / "board.json", fs::copy_options::overwrite_existing);
        if (a_.groundTruthComposite) writeGroundTruthInfo(dir, gtInfo_);
    }

    struct Frame {
        std::vector<cv::Mat> images;  // one per camera, 8-bit BGR
        std::vector<double> times;
        Pose groundTruth;
        std::optional<render::GroundTruthFrame> composite;
    };

    Frame renderFrame(int f) {
        const double t = f / a_.fps;
        Frame out;
        out.groundTruth = cameraPathPose(a_.path, t);
        if (a_.envRotationDegPerSecond != 0) setEnvironmentRotation(t);
        const LinearFrame real = renderSubset(*realScene_, f, t);
        const double exposure = exposureAt(a_.sensor, t, duration_);
        const glm::dvec3 whiteBalance = whiteBalanceAt(a_.sensor, t, duration_);
        const uint64_t noiseSeed = a_.seed * 31 + uint64_t(f);
        out.images.push_back(
            applySensor(real.radiance, a_.sensor, exposure, noiseSeed, whiteBalance));
        out.times.push_back(t);
        if (a_.environmentCamera) {
            const cv::Mat envLinear =
                a_.envRotationDegPerSecond != 0 ? renderEnvironmentCamera() : envLinear_;
            // The environment camera's own white balance, then its own exposure.
            cv::Mat balanced;
            cv::multiply(
                envLinear,
                cv::Scalar(a_.envWhiteBalance.r, a_.envWhiteBalance.g, a_.envWhiteBalance.b),
                balanced);
            SensorOptions envSensor = a_.sensor;
            envSensor.responseGamma = 0.0;  // the environment camera's response stays sRGB
            out.images.push_back(
                applySensor(balanced, envSensor, a_.envExposure, a_.seed * 37 + uint64_t(f)));
            out.times.push_back(t);
        }
        if (a_.groundTruthComposite) {
            // Ground truth: the camera filming the mixed world. The footage is CI = S(L_r) with
            // the sensor S (gain g = exposure x vignette, then noise and 8-bit sRGB encoding), so
            // the reference's differential composite CI + (CI / L_r)(L_rv - L_r) = g L_rv + noise
            // = S(L_rv) wherever the sensor is linear: the same sensor (same noise draws) applied
            // to L_rv is that composite, and where the sensor clips it is what a camera would
            // show.
            const LinearFrame mixed = renderSubset(*mixedScene_, f, t);
            render::GroundTruthFrame g;
            g.compositeSrgb =
                applySensor(mixed.radiance, a_.sensor, exposure, noiseSeed, whiteBalance);
            g.influence = render::influenceMask(real.radiance, mixed.radiance, mixed.coverage,
                                                exposure, a_.influenceThreshold);
            out.composite = std::move(g);
        }
        return out;
    }

private:
    // The environment camera's linear image of the real world (its scene's current environment).
    cv::Mat renderEnvironmentCamera() const {
        RenderSettings es = st_;
        es.seed = a_.seed + 7777;
        return render(*realScene_, RenderCamera{envK_, T_world_env_}, es).radiance;
    }

    // The environment of time t (seconds): rotation_y_deg + rate x t about +Y, in every scene.
    void setEnvironmentRotation(double t) {
        const double deg = envRotation0_ + a_.envRotationDegPerSecond * t;
        realScene_->setEnvironment(
            std::make_unique<EnvironmentLight>(envImage_, envIntensity_, deg));
        if (mixedScene_)
            mixedScene_->setEnvironment(
                std::make_unique<EnvironmentLight>(envImage_, envIntensity_, deg));
    }

    // One frame of a scene subset at time t, exactly as the footage is made: the same seeds for
    // L_r and L_rv, so where no path touches a virtual object the two renders are identical.
    LinearFrame renderSubset(const RayTracingScene& rt, int f, double t) {
        LinearFrame lf;
        RenderSettings st = st_;
        if (a_.shutter > 0 && a_.blurSubframes > 1) {
            // Motion blur: average renders over the open shutter, centred on t (the ground truth).
            lf.radiance = cv::Mat::zeros(a_.height, a_.width, CV_32FC3);
            lf.coverage = cv::Mat::zeros(a_.height, a_.width, CV_32F);
            st.samplesPerPixel = std::max(1, a_.samplesPerPixel / a_.blurSubframes);
            for (int s = 0; s < a_.blurSubframes; ++s) {
                const double ts = t + ((s + 0.5) / a_.blurSubframes - 0.5) * a_.shutter / a_.fps;
                st.seed = a_.seed + uint64_t(f) * 1000 + uint64_t(s);
                RenderResult r = render(rt, RenderCamera{mainK_, cameraPathPose(a_.path, ts)}, st);
                lf.radiance += r.radiance / double(a_.blurSubframes);
                lf.coverage += r.virtualCoverage / double(a_.blurSubframes);
            }
        } else {
            st.seed = a_.seed + uint64_t(f) * 1000;
            RenderResult r = render(rt, RenderCamera{mainK_, cameraPathPose(a_.path, t)}, st);
            lf.radiance = std::move(r.radiance);
            lf.coverage = std::move(r.virtualCoverage);
        }
        return lf;
    }

    SyntheticSessionOptions a_;
    std::unique_ptr<EmbreeDevice> device_;
    std::unique_ptr<RayTracingScene> realScene_, mixedScene_;
    CameraIntrinsics mainK_, envK_;
    Pose T_world_env_;
    Session meta_;
    SessionWriter::Options writerOptions_;
    RenderSettings st_;
    int frames_ = 0;
    double duration_ = 0;
    render::GroundTruthInfo gtInfo_;
    cv::Mat envLinear_;
    cv::Mat envImage_;  // the scene's environment map, for a rotating environment
    float envIntensity_ = 1.0f;
    double envRotation0_ = 0.0;
};

std::string framePng(const std::string& camera, int frame) {
    return fmt::format("{}/{:06d}.png", camera, frame);
}

nlohmann::json poseJson(const Pose& p) {
    return {p.translation.x, p.translation.y, p.translation.z, p.rotation.w,
            p.rotation.x,    p.rotation.y,    p.rotation.z};
}

Pose poseFromJson(const nlohmann::json& j) {
    Pose p;
    p.translation = {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
    p.rotation = glm::dquat(j.at(3).get<double>(), j.at(4).get<double>(), j.at(5).get<double>(),
                            j.at(6).get<double>());
    return p;
}

}  // namespace

int syntheticFrameCount(const SyntheticSessionOptions& a) {
    return std::max(1, int(std::lround(a.seconds * a.fps)));
}

std::string syntheticFingerprint(const SyntheticSessionOptions& a, uint64_t sceneBytes,
                                 uint64_t boardBytes) {
    // Every option that changes a frame; the scene and board by their bytes. Threads and the
    // output format (MKV or PNG folder) change no pixel but the latter changes the merge, so it
    // is included; threads are not.
    const std::string all = fmt::format(
        "{}x{} hfov {:.17g} fps {:.17g} s {:.17g} spp {} seed {} shutter {:.17g} sub {} env {} "
        "{} {:.17g} seq {} gt {} thr {:.17g} sensor {:.17g} {} {:.17g} {:.17g} path {:.17g} "
        "{:.17g} {:.17g} {:.17g} envcam {:.9g} {:.9g} {:.9g} {:.9g} {:.17g} scene {} board {}{}{}",
        a.width, a.height, a.hfovDeg, a.fps, a.seconds, a.samplesPerPixel, a.seed, a.shutter,
        a.blurSubframes, a.environmentCamera, a.envSize, a.envFovDeg, a.imageSequence,
        a.groundTruthComposite, a.influenceThreshold, a.sensor.exposure, a.sensor.exposureChange,
        a.sensor.vignette, a.sensor.noise, a.path.radius, a.path.height, a.path.panDeg,
        a.path.shakeTranslation, a.envExposure, a.envWhiteBalance.r, a.envWhiteBalance.g,
        a.envWhiteBalance.b, a.envRotationDegPerSecond, hex64(sceneBytes), hex64(boardBytes),
        // Only when used: sessions made before these options keep their fingerprint.
        a.sensor.exposureStep == 1.0 && a.sensor.whiteBalanceDrift == glm::dvec3(1.0)
            ? std::string()
            : fmt::format(" step {:.17g} wb {:.17g} {:.17g} {:.17g}", a.sensor.exposureStep,
                          a.sensor.whiteBalanceDrift.r, a.sensor.whiteBalanceDrift.g,
                          a.sensor.whiteBalanceDrift.b),
        a.sensor.responseGamma == 0.0 ? std::string()
                                      : fmt::format(" response {:.17g}", a.sensor.responseGamma));
    return hex64(fingerprint64(all));
}

void writeSyntheticSession(const Scene& scene, const fs::path& out,
                           const SyntheticSessionOptions& a, const SynthProgress& progress) {
    SyntheticRun run(scene, a);
    Session meta = run.meta();
    meta.createdAt = utcTimestamp();
    SessionWriter writer(out, meta, run.writerOptions());
    run.writeStaticFiles(out);
    const int frames = run.frames();
    for (int f = 0; f < frames; ++f) {
        SyntheticRun::Frame frame = run.renderFrame(f);
        // Frame f is row f of frames.csv (SessionWriter numbers frames from 0).
        if (frame.composite) writeGroundTruthFrame(out, run.groundTruthInfo(), f, *frame.composite);
        writer.append(frame.images, frame.times, frame.groundTruth);
        if (progress) progress(f + 1, frames, run.segment(f));
    }
    writer.close();
    spdlog::info("wrote session {} ({} frames at {} fps, {}x{}{}{})", out.string(), frames, a.fps,
                 a.width, a.height,
                 a.environmentCamera ? fmt::format(", fish-eye {}x{}", a.envSize, a.envSize) : "",
                 a.groundTruthComposite ? ", ground-truth composite" : "");
}

nlohmann::json writeSyntheticShard(const Scene& scene, const fs::path& dir,
                                   const SyntheticSessionOptions& a, const std::vector<int>& frames,
                                   const SynthProgress& progress) {
    SyntheticRun run(scene, a);
    fs::create_directories(dir);
    for (const SessionCamera& c : run.meta().cameras) fs::create_directories(dir / c.name);
    run.writeStaticFiles(dir);
    nlohmann::json perFrame = nlohmann::json::object();
    int done = 0;
    for (int f : frames) {
        if (f < 0 || f >= run.frames())
            throw Error(
                fmt::format("synthetic shard: frame {} is outside 0..{}", f, run.frames() - 1));
        SyntheticRun::Frame frame = run.renderFrame(f);
        // PNG keeps the 8-bit images exactly, so the merge encodes the very bytes the whole run
        // would have encoded.
        for (size_t c = 0; c < frame.images.size(); ++c)
            writeBgr8(dir / framePng(run.meta().cameras[c].name, f), frame.images[c]);
        if (frame.composite) writeGroundTruthFrame(dir, run.groundTruthInfo(), f, *frame.composite);
        // JSON numbers are written with the shortest exact representation: times and poses
        // come back bit for bit.
        perFrame[std::to_string(f)] = {{"times", frame.times},
                                       {"ground_truth", poseJson(frame.groundTruth)}};
        if (progress) progress(++done, int(frames.size()), run.segment(f));
    }
    nlohmann::json cameras = nlohmann::json::array();
    for (const SessionCamera& c : run.meta().cameras)
        cameras.push_back({{"name", c.name},
                           {"video", c.video},
                           {"calibration", c.calibration},
                           {"role", c.role},
                           {"shutter", c.shutter ? nlohmann::json(*c.shutter) : nlohmann::json()}});
    return {{"fps", a.fps},
            {"frames_total", run.frames()},
            {"cameras", cameras},
            {"board", run.meta().board},
            {"created_by", run.meta().createdBy},
            {"image_sequence", run.writerOptions().imageSequence},
            {"jpeg_quality", run.writerOptions().jpegQuality},
            {"ground_truth_composite", a.groundTruthComposite},
            {"frames", perFrame}};
}

void mergeSyntheticShards(const ShardSet& set, const fs::path& out, const SynthProgress& progress) {
    const ShardManifest& first = set.shards.front();
    const nlohmann::json& p = first.payload;
    const fs::path firstDir = set.folders.front();
    try {
        Session meta;
        meta.fps = p.at("fps").get<double>();
        for (const auto& c : p.at("cameras"))
            meta.cameras.push_back(
                {c.at("name").get<std::string>(), c.at("video").get<std::string>(),
                 c.at("calibration").get<std::string>(), c.at("role").get<std::string>(),
                 c.contains("shutter") && c.at("shutter").is_number()
                     ? std::optional<double>(c.at("shutter").get<double>())
                     : std::nullopt});
        meta.board = p.at("board").get<std::string>();
        meta.createdBy = p.at("created_by").get<std::string>();
        // The run's creation time: its earliest shard's.
        meta.createdAt = first.createdAt;
        for (const ShardManifest& m : set.shards)
            meta.createdAt = std::min(meta.createdAt, m.createdAt);
        SessionWriter::Options wopts;
        wopts.fps = meta.fps;
        wopts.imageSequence = p.at("image_sequence").get<bool>();
        wopts.jpegQuality = p.at("jpeg_quality").get<int>();
        const bool groundTruth = p.at("ground_truth_composite").get<bool>();

        SessionWriter writer(out, meta, wopts);
        // Static files are the same in every shard (same fingerprint): take the first shard's.
        for (const SessionCamera& c : meta.cameras)
            if (!c.calibration.empty())
                fs::copy_file(firstDir / c.calibration, out / c.calibration,
                              fs::copy_options::overwrite_existing);
        if (!meta.board.empty())
            fs::copy_file(firstDir / meta.board, out / meta.board,
                          fs::copy_options::overwrite_existing);
        std::optional<render::GroundTruthInfo> gtInfo;
        if (groundTruth) {
            gtInfo = render::readGroundTruthInfo(firstDir);
            if (!gtInfo)
                throw FileError((firstDir / "ground_truth.json").string(),
                                "missing: the shard is incomplete (rerun it)");
            writeGroundTruthInfo(out, *gtInfo);
        }
        const int total = first.range.end - first.range.begin;
        for (int f = first.range.begin; f < first.range.end; ++f) {
            const size_t s = size_t(set.owner[size_t(f)]);
            const fs::path dir = set.folders[s];
            const nlohmann::json& rec = set.shards[s].payload.at("frames").at(std::to_string(f));
            std::vector<cv::Mat> images;
            for (const SessionCamera& c : meta.cameras) {
                const fs::path png = dir / framePng(c.name, f);
                cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
                if (img.empty())
                    throw FileError(png.string(), "missing or unreadable: rerun this shard");
                images.push_back(std::move(img));
            }
            if (gtInfo) {
                std::optional<render::GroundTruthFrame> g =
                    render::readGroundTruthFrame(dir, *gtInfo, f);
                if (!g)
                    throw FileError(dir.string(),
                                    fmt::format("ground truth of frame {} is missing: "
                                                "rerun this shard",
                                                f));
                // Frames of a --frames range are renumbered from 0, as in the session.
                writeGroundTruthFrame(out, *gtInfo, f - first.range.begin, *g);
            }
            writer.append(images, rec.at("times").get<std::vector<double>>(),
                          poseFromJson(rec.at("ground_truth")));
            if (progress) progress(f - first.range.begin + 1, total, "merge");
        }
        writer.close();
    } catch (const nlohmann::json::exception& e) {
        throw FileError((firstDir / "shard.json").string(),
                        std::string("payload is malformed: ") + e.what());
    }
}

}  // namespace mirage::raytrace
