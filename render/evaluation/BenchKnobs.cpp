// `mirage bench` knobs: each knob's values and how it sets a configuration, and the grid of
// configurations (render/evaluation/RealtimeBench.h).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/PassKnob.h"
#include "render/evaluation/RealtimeBench.h"

namespace mirage::render {
namespace {

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

}  // namespace

std::string BenchConfig::label() const {
    std::string s;
    for (const auto& [n, v] : knobs) s += (s.empty() ? "" : " ") + n + "=" + v;
    return s;
}

namespace {

// The frame-level knobs: what the bench sets around the renderer (the judging resolution, the
// pose, moving objects, the footage's response) or on the frame graph. Every pass's own knobs
// come from its folder through the registry (render/PassKnob.h).
void frameKnobs(std::vector<BenchKnob>& knobs) {
    knobs.insert(
        knobs.end(),
        {
            {"resolution",
             "render (and judging) resolution WIDTHxHEIGHT, same aspect as the session",
             [](const CameraIntrinsics& k, bool quick) {
                 // The session's size, then the standard 4:3 sizes below it with its aspect ratio.
                 std::vector<std::string> v{fmt::format("{}x{}", k.width, k.height)};
                 const std::pair<int, int> standard[] = {{1024, 768}, {640, 480}, {320, 240}};
                 for (auto [w, h] : standard)
                     if (w * h < k.width * k.height && sameAspect(w, h, k.width, k.height))
                         v.push_back(fmt::format("{}x{}", w, h));
                 if (quick) {
                     // The largest size up to 640x480 (the goal's resolution when the session has
                     // it).
                     for (const auto& s : v)
                         if (parseResolution(s).first <= 640) return std::vector<std::string>{s};
                     return std::vector<std::string>{v.back()};
                 }
                 return v;
             },
             [](BenchConfig& c, const std::string& v) {
                 std::tie(c.width, c.height) = parseResolution(v);
             },
             [](const BenchConfig& c) {
                 return c.width > 0 ? fmt::format("{}x{}", c.width, c.height)
                                    : std::string("session");
             }},
            {"static_reuse",
             "on: reuse the camera-independent passes (shadow, vpl, ism) while the plan is "
             "unchanged; off: re-run them every frame",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.graph.reuseStaticPasses = parseKnobOnOff("static_reuse", v);
             },
             [](const BenchConfig& c) { return knobOnOff(c.options.graph.reuseStaticPasses); }},
            {"sync_passes",
             "on: glFinish around every pass so each pass's GPU ms is its own (llvmpipe defers "
             "work); "
             "off: as mirage replay runs, passes overlap and only the wall ms is meaningful",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.graph.syncPasses = parseKnobOnOff("sync_passes", v);
             },
             [](const BenchConfig& c) { return knobOnOff(c.options.graph.syncPasses); }},
            {"pose_jitter",
             "tracking-like noise on every frame's pose: mm of translation (1 sigma per axis) and "
             "a tenth of that in degrees of rotation (0..10; 0: the exact ground-truth pose)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"0"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.poseJitterMm =
                     parseKnobNumber("pose_jitter", v, 0.0, 10.0, false, "a number of mm");
             },
             [](const BenchConfig& c) { return fmt::format("{:g}", c.poseJitterMm); }},
            {"moving_objects",
             "on: the virtual objects move before every frame (to 1 cm along +X and back), so "
             "every frame redoes what depends on where they stand: shadows, VPLs, ISMs, caustics, "
             "impostors (docs/live.md)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"off"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.movingObjects = parseKnobOnOff("moving_objects", v);
             },
             [](const BenchConfig& c) { return knobOnOff(c.movingObjects); }},
            {"env_source",
             "static: the scene's environment map; camera: the session's environment camera, a new "
             "frame every frame",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"static"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.environmentCamera = parseKnobChoice("env_source", v, {"static", "camera"}) == 1;
             },
             [](const BenchConfig& c) {
                 return std::string(c.environmentCamera ? "camera" : "static");
             }},
        });
    knobs.push_back(
        {"motion_blur",
         "on: what the renderer adds is blurred along its screen motion over the session's "
         "shutter time (velocity buffer + McGuire et al. 2012's reconstruction filter); off: it "
         "is drawn as a pinhole camera with an instantaneous shutter would",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"off"}; },
         [](BenchConfig& c, const std::string& v) {
             c.motionBlur = parseKnobOnOff("motion_blur", v);
         },
         [](const BenchConfig& c) { return knobOnOff(c.motionBlur); }});
    knobs.push_back(
        {"camera_response",
         "session: the footage linearised with the main camera's response from its calibration "
         "(`response`; sRGB when it states none) and the composite encoded with it; srgb: the "
         "footage taken as sRGB whatever the calibration says (what a camera without a measured "
         "response gets)",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"session"}; },
         [](BenchConfig& c, const std::string& v) {
             c.sessionResponse = parseKnobChoice("camera_response", v, {"session", "srgb"}) == 0;
         },
         [](const BenchConfig& c) { return std::string(c.sessionResponse ? "session" : "srgb"); }});
    // The aa pass's knob, with one bench-only value: ssaa2 (supersampling, not a renderer mode).
    const PassKnob* aa = findPassKnob("aa");
    knobs.push_back(
        {"aa",
         "anti-aliasing of what the renderer adds: morphological (the aa pass, an edge-directed "
         "filter of the renderer's contribution), ssaa2 (the renderer at 2x2 the resolution, "
         "averaged down: a measured alternative), off",
         [aa](const CameraIntrinsics&, bool quick) { return aa->sweep(quick); },
         [aa](BenchConfig& c, const std::string& v) {
             const bool ssaa = parseKnobChoice("aa", v, {"off", "morphological", "ssaa2"}) == 2;
             c.supersample = ssaa ? 2 : 1;
             aa->apply(c.options, ssaa ? "off" : v);
         },
         [aa](const BenchConfig& c) {
             return c.supersample == 2 ? std::string("ssaa2") : aa->read(c.options);
         }});
}

// A pass's knob as the bench sets it: on the configuration's RendererOptions.
BenchKnob benchKnob(const PassKnob& k) {
    return {k.name, k.help, [&k](const CameraIntrinsics&, bool quick) { return k.sweep(quick); },
            [&k](BenchConfig& c, const std::string& v) { k.apply(c.options, v); },
            [&k](const BenchConfig& c) { return k.read(c.options); }};
}

// The grid's (and the report's) column order of the knobs that existed when the knobs moved into
// their passes, kept so that bench tables stay comparable; a knob not listed follows them in
// registration order.
const char* const kColumnOrder[] = {"resolution",
                                    "vpls",
                                    "indirect_scale",
                                    "static_reuse",
                                    "sync_passes",
                                    "shadow_filter",
                                    "shadow_map",
                                    "shadow_rsm",
                                    "specular_trace",
                                    "impostor_resolution",
                                    "impostor_steps",
                                    "refraction_steps",
                                    "specular_vpl_stride",
                                    "specular_trace_resolution",
                                    "specular_resolution",
                                    "virtual",
                                    "caustics",
                                    "glass_shadows",
                                    "refl_refr_vpls",
                                    "caustic_map",
                                    "caustic_quad",
                                    "caustic_gather",
                                    "rough_highlight",
                                    "rough_photons",
                                    "caustic_radius",
                                    "caustic_gather_cap",
                                    "caustic_refresh",
                                    "caustic_temporal",
                                    "specular_temporal",
                                    "specular_refresh",
                                    "pose_jitter",
                                    "fuzzy",
                                    "fuzzy_cone",
                                    "fuzzy_taps",
                                    "rough_method",
                                    "gsr_subdivisions",
                                    "lean_mip_levels",
                                    "translucent_shadows",
                                    "vnm_resolution",
                                    "vnm_kernel",
                                    "vnm_surface",
                                    "vnm_albedo",
                                    "vnm_lookup",
                                    "moving_objects",
                                    "env_source",
                                    "env_resolution",
                                    "env_lights",
                                    "exposure_match",
                                    "motion_blur",
                                    "aa",
                                    "noise_match",
                                    "vignette_match",
                                    "camera_response"};

}  // namespace

// The frame's knobs and every pass's (a frame knob of the same name replaces the pass's), in
// column order.
const std::vector<BenchKnob>& benchKnobs() {
    static const std::vector<BenchKnob> knobs = [] {
        std::vector<BenchKnob> pool;
        frameKnobs(pool);
        for (const PassKnob& k : passKnobs())
            if (std::none_of(pool.begin(), pool.end(),
                             [&](const BenchKnob& b) { return b.name == k.name; }))
                pool.push_back(benchKnob(k));
        std::vector<BenchKnob> ordered;
        auto take = [&](const std::string& name) {
            const auto it = std::find_if(pool.begin(), pool.end(),
                                         [&](const BenchKnob& b) { return b.name == name; });
            if (it == pool.end()) throw Error(fmt::format("bench: no knob '{}'", name));
            ordered.push_back(std::move(*it));
            pool.erase(it);
        };
        for (const char* name : kColumnOrder) take(name);
        for (const PassKnob& k : passKnobs())
            if (std::any_of(pool.begin(), pool.end(),
                            [&](const BenchKnob& b) { return b.name == k.name; }))
                take(k.name);
        if (!pool.empty()) throw Error(fmt::format("bench: knob '{}' has no column", pool[0].name));
        return ordered;
    }();
    return knobs;
}

BenchConfig benchDefaultConfig() {
    BenchConfig c;
    c.options.graph.syncPasses = true;  // per-pass attribution of GPU time (see RendererOptions)
    return c;
}

std::map<std::string, std::string> benchDefaultKnobs() {
    const BenchConfig c = benchDefaultConfig();
    std::map<std::string, std::string> values;
    for (const auto& k : benchKnobs()) values[k.name] = k.value(c);
    return values;
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
    std::vector<BenchConfig> grid{benchDefaultConfig()};
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

}  // namespace mirage::render
