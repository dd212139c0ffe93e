// `mirage bench` knobs: each knob's values and how it sets a configuration, and the grid of
// configurations (render/evaluation/RealtimeBench.h).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/evaluation/RealtimeBench.h"

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

// One of two named values: true for `yes`, false for `no`.
bool parseChoice(const std::string& knob, const std::string& v, const char* yes, const char* no) {
    if (v != yes && v != no)
        throw Error(fmt::format("bench knob '{}': '{}' is not {} or {}", knob, v, yes, no));
    return v == yes;
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

std::string onOff(bool b) {
    return b ? "on" : "off";
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

// The frame: resolution, VPLs, gather scale, pass reuse and timing.
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
            {"vpls", "virtual point lights per frame (RendererOptions::vpl.count)",
             [](const CameraIntrinsics&, bool quick) {
                 return quick ? std::vector<std::string>{"64", "256"}
                              : std::vector<std::string>{"64", "256", "1024"};
             },
             [](BenchConfig& c, const std::string& v) {
                 c.options.vpl.count = parseInt("vpls", v, 0, 16384);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.vpl.count); }},
            {"indirect_scale",
             "VPL gather at 1/N resolution per axis (1..4), or auto: width / 160 in 1..4 (4 at "
             "640x480)",
             [](const CameraIntrinsics&, bool quick) {
                 return quick ? std::vector<std::string>{"auto"}
                              : std::vector<std::string>{"auto", "2", "1"};
             },
             [](BenchConfig& c, const std::string& v) {
                 c.options.indirect.scale = v == "auto" ? 0 : parseInt("indirect_scale", v, 1, 4);
             },
             [](const BenchConfig& c) {
                 return c.options.indirect.scale == 0 ? std::string("auto")
                                                      : std::to_string(c.options.indirect.scale);
             }},
            {"static_reuse",
             "on: reuse the camera-independent passes (shadow, vpl, ism) while the plan is "
             "unchanged; off: re-run them every frame",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.graph.reuseStaticPasses = parseOnOff("static_reuse", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.graph.reuseStaticPasses); }},
            {"sync_passes",
             "on: glFinish around every pass so each pass's GPU ms is its own (llvmpipe defers "
             "work); "
             "off: as mirage replay runs, passes overlap and only the wall ms is meaningful",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.graph.syncPasses = parseOnOff("sync_passes", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.graph.syncPasses); }},
            {"shadow_filter",
             "pcf: shadow maps looked up with percentage-closer filtering over 4x4 texels "
             "(straight shadow edges); off: the 2x2 bilinear lookup (1-texel stair steps)",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{shadowFilterName(RendererOptions{}.shadow.filter)};
             },
             [](BenchConfig& c, const std::string& v) {
                 if (v != "off" && v != "pcf")
                     throw Error(
                         fmt::format("bench knob 'shadow_filter': '{}' is not off or pcf", v));
                 c.options.shadow.filter = v == "pcf" ? ShadowFilter::Pcf : ShadowFilter::Bilinear;
             },
             [](const BenchConfig& c) {
                 return std::string(shadowFilterName(c.options.shadow.filter));
             }},
            {"shadow_map", "texels per side of each shadow-map layer (occluder distance)",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{std::to_string(RendererOptions{}.shadow.mapSize)};
             },
             [](BenchConfig& c, const std::string& v) {
                 c.options.shadow.mapSize = parseInt("shadow_map", v, 16, 4096);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.shadow.mapSize); }},
            {"shadow_rsm",
             "texels per side of each reflective-shadow-map layer (the VPLs' source; its own "
             "raster when it differs from shadow_map)",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{std::to_string(RendererOptions{}.shadow.rsmSize)};
             },
             [](BenchConfig& c, const std::string& v) {
                 c.options.shadow.rsmSize = parseInt("shadow_rsm", v, 16, 4096);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.shadow.rsmSize); }},
        });
}

// Specular objects. One default value each, so the default grid does not grow; sweep them
// with --knob (docs/bench.md). They change nothing in a scene without mirror or glass (the
// impostor and specular passes do not run).
void specularKnobs(std::vector<BenchKnob>& knobs) {
    knobs.insert(
        knobs.end(),
        {
            {"specular_trace",
             "what reflected/refracted rays are traced against: impostors (Popescu et al. 2006) or "
             "cubemap (the plain G-buffer cube-map baseline)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"impostors"}; },
             [](BenchConfig& c, const std::string& v) {
                 if (v != "impostors" && v != "cubemap")
                     throw Error(fmt::format(
                         "bench: knob specular_trace: '{}' is not impostors or cubemap", v));
                 c.options.impostor.cubeMapBaseline = v == "cubemap";
             },
             [](const BenchConfig& c) {
                 return std::string(c.options.impostor.cubeMapBaseline ? "cubemap" : "impostors");
             }},
            {"impostor_resolution", "texels per side of each impostor and cube-map face",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"256"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.impostor.resolution = parseInt("impostor_resolution", v, 16, 2048);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.impostor.resolution); }},
            {"impostor_steps", "refinement steps of the impostor height-field search",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"2"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.impostor.refineSteps = parseInt("impostor_steps", v, 0, 32);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.impostor.refineSteps); }},
            {"refraction_steps",
             "march steps of the refracted ray through the back-face buffer (the exit point; also "
             "the caustic photons')",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"16"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.specular.refractionMarchSteps = parseInt("refraction_steps", v, 2, 128);
             },
             [](const BenchConfig& c) {
                 return std::to_string(c.options.specular.refractionMarchSteps);
             }},
            {"specular_vpl_stride",
             "VPL interleaving at the reflected/refracted hits: each hit sums every N-th VPL (x N) "
             "over an N-pixel tile: 1 (all), 4 (2x2) or 16 (4x4)",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{
                     std::to_string(RendererOptions{}.specular.vplStride)};
             },
             [](BenchConfig& c, const std::string& v) {
                 const int n = parseInt("specular_vpl_stride", v, 1, 16);
                 if (n != 1 && n != 4 && n != 16)
                     throw Error(
                         fmt::format("bench: knob specular_vpl_stride: '{}' is not 1, 4 or 16", v));
                 c.options.specular.vplStride = n;
             },
             [](const BenchConfig& c) { return std::to_string(c.options.specular.vplStride); }},
            {"specular_trace_resolution",
             "resolution of the reflected/refracted ray search (specgbuf): full (a ray pair per "
             "specular pixel) or half (one per 2x2 block, filled by primary-surface geometry)",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{
                     RendererOptions{}.specular.halfResolutionTrace ? "half" : "full"};
             },
             [](BenchConfig& c, const std::string& v) {
                 c.options.specular.halfResolutionTrace =
                     parseChoice("specular_trace_resolution", v, "half", "full");
             },
             [](const BenchConfig& c) {
                 return std::string(c.options.specular.halfResolutionTrace ? "half" : "full");
             }},
            {"specular_resolution",
             "resolution of the lighting at the reflected/refracted hits: full (every specular "
             "pixel) or half (one pixel per 2x2 block, upsampled by hit geometry)",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{
                     RendererOptions{}.specular.halfResolution ? "half" : "full"};
             },
             [](BenchConfig& c, const std::string& v) {
                 if (v != "full" && v != "half")
                     throw Error(fmt::format(
                         "bench: knob specular_resolution: '{}' is not full or half", v));
                 c.options.specular.halfResolution = v == "half";
             },
             [](const BenchConfig& c) {
                 return std::string(c.options.specular.halfResolution ? "half" : "full");
             }},
            {"virtual",
             "on: composite the virtual objects; off: the composite is the footage unchanged (a "
             "sanity point: it must score as the footage-only row, and any configuration that does "
             "not beat that row is broken)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.composite.showVirtual = parseOnOff("virtual", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.composite.showVirtual); }},
        });
}

// Caustics (docs/caustics.md): one default value each, as the specular knobs; and the pose
// jitter the temporal buffers are judged under.
void causticKnobs(std::vector<BenchKnob>& knobs) {
    knobs.insert(
        knobs.end(),
        {
            {"caustics",
             "on: photon G-buffers and the caustic splat for spot lights on mirror/glass",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.caustic.enabled = parseOnOff("caustics", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.caustic.enabled); }},
            {"glass_shadows",
             "on: glass transmits (tints) the light in the shadow maps of lights without caustics; "
             "off: glass is opaque there",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.shadow.glass = parseOnOff("glass_shadows", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.shadow.glass); }},
            {"refl_refr_vpls",
             "on: a VPL on a mirror or glass follows the reflected / refracted photon to its "
             "receiver (spot lights with caustics); off: it stays dark on the object",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.vpl.throughSpecular = parseOnOff("refl_refr_vpls", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.vpl.throughSpecular); }},
            {"caustic_map", "texels per side of each photon G-buffer (a multiple of 8)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"256"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.caustic.mapSize = parseInt("caustic_map", v, 16, 2048);
                 if (c.options.caustic.mapSize % 8 != 0)
                     throw Error(
                         fmt::format("bench: knob caustic_map: {} is not a multiple of 8", v));
             },
             [](const BenchConfig& c) { return std::to_string(c.options.caustic.mapSize); }},
            {"caustic_quad", "photon quad radius in photon spacings on the receiver (0.25..8)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"1.5"}; },
             [](BenchConfig& c, const std::string& v) {
                 char* end = nullptr;
                 const float q = std::strtof(v.c_str(), &end);
                 if (v.empty() || end != v.c_str() + v.size() || !(q >= 0.25f && q <= 8.0f))
                     throw Error(fmt::format(
                         "bench: knob caustic_quad: '{}' is not a number in [0.25, 8]", v));
                 c.options.caustic.quadScale = q;
             },
             [](const BenchConfig& c) { return fmt::format("{:g}", c.options.caustic.quadScale); }},
            {"caustic_gather",
             "on: the photons in a world-space grid, gathered at the reflected / refracted hits "
             "(caustics seen in mirrors and through glass); off: those hits get no caustic",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.caustic.gather = parseOnOff("caustic_gather", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.caustic.gather); }},
            {"rough_highlight",
             "on: rough mirrors, metals and glass show the punctual lights' GGX highlight; off: "
             "their light comes from the mirror / refracted ray alone (no highlight)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.direct.roughHighlight = parseOnOff("rough_highlight", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.direct.roughHighlight); }},
            {"rough_photons",
             "on: photons leaving a rough mirror, metal or glass scatter over its GGX lobe (a "
             "soft caustic, spread reflected / refracted VPLs); off: they follow the mirror / "
             "Snell ray (a sharp caustic)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.caustic.roughLobes = parseOnOff("rough_photons", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.caustic.roughLobes); }},
            {"caustic_radius",
             "photon kernel radius cap of the caustic gather, in cm (0.1..50; grid cells are twice "
             "that)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"1"}; },
             [](BenchConfig& c, const std::string& v) {
                 char* end = nullptr;
                 const float q = std::strtof(v.c_str(), &end);
                 if (v.empty() || end != v.c_str() + v.size() || !(q >= 0.1f && q <= 50.0f))
                     throw Error(fmt::format(
                         "bench: knob caustic_radius: '{}' is not a number of cm in [0.1, 50]", v));
                 c.options.caustic.gatherRadius = 0.01f * q;
             },
             [](const BenchConfig& c) {
                 return fmt::format("{:g}", 100.0f * c.options.caustic.gatherRadius);
             }},
            {"caustic_gather_cap",
             "photons the caustic gather reads per grid bucket, 0 = all (a fuller bucket is read "
             "by its finest stratified subsample of the photon map within the cap, weighted by "
             "count / read)",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{
                     std::to_string(RendererOptions{}.caustic.gatherCap)};
             },
             [](BenchConfig& c, const std::string& v) {
                 char* end = nullptr;
                 const long q = std::strtol(v.c_str(), &end, 10);
                 if (v.empty() || end != v.c_str() + v.size() || q < 0 || q > (1 << 20))
                     throw Error(
                         fmt::format("bench: knob caustic_gather_cap: '{}' is not a photon "
                                     "count in 0..1048576 (0: all)",
                                     v));
                 c.options.caustic.gatherCap = int(q);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.caustic.gatherCap); }},
            {"caustic_refresh",
             "frames between two splats of the caustic photons (1..8); in the frames between, last "
             "frame's caustic reprojected by the receivers' positions",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{
                     std::to_string(RendererOptions{}.caustic.refreshInterval)};
             },
             [](BenchConfig& c, const std::string& v) {
                 c.options.caustic.refreshInterval = parseInt("caustic_refresh", v, 1, 8);
             },
             [](const BenchConfig& c) {
                 return std::to_string(c.options.caustic.refreshInterval);
             }},
            {"caustic_temporal",
             "on: the caustic buffer smoothed over frames (reprojected history, the GI filter's "
             "reset rules); off: every frame's caustic stands alone",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.caustic.temporal = parseOnOff("caustic_temporal", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.caustic.temporal); }},
            {"specular_temporal",
             "on: the light of the reflected / refracted hits (L'_rv, L'_r) smoothed over frames, "
             "history rejected where a hit moved; off: every frame's stands alone",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.specular.temporal = parseOnOff("specular_temporal", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.specular.temporal); }},
            {"specular_refresh",
             "frames over which the reflected / refracted hits' light is refreshed (1, 2 or 4): "
             "each frame shades one phase of 8x8-pixel tiles, the others take last frame's light "
             "where it was lit at this frame's hits",
             [](const CameraIntrinsics&, bool) {
                 return std::vector<std::string>{
                     std::to_string(RendererOptions{}.specular.refreshInterval)};
             },
             [](BenchConfig& c, const std::string& v) {
                 const int n = parseInt("specular_refresh", v, 1, 4);
                 if (n == 3)
                     throw Error(
                         fmt::format("bench knob 'specular_refresh': '{}' is not 1, 2 or 4", v));
                 c.options.specular.refreshInterval = n;
             },
             [](const BenchConfig& c) {
                 return std::to_string(c.options.specular.refreshInterval);
             }},
            {"pose_jitter",
             "tracking-like noise on every frame's pose: mm of translation (1 sigma per axis) and "
             "a tenth of that in degrees of rotation (0..10; 0: the exact ground-truth pose)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"0"}; },
             [](BenchConfig& c, const std::string& v) {
                 char* end = nullptr;
                 const double q = std::strtod(v.c_str(), &end);
                 if (v.empty() || end != v.c_str() + v.size() || !(q >= 0.0 && q <= 10.0))
                     throw Error(fmt::format(
                         "bench: knob pose_jitter: '{}' is not a number of mm in [0, 10]", v));
                 c.poseJitterMm = q;
             },
             [](const BenchConfig& c) { return fmt::format("{:g}", c.poseJitterMm); }},
        });
}

// Fuzzy reflections of rough metals and rough glass (docs/specular.md): one default value
// each.
void roughKnobs(std::vector<BenchKnob>& knobs) {
    knobs.insert(
        knobs.end(),
        {
            {"fuzzy",
             "on: the fuzzy-reflection filter over rough metals' mirror reflections; off: rough "
             "metals reflect sharply (their roughness ignored)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.fuzzy.enabled = parseOnOff("fuzzy", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.fuzzy.enabled); }},
            {"fuzzy_cone", "the fuzzy filter's cone bound Theta in degrees (0 < Theta <= 60)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"20"}; },
             [](BenchConfig& c, const std::string& v) {
                 char* end = nullptr;
                 const float q = std::strtof(v.c_str(), &end);
                 if (v.empty() || end != v.c_str() + v.size() || !(q > 0.0f && q <= 60.0f))
                     throw Error(
                         fmt::format("bench: knob fuzzy_cone: '{}' is not a number in (0, 60]", v));
                 c.options.fuzzy.coneDeg = q;
             },
             [](const BenchConfig& c) { return fmt::format("{:g}", c.options.fuzzy.coneDeg); }},
            {"fuzzy_taps", "taps per side of each separable fuzzy-filter pass (1..64)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"12"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.fuzzy.taps = parseInt("fuzzy_taps", v, 1, 64);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.fuzzy.taps); }},
            // Rough glass (docs/specular.md, "Rough refraction"): one default value each.
            {"rough_method",
             "how rough glass blurs what is seen through it: lean (LEAN-mapped back faces, one "
             "lobe), gsr (Gaussian sum reduction, one lobe per hemisphere subdivision) or filter "
             "(the fuzzy pass's image-space filter)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"lean"}; },
             [](BenchConfig& c, const std::string& v) {
                 if (v == "lean")
                     c.options.rough.method = RoughRefractionMethod::Lean;
                 else if (v == "gsr")
                     c.options.rough.method = RoughRefractionMethod::Gsr;
                 else if (v == "filter")
                     c.options.rough.method = RoughRefractionMethod::Filter;
                 else
                     throw Error(fmt::format(
                         "bench: knob rough_method: '{}' is not one of lean, gsr, filter", v));
             },
             [](const BenchConfig& c) {
                 return std::string(roughRefractionMethodName(c.options.rough.method));
             }},
            {"gsr_subdivisions", "hemisphere sectors of the Gaussian sum reduction (1..8)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"4"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.rough.gsrSubdivisions = parseInt("gsr_subdivisions", v, 1, 8);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.rough.gsrSubdivisions); }},
            {"lean_mip_levels",
             "mip levels of the rough-refraction chains (LEAN moments, camera image, rough-glass "
             "radiance; 1..12): a wider lobe is cut at the last",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"8"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.rough.mipLevels = parseInt("lean_mip_levels", v, 1, 12);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.rough.mipLevels); }},
        });
}

// Translucent objects (docs/translucency.md) and moving objects.
void translucencyKnobs(std::vector<BenchKnob>& knobs) {
    knobs.insert(
        knobs.end(),
        {
            {"translucent_shadows",
             "on: a translucent object lets light through in the shadow maps (its optical "
             "thickness along the light's ray, coloured by its medium); off: it is opaque there",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"on"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.translucency.shadows = parseOnOff("translucent_shadows", v);
             },
             [](const BenchConfig& c) { return onOff(c.options.translucency.shadows); }},
            {"vnm_resolution",
             "voxels along a translucent object's longest side in its voxel number map (2..512; "
             "the LUT grows with the 4th power)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"16"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.translucency.vnmResolution = parseInt("vnm_resolution", v, 2, 512);
             },
             [](const BenchConfig& c) {
                 return std::to_string(c.options.translucency.vnmResolution);
             }},
            {"vnm_kernel",
             "how light spreads between a translucent object's surface voxels: diffusion "
             "(e^{-k tau}, k = min(1, sqrt(3 (1 - albedo))) per channel) or extinction (the "
             "seed's e^{-tau})",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"extinction"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.translucency.diffusionKernel =
                     parseChoice("vnm_kernel", v, "diffusion", "extinction");
             },
             [](const BenchConfig& c) {
                 return std::string(c.options.translucency.diffusionKernel ? "diffusion"
                                                                           : "extinction");
             }},
            {"vnm_surface",
             "where a surface voxel's normal and area come from: mesh (the object's triangles) "
             "or occupancy (the empty voxels around it and its exposed faces)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"occupancy"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.translucency.meshSurface =
                     parseChoice("vnm_surface", v, "mesh", "occupancy");
             },
             [](const BenchConfig& c) {
                 return std::string(c.options.translucency.meshSurface ? "mesh" : "occupancy");
             }},
            {"vnm_albedo",
             "the share of a translucent object's scattered light that leaves it: walks (measured "
             "by random walks through its voxels) or hapke (a thick half-space's albedo)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"hapke"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.translucency.measuredAlbedo =
                     parseChoice("vnm_albedo", v, "walks", "hapke");
             },
             [](const BenchConfig& c) {
                 return std::string(c.options.translucency.measuredAlbedo ? "walks" : "hapke");
             }},
            {"vnm_lookup",
             "a translucent pixel's radiance: smooth (each voxel's near field normalised, the "
             "surface voxels within 1.5 voxels blended) or nearest (the nearest voxel alone)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"smooth"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.translucency.smoothLookup =
                     parseChoice("vnm_lookup", v, "smooth", "nearest");
             },
             [](const BenchConfig& c) {
                 return std::string(c.options.translucency.smoothLookup ? "smooth" : "nearest");
             }},
            {"moving_objects",
             "on: the virtual objects move before every frame (to 1 cm along +X and back), so "
             "every frame redoes what depends on where they stand: shadows, VPLs, ISMs, caustics, "
             "impostors (docs/live.md)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"off"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.movingObjects = parseOnOff("moving_objects", v);
             },
             [](const BenchConfig& c) { return onOff(c.movingObjects); }},
        });
}

// The environment (docs/environment.md). Defaults keep the static map, so the default grid
// is unchanged; sweep with --knob env_source=static,camera --knob env_resolution=...
void environmentKnobs(std::vector<BenchKnob>& knobs) {
    knobs.insert(
        knobs.end(),
        {
            {"env_source",
             "static: the scene's environment map; camera: the session's environment camera, a new "
             "frame every frame",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"static"}; },
             [](BenchConfig& c, const std::string& v) {
                 if (v != "static" && v != "camera")
                     throw Error(
                         fmt::format("bench: knob env_source: '{}' is not static or camera", v));
                 c.environmentCamera = v == "camera";
             },
             [](const BenchConfig& c) {
                 return std::string(c.environmentCamera ? "camera" : "static");
             }},
            {"env_resolution",
             "width of the environment map built from each environment-camera frame (height = "
             "width "
             "/ 2; with env_source=camera)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"512"}; },
             [](BenchConfig& c, const std::string& v) {
                 const int w = parseInt("env_resolution", v, 16, 4096);
                 if (w % 2 != 0)
                     throw Error(fmt::format("bench: knob env_resolution: '{}' is not even", v));
                 c.options.environment.mapWidth = w;
             },
             [](const BenchConfig& c) { return std::to_string(c.options.environment.mapWidth); }},
            {"env_lights",
             "lights found in each environment-camera frame placed as shadow-casting lights, taken "
             "out of the environment light (0 = none; with env_source=camera)",
             [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"0"}; },
             [](BenchConfig& c, const std::string& v) {
                 c.options.environment.lights = parseInt("env_lights", v, 0, kMaxLights);
             },
             [](const BenchConfig& c) { return std::to_string(c.options.environment.lights); }},
        });
}

// Matching the camera (docs/camera-matching.md). Off by default, so that the default grid is the
// renderer as a model (a fixed exposure, as before); `mirage replay` and `mirage live` switch it
// on. Sweep with --knob exposure_match=off,on on a session whose exposure or white balance moves.
void cameraKnobs(std::vector<BenchKnob>& knobs) {
    knobs.push_back(
        {"exposure_match",
         "on: the exposure and white balance estimated every frame from the footage against the "
         "rendered real surfaces, applied to what the renderer adds; off: the fixed --exposure",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"off"}; },
         [](BenchConfig& c, const std::string& v) {
             c.options.exposureMatch.enabled = parseOnOff("exposure_match", v);
         },
         [](const BenchConfig& c) { return onOff(c.options.exposureMatch.enabled); }});
    knobs.push_back(
        {"motion_blur",
         "on: what the renderer adds is blurred along its screen motion over the session's "
         "shutter time (velocity buffer + McGuire et al. 2012's reconstruction filter); off: it "
         "is drawn as a pinhole camera with an instantaneous shutter would",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"off"}; },
         [](BenchConfig& c, const std::string& v) { c.motionBlur = parseOnOff("motion_blur", v); },
         [](const BenchConfig& c) { return onOff(c.motionBlur); }});
    knobs.push_back(
        {"aa",
         "anti-aliasing of what the renderer adds: morphological (the aa pass, an edge-directed "
         "filter of the renderer's contribution), ssaa2 (the renderer at 2x2 the resolution, "
         "averaged down: a measured alternative), off",
         [](const CameraIntrinsics&, bool) {
             return std::vector<std::string>{RendererOptions{}.aa.enabled ? "morphological"
                                                                          : "off"};
         },
         [](BenchConfig& c, const std::string& v) {
             if (v != "off" && v != "morphological" && v != "ssaa2")
                 throw Error(
                     fmt::format("bench knob 'aa': '{}' is not off, morphological or ssaa2", v));
             c.supersample = v == "ssaa2" ? 2 : 1;
             c.options.aa.enabled = v == "morphological";
         },
         [](const BenchConfig& c) {
             return c.supersample == 2
                        ? std::string("ssaa2")
                        : std::string(c.options.aa.enabled ? "morphological" : "off");
         }});
    knobs.push_back(
        {"noise_match",
         "on: the footage's noise (its level per intensity, estimated every frame) added to the "
         "pixels the renderer changed, drawn from the footage's own grain; synthesised: the same "
         "level drawn as Gaussian noise from a seed; off: they stay clean",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"off"}; },
         [](BenchConfig& c, const std::string& v) {
             if (v != "off" && v != "on" && v != "synthesised")
                 throw Error(fmt::format(
                     "bench knob 'noise_match': '{}' is not off, on or synthesised", v));
             c.options.grain.noise.enabled = v != "off";
             c.options.grain.noise.footageGrain = v == "on";
         },
         [](const BenchConfig& c) {
             const auto& n = c.options.grain.noise;
             return std::string(!n.enabled ? "off" : n.footageGrain ? "on" : "synthesised");
         }});
    knobs.push_back(
        {"vignette_match",
         "on: the camera's vignetting (estimated from the footage over frames) applied to the "
         "virtual pixels; off: none",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"off"}; },
         [](BenchConfig& c, const std::string& v) {
             c.options.grain.vignette.enabled = parseOnOff("vignette_match", v);
         },
         [](const BenchConfig& c) { return onOff(c.options.grain.vignette.enabled); }});
    knobs.push_back(
        {"camera_response",
         "session: the footage linearised with the main camera's response from its calibration "
         "(`response`; sRGB when it states none) and the composite encoded with it; srgb: the "
         "footage taken as sRGB whatever the calibration says (what a camera without a measured "
         "response gets)",
         [](const CameraIntrinsics&, bool) { return std::vector<std::string>{"session"}; },
         [](BenchConfig& c, const std::string& v) {
             if (v != "session" && v != "srgb")
                 throw Error(
                     fmt::format("bench knob 'camera_response': '{}' is not session or srgb", v));
             c.sessionResponse = v == "session";
         },
         [](const BenchConfig& c) { return std::string(c.sessionResponse ? "session" : "srgb"); }});
}

}  // namespace

// The knobs, one group per effect, in the grid's (and the report's) column order.
const std::vector<BenchKnob>& benchKnobs() {
    static const std::vector<BenchKnob> knobs = [] {
        std::vector<BenchKnob> k;
        frameKnobs(k);
        specularKnobs(k);
        causticKnobs(k);
        roughKnobs(k);
        translucencyKnobs(k);
        environmentKnobs(k);
        cameraKnobs(k);
        return k;
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
