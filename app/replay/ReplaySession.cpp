#include "app/replay/ReplaySession.h"

#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "app/BoardPlane.h"
#include "app/EffectSwitches.h"
#include "app/InputChecks.h"
#include "app/KnobSettings.h"
#include "app/OutputKind.h"
#include "app/commands/ShardMerge.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CameraResponse.h"
#include "core/image/ImageIO.h"
#include "core/scene/ScenePlacement.h"
#include "core/session/SessionReadOptions.h"
#include "render/LightEstimation.h"

namespace mirage::app {

namespace fs = std::filesystem;

namespace {

// The main camera's exposure time for the motion blur: --shutter, else the session's; without
// either the motion blur is off, and the log says so.
double replayShutterSeconds(const ReplayOptions& a, const Session& s) {
    if (a.shutter) {
        spdlog::info("replay: motion blur {} (--shutter {} s)", *a.shutter > 0 ? "on" : "off",
                     *a.shutter);
        return *a.shutter;
    }
    const std::optional<double> fromSession = s.cameras.front().shutter;
    if (!fromSession) {
        spdlog::info(
            "replay: motion blur off: the session states no shutter time (session.json "
            "cameras[0].shutter); pass --shutter SECONDS to blur what the renderer adds");
        return 0.0;
    }
    spdlog::info("replay: motion blur {} (the session's shutter: {} s)",
                 *fromSession > 0 ? "on" : "off", *fromSession);
    return *fromSession;
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

}  // namespace

ReplaySession::ReplaySession(const ReplayOptions& a) : options_(a) {
    SessionReadReport readReport;
    // Rows need only the main camera: an environment video that ends early does not shorten the
    // replay (the static environment takes over).
    session_ = readSession(a.session, &readReport, SessionReadOptions{true});
    for (const auto& w : readReport.warnings) spdlog::warn("session: {}", w);
    for (const auto& c : session_.cameras)
        if (c.role == "main") main_ = &c;
    if (!main_ && !session_.cameras.empty()) main_ = &session_.cameras.front();
    if (!main_) throw FileError(a.session, "the session lists no camera");
    checkOutputs();
    if (main_->calibration.empty())
        throw FileError(a.session, "camera '" + main_->name +
                                       "' has no calibration file; calibrate it (mirage calibrate) "
                                       "and name the YAML in session.json");
    calibration_ = loadCalibration(session_.path(main_->calibration));
    loadScene();
    poses_ = std::make_unique<ReplayPoses>(session_, calibration_.intrinsics, a.poses,
                                           a.groundTruth, a.boardOnly);
    track_ = std::make_unique<PoseStage>(poses_->tracker());
    createRenderer();
    outputs_->open(session_.fps, a.jpegQuality, renderer_->passNames());
    frames_ = openCameraFrames(session_, main_->name);
    selectFrames();
}

ReplaySession::~ReplaySession() {
    restoreStopSignals();
}

// Outputs are checked before any work: never one of the inputs, never an unnamed existing file
// without --force; written under temporary names and renamed when finished. A shard (--shard
// I/N: the I-th of N contiguous blocks of the frames) writes PNG frames and its CSV rows into
// OUT.shards/I-of-N; `mirage merge OUT` makes OUT of them.
void ReplaySession::checkOutputs() {
    const ReplayOptions& a = options_;
    userOut_ = a.output;
    split_ = !a.shard.empty();
    shard_ = split_ ? parseShardSpec(a.shard) : ShardSpec{};
    userMkv_ = isVideoOutput(userOut_, "mirage replay");
    OutputRule rule{sessionInputs(session_), a.force, "mirage replay"};
    rule.inputs.push_back(a.scene);
    if (!a.poses.empty()) rule.inputs.push_back(a.poses);
    if (!a.staticEnv.empty()) rule.inputs.push_back(a.staticEnv);
    if (split_) {
        checkOutput(userOut_, OutputOrigin::Named, rule, /*outIsFolder=*/!userMkv_);
        const auto dir = shardFolder(userOut_, shard_);
        if (fs::exists(dir / "shard.json") && !a.force)
            throw FileError(dir.string(),
                            "this shard is already complete; pass --force to replay it again");
        staged_.emplace(dir);
        fs::create_directories(staged_->temp());
    }
    out_ = split_ ? staged_->temp() : userOut_;
    mkv_ = split_ ? false : userMkv_;
    fs::path csvPath;
    if (mkv_) {
        csvPath = fs::path(out_).replace_extension(".csv");
    } else {
        if (!split_) checkOutput(out_, OutputOrigin::Named, rule, /*outIsFolder=*/true);
        csvPath = out_ / "frames.csv";
    }
    outputs_ = std::make_unique<ReplayOutputs>(out_, mkv_, csvPath, rule);
}

void ReplaySession::loadScene() {
    const ReplayOptions& a = options_;
    checkLooksLikeGltf(a.scene);
    scene_ = mirage::loadScene(a.scene);
    // The virtual objects where a live session placed them (SCENE.placement.json), on the plane
    // of the session's board.
    placementFile_ = a.placement.empty() ? placementPath(a.scene) : fs::path(a.placement);
    if (const auto placement = loadPlacement(placementFile_);
        placement && !placement->isIdentity()) {
        if (session_.board.empty() || !fs::exists(session_.path(session_.board)))
            throw FileError(placementFile_.string(),
                            "places the virtual objects on the tag board, but the session has "
                            "no board file");
        applyPlacement(scene_, *placement,
                       boardPlane(tracking::Board::load(session_.path(session_.board))));
        spdlog::info("replay: virtual objects placed as {} says", placementFile_.string());
    }
    if (!a.staticEnv.empty()) {
        // The given map replaces the scene's environment image; a scene's equirectangular
        // intensity and rotation are kept (they describe the room, not the file).
        readLinearRgb(a.staticEnv);  // a clear FileError now rather than at the renderer
        if (scene_.environment.kind != Environment::Kind::Equirectangular) {
            scene_.environment.intensity = 1.0f;
            scene_.environment.rotationYDeg = 0.0;
        }
        scene_.environment.kind = Environment::Kind::Equirectangular;
        scene_.environment.image = fs::absolute(a.staticEnv);
        scene_.environment.origin = Origin::Real;
    }
    if (!scene_.hasVirtual())
        spdlog::warn("scene {} has no virtual object: the output will equal the footage", a.scene);
}

void ReplaySession::createRenderer() {
    const ReplayOptions& a = options_;
    gl::ContextOptions copt;
    copt.width = calibration_.intrinsics.width;
    copt.height = calibration_.intrinsics.height;
    copt.title = "mirage replay";
    context_ = std::make_unique<gl::Context>(a.window ? gl::Context::window(copt)
                                                      : gl::Context::headless(copt));
    render::RendererOptions ropt;
    ropt.vpl.count = a.vpls;
    ropt.composite.exposure = a.exposure;  // the prior of the per-frame estimate
    ropt.exposureMatch.enabled = true;
    ropt.grain.noise.enabled = true;
    ropt.grain.vignette.enabled = true;
    switchEffectsOff(a.effectsOff, ropt);
    applyKnobSettings(a.knobSettings, ropt);
    ropt.motionBlur.shutterSeconds = replayShutterSeconds(a, session_);
    if (a.estimateLights) {
        // As many as light estimation reports, within the renderer's light budget.
        const int room = render::kMaxLights - int(scene_.lightInstances().size());
        if (room <= 0)
            throw Error(fmt::format(
                "mirage replay --estimate-lights: scene {} already has {} lights, the real-time "
                "renderer's limit; remove one or use --report-lights",
                a.scene, render::kMaxLights));
        ropt.environment.lights = std::min(render::LightEstimationOptions{}.maxLights, room);
    }
    ropt.composite.cameraResponse = cameraResponseOrSrgb(session_.path(main_->calibration));
    renderer_ = std::make_unique<render::Renderer>(scene_, calibration_.intrinsics, ropt);
    compositor_ = std::make_unique<FrameCompositor>(*renderer_);
    // The environment camera, unless --static-env overrides it.
    environment_ =
        std::make_unique<ReplayEnvironment>(session_, *renderer_, a.exposure, a.staticEnv.empty());
    if (!a.staticEnv.empty())
        for (const SessionCamera& c : session_.cameras)
            if (c.role == "environment")
                spdlog::info("replay: --static-env {} is the environment; camera '{}' is not used",
                             a.staticEnv, c.name);
}

void ReplaySession::selectFrames() {
    const ReplayOptions& a = options_;
    listed_ = int(session_.frames.size());
    if (a.start >= listed_)
        throw Error(fmt::format("mirage replay: --start {} is beyond the session's {} frames",
                                a.start, listed_));
    wanted_ = a.maxFrames >= 0 ? std::min(a.maxFrames, listed_ - a.start) : listed_ - a.start;
    // The frames written: [begin, begin + total) of the session's list; a shard's block of them.
    block_ = selectBlock(listed_, ItemRange{a.start, a.start + wanted_}, shard_);
    if (block_.empty())
        throw Error(
            fmt::format("mirage replay: shard {}/{} holds none of the {} frames; use at "
                        "most as many shards as frames",
                        shard_.index, shard_.count, wanted_));
    begin_ = block_.front();
    total_ = int(block_.size());
    first_ = std::max(0, begin_ - a.warmup);  // warm-up frames are not written
}

void ReplaySession::logLights(int index, const CompositedFrame& cf) {
    if (!(options_.estimateLights || options_.reportLights) || !cf.report ||
        !cf.report->ran("environment"))
        return;
    if (options_.estimateLights && renderer_->environmentLive())
        logEnvironmentLights(index, renderer_->environmentLights().lights,
                             "placed as a shadow-casting light, its region taken out of the "
                             "environment light");
    else
        logEnvironmentLights(index, render::estimateLights(renderer_->readEnvironmentMap()),
                             renderer_->environmentLive()
                                 ? "reported, not placed (--estimate-lights places it)"
                                 : "reported, not placed (lights are placed from an environment "
                                   "camera only)");
}

bool ReplaySession::step(int pos, bool emit) {
    const FrameRecord& rec = session_.frames[size_t(pos)];
    const auto t0 = Clock::now();
    cv::Mat bgr;
    if (!frames_->read(bgr)) {
        spdlog::warn("replay: the video ends after {} frames", pos);
        return false;
    }
    ReplayFrameTimes times;
    times.decodeMs = msSince(t0);
    const double t = rec.timestamps.empty() ? pos / session_.fps : rec.timestamps.front();
    const std::string problem = frames_->lastProblem();
    environment_->update(rec);
    const auto t1 = Clock::now();
    PoseRow pose = track_->decide(bgr, t, problem, poses_->given(rec, bgr));
    const double trackingMs = msSince(t1);
    CompositedFrame cf = compositor_->composite(bgr, std::move(pose), true, t);
    cf.trackingMs = trackingMs;
    if (bgr.empty()) spdlog::warn("replay: {}", cf.pose.reason);
    logLights(rec.index, cf);
    if (cf.report && options_.verbose && processed_ == 0)
        spdlog::info("frame {}:\n{}", rec.index, cf.report->summary());
    if (cf.report && options_.window)
        compositor_->blitToWindow(calibration_.intrinsics.width, calibration_.intrinsics.height);
    ++processed_;
    if (!emit) return true;  // warm-up: history and tracking only
    const auto t3 = Clock::now();
    if (outputs_->writeImage(rec.index, cf.image, t) && split_) written_.push_back({rec.index, t});
    times.encodeMs = msSince(t3);
    if (options_.window) {
        context_->swapBuffers();
        context_->pollEvents();
        if (context_->shouldClose()) windowClosed_ = true;
    }
    times.frameMs = msSince(t0);
    outputs_->writeRow(rec.index, t, cf, times, environment_->state());
    return true;
}

int ReplaySession::run() {
    installStopSignals();
    cv::Mat skipped;
    for (int i = 0; i < first_ && frames_->read(skipped); ++i) {
    }
    const auto tStart = Clock::now();
    for (int pos = first_; pos < begin_ + total_ && !windowClosed_ && !stopRequested(); ++pos) {
        if (!step(pos, pos >= begin_)) break;
        if (pos >= begin_) {
            const int done = outputs_->rowsWritten();
            progress(done, total_, done / std::max(1e-9, msSince(tStart) * 1e-3));
        }
    }
    if (isatty(STDERR_FILENO)) std::fprintf(stderr, "\n");
    // Interrupted or not, the frames done so far become the outputs (a playable video and its
    // CSV); an interruption still exits non-zero so that scripts do not take it for a full run.
    outputs_->finish();
    restoreStopSignals();
    if (renderer_) {
        // What the camera matching used, so that a composite without noise or vignetting says
        // why (docs/camera-matching.md).
        const render::GrainOptions& g = renderer_->options().grain;
        const std::string noise = renderer_->grainEstimates().noiseNote;
        spdlog::info("replay: camera noise: {}; vignetting: {}",
                     !g.noise.enabled ? "off"
                     : noise.empty()  ? "not measured"
                                      : noise,
                     g.vignette.enabled ? renderer_->vignettingNote() : "off");
    }
    summary_.rows = outputs_->rowsWritten();
    summary_.images = outputs_->imagesWritten();
    summary_.interrupted = stopRequested();
    if (split_ && !stopRequested()) {
        finishShard();
        return 0;
    }
    const int lost = summary_.rows - summary_.images;
    if (stopRequested())
        spdlog::warn("replay: interrupted after {} frames; {} is playable", summary_.rows,
                     options_.output);
    // What was written, counted where it was written: a lost frame has a CSV row, no image.
    spdlog::info("replay: {} frames written to {}{} (timings: {})", summary_.images,
                 options_.output,
                 lost > 0 ? fmt::format("; {} of the {} frames replayed were lost and have only "
                                        "their CSV row",
                                        lost, summary_.rows)
                          : std::string(),
                 outputs_->csvPath().string());
    return stopRequested() ? 128 + stopSignal() : 0;
}

void ReplaySession::finishShard() {
    const ReplayOptions& a = options_;
    ReplayShard rs;
    rs.shard = shard_;
    rs.listed = listed_;
    rs.range = ItemRange{a.start, a.start + wanted_};
    rs.frames = block_;
    rs.output = userOut_;
    rs.video = userMkv_;
    rs.fps = session_.fps;
    rs.jpegQuality = a.jpegQuality;
    rs.warmup = begin_ - first_;
    rs.written = written_;
    rs.fingerprint = hex64(fingerprint64(fmt::format(
        "{} {} {} {} {} {:.9g} {} {} {} {} {}", fs::absolute(a.session).string(), a.poses, a.vpls,
        a.groundTruth, a.warmup, a.exposure, hex64(fileFingerprint(a.scene)), userMkv_,
        fs::exists(placementFile_) ? hex64(fileFingerprint(placementFile_)) : std::string(),
        a.staticEnv.empty() ? "" : hex64(fileFingerprint(a.staticEnv)), a.estimateLights)));
    finishReplayShard(*staged_, rs);
}

}  // namespace mirage::app
