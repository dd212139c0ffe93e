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
#include "render/Renderer.h"

namespace mirage::render {
namespace {

int parseInt(const std::string& knob, const std::string& v, int lo, int hi) {
    try {
        size_t used = 0;
        const int x = std::stoi(v, &used);
        if (used == v.size() && x >= lo && x <= hi) return x;
    } catch (const std::exception&) {
    }
    throw Error(
        fmt::format("bench knob '{}': '{}' is not an integer in [{}, {}]", knob, v, lo, hi));
}

bool parseOnOff(const std::string& knob, const std::string& v) {
    if (v != "on" && v != "off")
        throw Error(fmt::format("bench knob '{}': '{}' is not on or off", knob, v));
    return v == "on";
}

// "WxH" -> (W, H); "session" -> (0, 0).
std::pair<int, int> parseResolution(const std::string& v) {
    if (v == "session") return {0, 0};
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(v.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 16 ||
        h < 16 || w > 8192 || h > 8192)
        throw Error(fmt::format(
            "bench knob 'resolution': '{}' is not WIDTHxHEIGHT (16..8192, e.g. 640x480) or "
            "'session'",
            v));
    return {w, h};
}

bool sameAspect(int w, int h, int W, int H) {
    return std::abs(double(w) * H - double(h) * W) <= 0.01 * double(W) * H;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string num(double v, int decimals) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return fmt::format("{:.{}f}", v, decimals);
}

std::vector<std::string> knobNames(const std::vector<BenchResult>& results) {
    std::vector<std::string> names;
    for (const auto& k : benchKnobs()) names.push_back(k.name);
    for (const auto& r : results)
        for (const auto& [n, v] : r.config.knobs)
            if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    return names;
}

// The passes that ran in any result, in the frame graph's order (Renderer::passNames).
std::vector<std::string> passNames(const std::vector<BenchResult>& results) {
    std::vector<std::string> order, names;
    for (const auto& r : results)
        if (!r.passOrder.empty()) order = r.passOrder;
    for (const std::string& p : order)
        for (const auto& r : results)
            if (std::find(r.passes.begin(), r.passes.end(), p) != r.passes.end()) {
                names.push_back(p);
                break;
            }
    return names;
}

std::string knobValue(const BenchConfig& c, const std::string& name) {
    for (const auto& [n, v] : c.knobs)
        if (n == name) return v;
    return "";
}

std::ofstream openOut(const std::string& path) {
    std::ofstream out(path);
    if (!out) throw FileError(path, "cannot create the file (does the folder exist?)");
    return out;
}

}  // namespace

std::string BenchConfig::label() const {
    std::string s;
    for (const auto& [n, v] : knobs) s += (s.empty() ? "" : " ") + n + "=" + v;
    return s;
}

const std::vector<BenchKnob>& benchKnobs() {
    static const std::vector<BenchKnob> knobs = {
        {"resolution", "render (and judging) resolution WIDTHxHEIGHT, same aspect as the session",
         [](const CameraIntrinsics& k, bool quick) {
             // The session's size, then the standard 4:3 sizes below it with its aspect ratio.
             std::vector<std::string> v{fmt::format("{}x{}", k.width, k.height)};
             const std::pair<int, int> standard[] = {{1024, 768}, {640, 480}, {320, 240}};
             for (auto [w, h] : standard)
                 if (w * h < k.width * k.height && sameAspect(w, h, k.width, k.height))
                     v.push_back(fmt::format("{}x{}", w, h));
             if (quick) {
                 // The largest size up to 640x480 (the goal's resolution when the session has it).
                 for (const auto& s : v)
                     if (parseResolution(s).first <= 640) return std::vector<std::string>{s};
                 return std::vector<std::string>{v.back()};
             }
             return v;
         },
         [](BenchConfig& c, const std::string& v) {
             std::tie(c.width, c.height) = parseResolution(v);
         }},
        {"vpls", "virtual point lights per frame (RendererOptions::vplCount)",
         [](const CameraIntrinsics&, bool quick) {
             return quick ? std::vector<std::string>{"64", "256"}
                          : std::vector<std::string>{"64", "256", "1024"};
         },
         [](BenchConfig& c, const std::string& v) {
             c.options.vplCount = parseInt("vpls", v, 0, 16384);
         }},
        {"indirect_scale", "VPL gather at 1/N resolution per axis (1 or 2)",
         [](const CameraIntrinsics&, bool quick) {
             return quick ? std::vector<std::string>{"2"} : std::vector<std::string>{"2", "1"};
         },
         [](BenchConfig& c, const std::string& v) {
             c.options.indirectScale = parseInt("indirect_scale", v, 1, 2);
         }},
        {"static_reuse",
         "on: reuse the camera-independent passes (shadow, vpl, ism) while the plan is "
         "unchanged; off: re-run them every frame",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
         [](BenchConfig& c, const std::string& v) {
             c.options.reuseStaticPasses = parseOnOff("static_reuse", v);
         }},
        {"sync_passes",
         "on: glFinish around every pass so each pass's GPU ms is its own (llvmpipe defers work); "
         "off: as mirage replay runs, passes overlap and only the wall ms is meaningful",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
         [](BenchConfig& c, const std::string& v) {
             c.options.syncPasses = parseOnOff("sync_passes", v);
         }},
        // Specular objects (issue 6). One default value each, so the default grid does not grow;
        // sweep them with --knob (docs/bench.md). They change nothing in a scene without mirror
        // or glass (the impostor and specular passes do not run).
        {"specular_trace",
         "what reflected/refracted rays are traced against: impostors (Popescu et al. 2006) or "
         "cubemap (the plain G-buffer cube-map baseline)",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"impostors"}; },
         [](BenchConfig& c, const std::string& v) {
             if (v != "impostors" && v != "cubemap")
                 throw Error(fmt::format(
                     "bench: knob specular_trace: '{}' is not impostors or cubemap", v));
             c.options.impostorCubeMapBaseline = v == "cubemap";
         }},
        {"impostor_resolution", "texels per side of each impostor and cube-map face",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"256"}; },
         [](BenchConfig& c, const std::string& v) {
             c.options.impostorResolution = parseInt("impostor_resolution", v, 16, 2048);
         }},
        {"impostor_steps", "refinement steps of the impostor height-field search",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"4"}; },
         [](BenchConfig& c, const std::string& v) {
             c.options.impostorRefineSteps = parseInt("impostor_steps", v, 0, 32);
         }},
    };
    return knobs;
}

std::vector<BenchConfig> benchGrid(
    const CameraIntrinsics& session, bool quick,
    const std::map<std::string, std::vector<std::string>>& overrides) {
    for (const auto& [name, values] : overrides) {
        const bool known = std::any_of(benchKnobs().begin(), benchKnobs().end(),
                                       [&](const BenchKnob& k) { return k.name == name; });
        if (!known) {
            std::string list;
            for (const auto& k : benchKnobs()) list += (list.empty() ? "" : ", ") + k.name;
            throw Error(fmt::format("bench: unknown knob '{}' (knobs: {})", name, list));
        }
        if (values.empty()) throw Error(fmt::format("bench: knob '{}' has no values", name));
    }
    BenchConfig base;
    base.options.syncPasses = true;  // per-pass attribution of GPU time (see RendererOptions)
    std::vector<BenchConfig> grid{base};
    for (const auto& knob : benchKnobs()) {
        const auto it = overrides.find(knob.name);
        const std::vector<std::string> values =
            it != overrides.end() ? it->second : knob.defaults(session, quick);
        std::vector<BenchConfig> next;
        for (const auto& c : grid)
            for (const auto& v : values) {
                BenchConfig n = c;
                knob.apply(n, v);
                n.knobs.emplace_back(knob.name, v);
                next.push_back(std::move(n));
            }
        grid = std::move(next);
    }
    for (const auto& c : grid) {
        const int w = c.width > 0 ? c.width : session.width;
        const int h = c.height > 0 ? c.height : session.height;
        if (w > session.width || h > session.height ||
            !sameAspect(w, h, session.width, session.height))
            throw Error(fmt::format(
                "bench: resolution {}x{} must be at most the session's {}x{} with the same aspect "
                "ratio (the ground truth is only downsampled, never upsampled)",
                w, h, session.width, session.height));
    }
    return grid;
}

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
    cv::Mat bgr;
    int missing = 0;
    for (size_t i = 0; i < session.frames.size(); ++i) {
        if (maxFrames >= 0 && int(frames.size()) >= maxFrames) break;
        if (!source->read(bgr)) break;
        if (int(i) < start) continue;
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
        frames.push_back(
            {rec.index, *rec.groundTruth, bgr.clone(), gt->compositeSrgb, gt->influence});
    }
    if (skipped) *skipped = missing;
    return frames;
}

BenchResult runBenchConfig(const Scene& scene, const CameraIntrinsics& sessionCamera,
                           const std::vector<BenchFrame>& allFrames, const BenchConfig& config,
                           int repeats) {
    if (allFrames.empty()) throw Error("bench: no frames to render");
    const int w = config.width > 0 ? config.width : sessionCamera.width;
    const int h = config.height > 0 ? config.height : sessionCamera.height;
    const std::vector<BenchFrame> frames = scaleFrames(allFrames, w, h);
    const CameraIntrinsics cam = scaleIntrinsics(sessionCamera, w, h);
    Renderer renderer(scene, cam, config.options);
    // Warm-up: shader compilation and first allocations stay out of the timings.
    renderer.render({frames.front().T_world_camera, frames.front().footage, true});

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
            const FrameReport& report =
                renderer.render({f.T_world_camera, f.footage, /*resetHistory=*/i == 0});
            const cv::Mat composite = renderer.compositeSrgb();
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
            one.add(composite, f.truth, f.influence);
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
        one.add(f.footage, f.truth, f.influence);
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

void writeBenchCsv(const std::string& path, const std::vector<BenchResult>& results) {
    std::ofstream out = openOut(path);
    const auto knobs = knobNames(results);
    const auto passes = passNames(results);
    out << "# mirage bench: medians over frames of GPU ms per pass (GL timer queries, syncPasses);"
           " errors pooled over frames, 8-bit sRGB vs the ground-truth composite\n";
    out << "config,baseline";
    for (const auto& k : knobs) out << "," << k;
    out << ",width,height,frames";
    for (const auto& p : passes) out << "," << p << "_ms";
    out << ",gpu_ms,wall_ms,psnr_frame_db,ssim_frame,psnr_influenced_db,ssim_influenced,"
           "influenced_px\n";
    for (const auto& r : results) {
        out << '"' << (r.baseline ? "footage (no virtual objects)" : r.config.label()) << '"' << ","
            << (r.baseline ? 1 : 0);
        for (const auto& k : knobs) out << "," << knobValue(r.config, k);
        out << "," << r.config.width << "," << r.config.height << "," << r.frames.size();
        for (const auto& p : passes) {
            const auto it = r.medianPassMs.find(p);
            out << "," << (it == r.medianPassMs.end() ? "" : num(it->second, 3));
        }
        out << "," << (r.baseline ? "" : num(r.medianGpuMs, 3)) << ","
            << (r.baseline ? "" : num(r.medianWallMs, 3)) << "," << num(r.error.psnrFrame, 3) << ","
            << num(r.error.ssimFrame, 5) << "," << num(r.error.psnrInfluenced, 3) << ","
            << num(r.error.ssimInfluenced, 5) << "," << num(r.error.influencedPixels, 0) << "\n";
    }
    if (!out) throw FileError(path, "write failed");
}

void writeBenchFramesCsv(const std::string& path, const std::vector<BenchResult>& results) {
    std::ofstream out = openOut(path);
    const auto passes = passNames(results);
    out << "config,frame";
    for (const auto& p : passes) out << "," << p << "_ms";
    out << ",gpu_ms,wall_ms,psnr_frame_db,ssim_frame,psnr_influenced_db,ssim_influenced,"
           "influenced_px\n";
    for (const auto& r : results)
        for (const auto& f : r.frames) {
            out << '"' << (r.baseline ? "footage (no virtual objects)" : r.config.label()) << '"'
                << "," << f.index;
            for (const auto& p : passes) {
                const auto it = f.passMs.find(p);
                out << "," << (it == f.passMs.end() ? "" : num(it->second, 3));
            }
            out << "," << num(f.gpuMs, 3) << "," << num(f.wallMs, 3) << ","
                << num(f.error.psnrFrame, 3) << "," << num(f.error.ssimFrame, 5) << ","
                << num(f.error.psnrInfluenced, 3) << "," << num(f.error.ssimInfluenced, 5) << ","
                << num(f.error.influencedPixels, 0) << "\n";
        }
    if (!out) throw FileError(path, "write failed");
}

void writeBenchMarkdown(const std::string& path, const std::vector<BenchResult>& results,
                        const std::string& preamble) {
    std::ofstream out = openOut(path);
    const auto knobs = knobNames(results);
    const auto passes = passNames(results);
    out << preamble << "\n";
    out << "|";
    for (const auto& k : knobs) out << " " << k << " |";
    for (const auto& p : passes) out << " " << p << " |";
    out << " **GPU ms** | frames/s | wall ms | PSNR dB | SSIM | PSNR infl. dB | SSIM infl. |\n|";
    for (size_t i = 0; i < knobs.size(); ++i) out << "---|";
    for (size_t i = 0; i < passes.size() + 7; ++i) out << "---:|";
    out << "\n";
    for (const auto& r : results) {
        out << "|";
        for (size_t i = 0; i < knobs.size(); ++i) {
            std::string v = knobValue(r.config, knobs[i]);
            if (r.baseline && i + 1 == knobs.size()) v = "footage only";
            out << " " << (v.empty() ? "–" : v) << " |";
        }
        for (const auto& p : passes) {
            const auto it = r.medianPassMs.find(p);
            out << " " << (it == r.medianPassMs.end() ? "–" : num(it->second, 1)) << " |";
        }
        if (r.baseline)
            out << " – | – | – |";
        else
            out << " **" << num(r.medianGpuMs, 1) << "** | "
                << num(r.medianGpuMs > 0 ? 1000.0 / r.medianGpuMs : 0.0, 1) << " | "
                << num(r.medianWallMs, 1) << " |";
        out << " " << num(r.error.psnrFrame, 2) << " | " << num(r.error.ssimFrame, 4) << " | "
            << num(r.error.psnrInfluenced, 2) << " | " << num(r.error.ssimInfluenced, 4) << " |\n";
    }
    if (!out) throw FileError(path, "write failed");
}

}  // namespace mirage::render
