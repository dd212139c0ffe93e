#include "render/evaluation/RealtimeBench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <set>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "core/scene/ScenePlacement.h"
#include "render/Renderer.h"
#include "render/evaluation/PoseJitter.h"

namespace mirage::render {
namespace {
double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

CameraIntrinsics scaleIntrinsics(const CameraIntrinsics& k, int width, int height) {
    if (width == k.width && height == k.height) return k;
    CameraIntrinsics s = k;
    const double sx = double(width) / k.width, sy = double(height) / k.height;
    s.width = width;
    s.height = height;
    s.fx = k.fx * sx;
    s.fy = k.fy * sy;
    // OpenCV pixel centres: pixel (0,0) is centred on 0, so the image edge is at -0.5.
    s.cx = (k.cx + 0.5) * sx - 0.5;
    s.cy = (k.cy + 0.5) * sy - 0.5;
    return s;
}

std::vector<BenchFrame> scaleFrames(const std::vector<BenchFrame>& frames, int width, int height) {
    std::vector<BenchFrame> out;
    out.reserve(frames.size());
    for (const auto& f : frames) {
        if (width <= 0 || (f.footage.cols == width && f.footage.rows == height)) {
            out.push_back(f);
            out.back().edges = edgePixels(f.footage, f.truth, f.influence);
            continue;
        }
        BenchFrame s = f;
        auto resizeSrgb = [&](const cv::Mat& bgr) {
            cv::Mat lin = srgbBgr8ToLinearRgb(bgr), small;
            cv::resize(lin, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
            return linearRgbToSrgbBgr8(small);
        };
        s.footage = resizeSrgb(f.footage);
        s.truth = resizeSrgb(f.truth);
        cv::Mat m, small;
        const cv::Mat touched = f.influence > 0;
        touched.convertTo(m, CV_32F, 1.0 / 255.0);
        cv::resize(m, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
        s.influence = small > 0.0f;
        s.edges = edgePixels(s.footage, s.truth, s.influence);
        out.push_back(std::move(s));
    }
    return out;
}

std::vector<BenchFrame> loadBenchFrames(const Session& session, const GroundTruthInfo& truth,
                                        const CameraIntrinsics& mainCamera, int start,
                                        int maxFrames, int* skipped) {
    const SessionCamera* main = session.cameras.empty() ? nullptr : &session.cameras.front();
    for (const auto& c : session.cameras)
        if (c.role == "main") main = &c;
    if (!main) throw FileError(session.dir.string(), "the session lists no camera");
    std::vector<BenchFrame> frames;
    auto source = openCameraFrames(session, main->name);
    // The environment camera's frames, in step with the main camera's (every row has both).
    std::unique_ptr<FrameSource> envSource;
    int envIndex = -1;
    for (const auto& c : session.cameras)
        if (c.role == "environment" && !envSource) {
            envSource = openCameraFrames(session, c.name);
            envIndex = session.cameraIndex(c.name);
        }
    const CameraResponse response =
        main->calibration.empty()
            ? CameraResponse::srgb()
            : loadCameraResponse(session.path(main->calibration)).value_or(CameraResponse::srgb());
    cv::Mat bgr, envBgr;
    int missing = 0;
    for (size_t i = 0; i < session.frames.size(); ++i) {
        if (maxFrames >= 0 && int(frames.size()) >= maxFrames) break;
        if (!source->read(bgr)) break;
        if (envSource && !envSource->read(envBgr)) envSource.reset();
        if (int(i) < start) continue;
        if (bgr.empty()) {  // lost: its bytes in the video are damaged
            ++missing;
            continue;
        }
        const FrameRecord& rec = session.frames[i];
        auto gt = readGroundTruthFrame(session.dir, truth, rec.index);
        if (!rec.groundTruth || !gt) {
            ++missing;
            continue;
        }
        if (bgr.size() != gt->compositeSrgb.size() || bgr.cols != mainCamera.width ||
            bgr.rows != mainCamera.height)
            throw FileError(groundTruthCompositePath(session.dir, truth, rec.index).string(),
                            fmt::format("size {}x{} differs from the footage {}x{} or the "
                                        "calibration {}x{}",
                                        gt->compositeSrgb.cols, gt->compositeSrgb.rows, bgr.cols,
                                        bgr.rows, mainCamera.width, mainCamera.height));
        BenchFrame bf;
        bf.index = rec.index;
        bf.T_world_camera = *rec.groundTruth;
        bf.footage = bgr.clone();
        bf.truth = gt->compositeSrgb;
        bf.influence = gt->influence;
        bf.time = rec.timestamps.empty()
                      ? double(rec.index) / session.fps
                      : rec.timestamps.at(size_t(session.cameraIndex(main->name)));
        bf.shutter = main->shutter;
        bf.response = response;
        frames.push_back(std::move(bf));
        if (envSource && !envBgr.empty()) {
            frames.back().environment = envBgr.clone();
            frames.back().environmentTime = rec.timestamps.at(size_t(envIndex));
        }
    }
    if (skipped) *skipped = missing;
    return frames;
}

BenchResult runBenchConfig(const Scene& scene, const CameraIntrinsics& sessionCamera,
                           const std::vector<BenchFrame>& allFrames, const BenchConfig& config,
                           int repeats, const EnvironmentCameraSetup* environment) {
    if (allFrames.empty()) throw Error("bench: no frames to render");
    if (config.environmentCamera &&
        (!environment || std::any_of(allFrames.begin(), allFrames.end(),
                                     [](const BenchFrame& f) { return f.environment.empty(); })))
        throw Error(
            "bench: knob env_source=camera needs a session with a usable environment camera "
            "(calibration with extrinsics, a frame for every row)");
    const int w = config.width > 0 ? config.width : sessionCamera.width;
    const int h = config.height > 0 ? config.height : sessionCamera.height;
    const std::vector<BenchFrame> frames = scaleFrames(allFrames, w, h);
    const int ss = std::max(1, config.supersample);
    const CameraIntrinsics cam = scaleIntrinsics(sessionCamera, w * ss, h * ss);
    // The footage the renderer composites into: each pixel replicated ss x ss times.
    std::vector<cv::Mat> footage;
    for (const BenchFrame& f : frames) {
        footage.push_back(f.footage);
        if (ss > 1)
            cv::resize(f.footage, footage.back(), cv::Size(w * ss, h * ss), 0, 0,
                       cv::INTER_NEAREST);
    }
    // The judged composite: the renderer's own, or its supersampled linear one averaged down.
    const auto judged = [&](const Renderer& r) {
        if (ss == 1) return r.compositeCameraCoded();
        cv::Mat small;
        cv::resize(r.compositeLinear(), small, cv::Size(w, h), 0, 0, cv::INTER_AREA);
        if (r.cameraResponse().isSrgb()) return linearRgbToSrgbBgr8(small);
        cv::Mat bgr(small.size(), CV_8UC3);
        for (int y = 0; y < small.rows; ++y)
            for (int x = 0; x < small.cols; ++x)
                for (int k = 0; k < 3; ++k)
                    bgr.at<cv::Vec3b>(y, x)[2 - k] =
                        uint8_t(r.cameraResponse().code(k, small.at<cv::Vec3f>(y, x)[k]));
        return bgr;
    };
    RendererOptions options = config.options;
    if (config.motionBlur) {
        const std::optional<double> shutter = allFrames.front().shutter;
        if (!shutter || !(*shutter > 0.0))
            throw Error(
                "bench: knob motion_blur=on needs a session that states a shutter time "
                "(session.json cameras[0].shutter > 0, as `mirage synth --shutter S` writes it)");
        options.motionBlur.shutterSeconds = *shutter;
    }
    if (config.sessionResponse) options.composite.cameraResponse = frames.front().response;
    Renderer renderer(scene, cam, options);
    if (config.environmentCamera) {
        renderer.setEnvironmentCamera(*environment);
        renderer.updateEnvironment(frames.front().environment, frames.front().environmentTime - 1);
    }
    // moving_objects: the scene with its virtual objects 1 cm along +X (world), to move to and
    // back from before each frame.
    Scene away;
    if (config.movingObjects) {
        away = scene;
        ScenePlacement step;
        step.moveU = 0.01;
        if (applyPlacement(away, step, PlacementPlane{}) == 0)
            throw Error("bench: knob moving_objects=on needs a scene with virtual objects");
        if (!renderer.updateTransforms(away))
            throw Error(
                "bench: knob moving_objects=on: a translucent object moves only with a new "
                "renderer (its voxel number map is precomputed in the world)");
        renderer.updateTransforms(scene);
    }
    // Warm-up: shader compilation and first allocations stay out of the timings.
    renderer.render({frames.front().T_world_camera, footage.front(), true});

    BenchResult result;
    result.passOrder = renderer.passNames();
    result.config = config;
    result.config.width = w;
    result.config.height = h;
    std::map<std::string, std::vector<double>> passSamples;
    std::vector<double> gpu, wall;
    for (int rep = 0; rep < std::max(1, repeats); ++rep) {
        CompositeErrorAccumulator acc;
        std::vector<BenchFrameResult> frameResults;
        for (size_t i = 0; i < frames.size(); ++i) {
            const BenchFrame& f = frames[i];
            const auto t0 = std::chrono::steady_clock::now();
            // A new environment frame with every frame (its time differs from the last one's,
            // also across repeats: the last frame's is never the first's).
            if (config.environmentCamera)
                renderer.updateEnvironment(f.environment, f.environmentTime + 1e-3 * double(rep));
            if (config.movingObjects) {
                renderer.updateTransforms(away);
                renderer.updateTransforms(scene);
            }
            const Pose pose =
                config.poseJitterMm > 0.0
                    ? jitteredPose(f.T_world_camera, config.poseJitterMm, 0.1 * config.poseJitterMm,
                                   uint64_t(rep) * 100003u + i)
                    : f.T_world_camera;
            const FrameReport& report =
                renderer.render({pose, footage[i], /*resetHistory=*/i == 0, f.time});
            const cv::Mat composite = judged(renderer);
            const double wallMs =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count();
            BenchFrameResult fr;
            fr.index = f.index;
            fr.gpuMs = report.totalGpuMs;
            fr.wallMs = wallMs;
            for (const auto& p : report.passes)
                if (p.ran) fr.passMs[p.name] = p.gpuMs;
            CompositeErrorAccumulator one;
            one.add(composite, f.truth, f.influence, f.edges);
            fr.error = one.result();
            acc.merge(one);
            if (i == 0) {
                result.firstComposite = composite;
                result.firstTruth = f.truth;
            }
            gpu.push_back(fr.gpuMs);
            wall.push_back(fr.wallMs);
            frameResults.push_back(std::move(fr));
        }
        result.error = acc.result();
        result.frames = std::move(frameResults);
        result.passes.clear();
        for (const std::string& p : result.passOrder)
            for (const auto& fr : result.frames)
                if (fr.passMs.count(p)) {
                    result.passes.push_back(p);
                    break;
                }
        for (const auto& fr : result.frames)
            for (const auto& p : result.passes) {
                const auto it = fr.passMs.find(p);
                passSamples[p].push_back(it == fr.passMs.end() ? 0.0 : it->second);
            }
    }
    for (const auto& [name, samples] : passSamples) result.medianPassMs[name] = median(samples);
    result.medianGpuMs = median(gpu);
    result.medianWallMs = median(wall);
    return result;
}

BenchResult footageBaseline(const std::vector<BenchFrame>& allFrames, int width, int height) {
    if (allFrames.empty()) throw Error("bench: no frames to judge");
    const std::vector<BenchFrame> frames = scaleFrames(allFrames, width, height);
    BenchResult result;
    result.baseline = true;
    result.config.width = frames.front().footage.cols;
    result.config.height = frames.front().footage.rows;
    result.config.knobs = {
        {"resolution", fmt::format("{}x{}", result.config.width, result.config.height)}};
    CompositeErrorAccumulator acc;
    for (const auto& f : frames) {
        BenchFrameResult fr;
        fr.index = f.index;
        CompositeErrorAccumulator one;
        one.add(f.footage, f.truth, f.influence, f.edges);
        fr.error = one.result();
        acc.merge(one);
        if (result.frames.empty()) {
            result.firstComposite = f.footage;
            result.firstTruth = f.truth;
        }
        result.frames.push_back(std::move(fr));
    }
    result.error = acc.result();
    return result;
}

}  // namespace mirage::render
