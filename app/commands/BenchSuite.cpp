#include "app/commands/BenchSuite.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "app/commands/MachineInfo.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/Shards.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "core/plot/SvgPlot.h"
#include "core/scene/Scene.h"
#include "core/session/Session.h"
#include "render/SessionEnvironment.h"
#include "render/evaluation/RealtimeBench.h"
#include "render/raytrace/GroundTruthComposite.h"
#include "render/raytrace/SyntheticSession.h"
#include "tracking/ArucoComparison.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;
using render::BenchConfig;
using render::BenchFrame;
using render::BenchResult;

// The scene with the named nodes' meshes left out (their lights and children stay).
Scene sceneVariant(const Scene& full, const std::vector<std::string>& hide,
                   const fs::path& sceneFile) {
    Scene s = full;
    for (const std::string& name : hide) {
        bool found = false;
        for (Node& n : s.nodes)
            if (n.name == name) {
                n.mesh = -1;
                found = true;
            }
        if (!found) {
            std::string names;
            for (const Node& n : full.nodes)
                if (n.mesh >= 0) names += (names.empty() ? "" : ", ") + n.name;
            throw FileError(sceneFile.string(),
                            fmt::format("the suite leaves out node '{}', which the scene does not "
                                        "have (nodes with meshes: {})",
                                        name, names));
        }
    }
    if (!s.hasVirtual())
        throw FileError(sceneFile.string(),
                        "with the suite's nodes left out no virtual object remains: nothing to "
                        "judge");
    return s;
}

// A UV sphere of about `triangles` triangles (radius 1, centred at the origin).
Mesh uvSphere(int triangles) {
    const int stacks = std::max(3, int(std::lround(std::sqrt(triangles / 4.0))));
    const int slices = std::max(3, int(std::lround(triangles / (2.0 * stacks))));
    Primitive p;
    for (int i = 0; i <= stacks; ++i) {
        const double theta = glm::pi<double>() * i / stacks;
        for (int j = 0; j <= slices; ++j) {
            const double phi = 2 * glm::pi<double>() * j / slices;
            const glm::vec3 n(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                              float(std::sin(theta) * std::sin(phi)));
            p.positions.push_back(n);
            p.normals.push_back(n);
        }
    }
    const auto idx = [&](int i, int j) { return uint32_t(i * (slices + 1) + j); };
    for (int i = 0; i < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            p.indices.insert(p.indices.end(), {idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)});
            p.indices.insert(p.indices.end(), {idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)});
        }
    Mesh m;
    m.name = fmt::format("sphere {} triangles", p.indices.size() / 3);
    m.primitives.push_back(std::move(p));
    return m;
}

size_t triangleCount(const Scene& s) {
    size_t n = 0;
    for (const MeshInstance& mi : s.meshInstances())
        for (const Primitive& p : s.meshes[size_t(mi.mesh)].primitives) n += p.indices.size() / 3;
    return n;
}

// The scene plus a virtual sphere of about `triangles` triangles beside its virtual objects.
Scene withSphere(const Scene& base, int triangles) {
    Scene s = base;
    s.meshes.push_back(uvSphere(triangles));
    for (Primitive& p : s.meshes.back().primitives) p.material = -1;  // glTF default: grey
    Node n;
    n.name = "scaling sphere";
    n.mesh = int(s.meshes.size()) - 1;
    // 8 cm radius at the table's centre, 20 cm up: in view of the suite's camera path.
    n.local = glm::dmat4(0.08);
    n.local[3] = glm::dvec4(0.0, 0.2, 0.0, 1.0);
    n.world = n.local;
    n.origin = Origin::Virtual;
    s.nodes.push_back(n);
    s.roots.push_back(int(s.nodes.size()) - 1);
    return s;
}

struct EffectRun {
    const SuiteEffect* effect = nullptr;
    fs::path session;
    CameraIntrinsics camera;
    std::vector<BenchFrame> frames;
    Scene scene;
    std::optional<render::SessionEnvironment> environment;  // SuiteEffect::environmentCamera
    std::vector<BenchResult> results;                       // unique configurations, default first
    std::vector<std::string> pointLabels;
    BenchResult baseline;
    size_t cheapest = 0;
};

std::string safeName(std::string s) {
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-') c = '_';
    return s;
}

fs::path effectSceneFile(const SuiteSpec& spec, const SuiteEffect& e) {
    return e.scene.empty() ? spec.scene : e.scene;
}

// Makes (or reuses) the effect's synthetic session under out/sessions/.
fs::path effectSession(const SuiteSpec& spec, const SuiteEffect& e, const Scene& scene,
                       const fs::path& out) {
    const fs::path sceneFile = effectSceneFile(spec, e);
    raytrace::SyntheticSessionOptions o;
    o.width = spec.width;
    o.height = spec.height;
    o.fps = spec.fps;
    o.seconds = spec.seconds;
    o.samplesPerPixel = spec.samplesPerPixel;
    o.environmentCamera = e.environmentCamera;
    o.groundTruthComposite = true;
    o.boardFile = spec.board.empty() ? sceneFile.parent_path() / "board.json" : spec.board;
    std::string hidden;
    for (const auto& h : e.hideNodes) hidden += h + ";";
    o.sceneName = fs::absolute(sceneFile).lexically_normal().string() +
                  (hidden.empty() ? "" : " without " + hidden);
    const std::string fp = raytrace::syntheticFingerprint(
        o, fileFingerprint(sceneFile) ^ fingerprint64(hidden), fileFingerprint(o.boardFile));
    const fs::path dir = out / "sessions" / (safeName(e.name) + "-" + fp.substr(0, 12));
    if (fs::exists(dir / "session.json") && render::readGroundTruthInfo(dir)) {
        spdlog::info("suite: {}: reusing the session {}", e.name, dir.string());
        return dir;
    }
    spdlog::info("suite: {}: synthesising {} at {}x{}, {} frame(s) at {} spp into {}", e.name,
                 sceneFile.filename().string(), o.width, o.height, raytrace::syntheticFrameCount(o),
                 o.samplesPerPixel, dir.string());
    fs::create_directories(dir.parent_path());
    StagedPath staged(dir);
    raytrace::writeSyntheticSession(scene, staged.temp(), o);
    staged.commit();
    return dir;
}

void loadFrames(EffectRun& run) {
    SessionReadReport report;
    const Session session = readSession(run.session, &report);
    const auto gt = render::readGroundTruthInfo(session.dir);
    if (!gt) throw FileError(run.session.string(), "the session has no ground truth");
    const SessionCamera* main = nullptr;
    for (const auto& c : session.cameras)
        if (c.role == "main") main = &c;
    if (!main && !session.cameras.empty()) main = &session.cameras.front();
    if (!main || main->calibration.empty())
        throw FileError(run.session.string(),
                        "the session has no main camera with a calibration; delete the folder "
                        "and the suite makes it again");
    run.camera = loadCalibration(session.path(main->calibration)).intrinsics;
    run.frames = render::loadBenchFrames(session, *gt, run.camera);
    if (run.frames.empty())
        throw FileError(run.session.string(), "no frame with a ground-truth composite");
    if (run.effect->environmentCamera) {
        std::string why;
        run.environment = render::SessionEnvironment::open(
            session, render::RendererOptions{}.composite.exposure, why);
        if (!run.environment)
            throw FileError(run.session.string(),
                            "the effect needs the session's environment camera: " +
                                (why.empty() ? std::string("it has none") : why) +
                                "; delete the folder and the suite makes it again");
    }
}

// The varied knob of a configuration against the defaults ("default" when none differs).
std::string pointLabel(const BenchConfig& c, const std::map<std::string, std::string>& defaults,
                       const CameraIntrinsics& camera) {
    std::string s;
    for (const auto& [k, v] : c.knobs) {
        auto it = defaults.find(k);
        std::string d = it == defaults.end() ? "" : it->second;
        if (k == "resolution" && d == "session")
            d = fmt::format("{}x{}", camera.width, camera.height);
        std::string value = v;
        if (k == "resolution" && v == "session")
            value = fmt::format("{}x{}", camera.width, camera.height);
        if (value != d) s += (s.empty() ? "" : " ") + k + "=" + v;
    }
    return s.empty() ? "default" : s;
}

void runEffect(EffectRun& run, int repeats) {
    const auto defaults = render::benchDefaultKnobs();
    std::map<std::string, std::vector<std::string>> base;
    for (const auto& [k, v] : defaults) base[k] = {v};
    std::vector<BenchConfig> configs = render::benchGrid(run.camera, false, base);
    std::set<std::string> seen{configs.front().label()};
    for (const auto& [knob, values] : run.effect->sweeps) {
        auto ov = base;
        ov[knob] = values;
        for (BenchConfig& c : render::benchGrid(run.camera, false, ov))
            if (seen.insert(c.label()).second) configs.push_back(std::move(c));
    }
    for (size_t i = 0; i < configs.size(); ++i) {
        BenchResult r =
            render::runBenchConfig(run.scene, run.camera, run.frames, configs[i], repeats,
                                   run.environment ? &run.environment->setup() : nullptr);
        run.pointLabels.push_back(pointLabel(configs[i], defaults, run.camera));
        spdlog::info("suite: {} [{}/{}] {}: {:.1f} ms/frame, influenced PSNR {:.2f} dB",
                     run.effect->name, i + 1, configs.size(), run.pointLabels.back(),
                     r.medianWallMs, r.error.psnrInfluenced);
        run.results.push_back(std::move(r));
    }
    run.baseline = render::footageBaseline(run.frames);
    run.cheapest = 0;
    for (size_t i = 0; i < run.results.size(); ++i)
        if (run.results[i].medianWallMs < run.results[run.cheapest].medianWallMs) run.cheapest = i;
}

bool beatsFootage(const BenchResult& r, const BenchResult& baseline) {
    return r.error.psnrInfluenced > baseline.error.psnrInfluenced + 0.05;
}

// real-time | ground truth | |difference| x 4, cropped to the influenced pixels (8 px margin).
cv::Mat sideBySide(const BenchResult& r, const cv::Mat& influenceFull) {
    const cv::Mat& got = r.firstComposite;
    const cv::Mat& truth = r.firstTruth;
    if (got.empty() || truth.empty() || got.size() != truth.size()) return {};
    cv::Mat influence;
    cv::resize(influenceFull, influence, got.size(), 0, 0, cv::INTER_NEAREST);
    cv::Rect box = cv::boundingRect(influence);
    if (box.area() == 0) box = cv::Rect(0, 0, got.cols, got.rows);
    const int m = 8;
    box = cv::Rect(box.x - m, box.y - m, box.width + 2 * m, box.height + 2 * m) &
          cv::Rect(0, 0, got.cols, got.rows);
    cv::Mat diff;
    cv::absdiff(got(box), truth(box), diff);
    diff.convertTo(diff, CV_8UC3, 4.0);
    const cv::Mat gap(box.height, 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{got(box), gap, truth(box), gap, diff}, row);
    // At most 1200 px wide (three panels of 400): the page's crops stay small enough to commit.
    if (row.cols > 1200)
        cv::resize(row, row, {1200, std::max(1, row.rows * 1200 / row.cols)}, 0, 0, cv::INTER_AREA);
    return row;
}

std::string fmtDb(double v) {
    return std::isfinite(v) ? fmt::format("{:.2f}", v) : "n/a";
}

void writeText(const fs::path& path, const std::string& text) {
    OutputFile f(path, OutputOrigin::Derived, OutputRule{{}, true, "mirage bench --suite"});
    {
        std::ofstream o(f.temp(), std::ios::binary);
        o << text;
        if (!o) throw FileError(f.temp().string(), "cannot write (disk full?)");
    }
    f.commit();
}

// Frames at another size for timing only (the error of these runs is not reported): footage
// and truth resized, influence nearest.
std::vector<BenchFrame> resizedFrames(const std::vector<BenchFrame>& frames, int w, int h) {
    std::vector<BenchFrame> out = frames;
    for (BenchFrame& f : out) {
        cv::resize(f.footage, f.footage, {w, h}, 0, 0, cv::INTER_LINEAR);
        cv::resize(f.truth, f.truth, {w, h}, 0, 0, cv::INTER_LINEAR);
        cv::resize(f.influence, f.influence, {w, h}, 0, 0, cv::INTER_NEAREST);
    }
    return out;
}

struct ScalingCurves {
    plot::Series pixels{"frame", {}}, vpls{"frame", {}}, triangles{"frame", {}};
    std::string table;
};

ScalingCurves runScaling(const SuiteSpec& spec, const EffectRun& run, int repeats) {
    ScalingCurves s;
    s.table = "| curve | value | ms per frame (median wall) |\n|---|---|---|\n";
    const auto defaults = render::benchDefaultKnobs();
    std::map<std::string, std::vector<std::string>> base;
    for (const auto& [k, v] : defaults) base[k] = {v};
    const BenchConfig def = render::benchGrid(run.camera, false, base).front();
    for (const std::string& res : spec.scalingResolutions) {
        int w = 0, h = 0;
        char x = 0;
        if (std::sscanf(res.c_str(), "%d%c%d", &w, &x, &h) != 3 || x != 'x' || w < 16 || h < 16)
            throw Error(fmt::format("suite: scaling resolution '{}' is not WIDTHxHEIGHT", res));
        const CameraIntrinsics cam = render::scaleIntrinsics(run.camera, w, h);
        const BenchResult r =
            render::runBenchConfig(run.scene, cam, resizedFrames(run.frames, w, h), def, repeats);
        s.pixels.points.push_back({double(w) * h / 1e6, r.medianWallMs, res});
        s.table += fmt::format("| pixels | {} | {:.1f} |\n", res, r.medianWallMs);
    }
    for (const std::string& v : spec.scalingVpls) {
        auto ov = base;
        ov["vpls"] = {v};
        const BenchResult r =
            render::runBenchConfig(run.scene, run.camera, run.frames,
                                   render::benchGrid(run.camera, false, ov).front(), repeats);
        s.vpls.points.push_back({std::stod(v), r.medianWallMs, v});
        s.table += fmt::format("| VPLs | {} | {:.1f} |\n", v, r.medianWallMs);
    }
    for (int t : spec.scalingTriangles) {
        const Scene scene = withSphere(run.scene, t);
        const size_t n = triangleCount(scene);
        const BenchResult r = render::runBenchConfig(scene, run.camera, run.frames, def, repeats);
        s.triangles.points.push_back({double(n), r.medianWallMs, std::to_string(n)});
        s.table += fmt::format("| triangles | {} | {:.1f} |\n", n, r.medianWallMs);
    }
    return s;
}

// The tracker against OpenCV ArUco: a table and a plot of time against rotation error.
std::string trackingSection(const std::vector<tracking::TrackerComparisonRow>& rows, int repeats,
                            const fs::path& out) {
    std::string md = fmt::format(
        "\n## Tracker against OpenCV ArUco\n\nmirage's tracker (libapriltag, corner refinement, "
        "IPPE + Levenberg-Marquardt pose, default options) against OpenCV 4.6 ArUco "
        "(`DICT_APRILTAG_36h11`, no corner refinement: its default) + `solvePnP`, on rendered "
        "views of the default board (tracking/ArucoComparison.h): a video (60 frames of an orbit "
        "at 30 frames/s, tracked from the previous pose after a warm-up pass) and 16 single "
        "frames (each a re-acquisition). Median wall ms per frame over {} repeat(s), one thread "
        "each; errors: medians; a pose off by more than 2 degrees or 2 % of the distance is "
        "wrong. The finer sweeps (decimation, corner refinements, tracking modes) are the Google "
        "Benchmark of docs/tracking.md.\n\n",
        repeats);
    md +=
        "| frames | method | size | ms per frame | speed-up over ArUco | tags found | corner error "
        "(px) | rotation error (deg) | translation error (%) | poses | wrong poses |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n";
    plot::ScatterPlot p;
    p.title = "Tracker against OpenCV ArUco";
    p.xLabel = "ms per frame (one thread)";
    p.yLabel = "median rotation error (deg)";
    p.drawFront = false;
    for (const auto& r : rows) {
        double arucoMs = 0;
        for (const auto& o : rows)
            if (o.frames == r.frames && o.width == r.width && o.method == "ArUco")
                arucoMs = o.medianMs;
        const auto& a = r.accuracy;
        md += fmt::format(
            "| {} | {} | {}x{} | {:.2f} | {} | {:.0f} % | {:.3f} | {:.3f} | {:.3f} | "
            "{}/{} | {} |\n",
            r.frames, r.method, r.width, r.height, r.medianMs,
            r.method == "ArUco" || arucoMs <= 0 ? std::string("-")
                                                : fmt::format("{:.2f}x", arucoMs / r.medianMs),
            100 * a.detectRate(), a.medianCornerErrPx(), a.medianRotErrDeg(),
            a.medianTransErrPercent(), a.poses, a.frames, a.wrongPoses);
        plot::Point pt{r.medianMs, a.medianRotErrDeg(),
                       fmt::format("{} {} {}", r.method, r.frames, r.width), r.method == "mirage",
                       a.wrongPoses > 0};
        if (std::isfinite(pt.y) && pt.y >= 0) p.points.push_back(pt);
    }
    writeText(out / "results" / "tracking_time_error.svg", plot::svgScatter(p));
    md +=
        "\n![tracker against ArUco](results/tracking_time_error.svg)\n\nRinged: mirage; red: "
        "a method that gave a wrong pose.\n";
    return md;
}

}  // namespace

SuiteSpec defaultSuite() {
    SuiteSpec s;
    s.scene = fs::path(MIRAGE_DEFAULT_DATA_DIR) / "scenes" / "tabletop" / "tabletop.gltf";
    const std::vector<std::pair<std::string, std::vector<std::string>>> specularSweeps = {
        {"impostor_resolution", {"64", "128", "256", "512"}},
        {"impostor_steps", {"0", "2", "4", "8"}},
        {"specular_trace", {"impostors", "cubemap"}},
        {"vpls", {"64", "256"}}};
    s.effects = {
        {"diffuse",
         "the yellow box alone: shadows and indirect light (the glass sphere and mirror left out)",
         {"glass_sphere", "mirror"},
         {{"vpls", {"64", "128", "256", "512", "1024"}},
          {"indirect_scale", {"auto", "2", "1"}},
          {"static_reuse", {"on", "off"}},
          {"shadow_filter", {"off", "pcf"}},
          {"shadow_map", {"512", "2048"}},
          {"shadow_focus", {"off", "on"}}},
         {}},
        {"mirror",
         "the mirror and the yellow box (the glass sphere left out)",
         {"glass_sphere"},
         specularSweeps,
         {}},
        {"glass",
         "the glass sphere and the yellow box (the mirror left out)",
         {"mirror"},
         specularSweeps,
         {}},
        {"both",
         "the whole tabletop: glass sphere, mirror and yellow box",
         {},
         {{"vpls", {"64", "256", "1024"}},
          {"impostor_resolution", {"128", "256"}},
          {"specular_trace", {"impostors", "cubemap"}},
          {"specular_vpl_stride", {"4", "16"}}},
         {}},
        {"caustics",
         "light through the glass sphere: its caustic, its tinted shadow and the VPLs it "
         "refracts onto the table (the mirror left out)",
         {"mirror"},
         {{"caustics", {"on", "off"}},
          {"caustic_map", {"128", "256", "512"}},
          {"glass_shadows", {"on", "off"}},
          {"refl_refr_vpls", {"on", "off"}},
          {"caustic_gather", {"on", "off"}},
          {"caustic_radius", {"0.5", "1", "2", "4"}},
          {"caustic_gather_cap", {"0", "64", "256", "1024"}}},
         {}},
    };
    const fs::path dir = s.scene.parent_path();
    SuiteEffect rough{"rough",
                      "frosted glass and brushed metal beside the yellow box "
                      "(tabletop_rough.gltf): fuzzy reflections and rough refraction",
                      {},
                      {{"fuzzy", {"on", "off"}},
                       {"fuzzy_cone", {"10", "20", "40"}},
                       {"fuzzy_taps", {"6", "12", "24"}}},
                      dir / "tabletop_rough.gltf"};
    SuiteEffect translucent{"translucent",
                            "the jade cube with a cavity and a density gradient beside the "
                            "yellow box (tabletop_translucent.gltf; glass sphere and mirror left "
                            "out): the voxel number map",
                            {"glass_sphere", "mirror"},
                            {{"vnm_resolution", {"8", "12", "16"}}},
                            dir / "tabletop_translucent.gltf"};
    SuiteEffect environment{
        "environment",
        "the yellow box lit by the room as the fish-eye environment camera "
        "films it, frame by frame, against the exact environment map",
        {"glass_sphere", "mirror"},
        {{"env_source", {"static", "camera"}}, {"env_resolution", {"64", "128", "256", "512"}}},
        {},
        true};
    s.effects.push_back(std::move(environment));
    s.effects.push_back(std::move(rough));
    s.effects.push_back(std::move(translucent));
    s.scalingResolutions = {"320x240", "640x480", "1024x768", "1600x1200", "1920x1440"};
    s.scalingVpls = {"64", "128", "256", "512", "1024"};
    s.scalingTriangles = {1000, 10000, 100000, 1000000};
    s.trackingWidths = {640, 1280};
    return s;
}

SuiteSpec loadSuite(const fs::path& file) {
    nlohmann::json j;
    {
        std::ifstream in(file);
        if (!in) throw FileError(file.string(), "cannot open the suite file");
        try {
            j = nlohmann::json::parse(in);
        } catch (const nlohmann::json::exception& e) {
            throw FileError(file.string(), std::string("not valid JSON: ") + e.what());
        }
    }
    const auto fail = [&](const std::string& field, const std::string& what) {
        return FileError(file.string(), fmt::format("field '{}': {}", field, what));
    };
    if (!j.is_object()) throw FileError(file.string(), "a suite file is a JSON object");
    SuiteSpec s;
    const SuiteSpec d = defaultSuite();
    const fs::path dir = file.parent_path();
    try {
        s.scene = j.contains("scene") ? dir / j.at("scene").get<std::string>() : d.scene;
        if (j.contains("board")) s.board = dir / j.at("board").get<std::string>();
        s.width = j.value("width", d.width);
        s.height = j.value("height", d.height);
        s.fps = j.value("fps", d.fps);
        s.seconds = j.value("seconds", d.seconds);
        s.samplesPerPixel = j.value("spp", d.samplesPerPixel);
        s.repeats = j.value("repeats", d.repeats);
        if (j.contains("scaling")) {
            const auto& sc = j.at("scaling");
            s.scalingResolutions = sc.value("resolutions", std::vector<std::string>{});
            s.scalingVpls = sc.value("vpls", std::vector<std::string>{});
            s.scalingTriangles = sc.value("triangles", std::vector<int>{});
        }
        if (j.contains("tracking"))
            s.trackingWidths = j.at("tracking").value("widths", std::vector<int>{});
        if (!j.contains("effects") || !j.at("effects").is_array() || j.at("effects").empty())
            throw fail("effects", "a non-empty list of {name, hide, sweeps} is required");
        for (const auto& e : j.at("effects")) {
            SuiteEffect x;
            x.name = e.at("name").get<std::string>();
            x.title = e.value("title", x.name);
            x.hideNodes = e.value("hide", std::vector<std::string>{});
            if (e.contains("scene")) x.scene = dir / e.at("scene").get<std::string>();
            x.environmentCamera = e.value("environment_camera", false);
            if (e.contains("sweeps"))
                for (const auto& [knob, values] : e.at("sweeps").items())
                    x.sweeps.emplace_back(knob, values.get<std::vector<std::string>>());
            if (x.name.empty()) throw fail("effects[].name", "must not be empty");
            s.effects.push_back(std::move(x));
        }
    } catch (const nlohmann::json::exception& e) {
        throw FileError(file.string(), std::string("wrong type or missing field: ") + e.what());
    }
    if (s.width < 16 || s.height < 16 || s.width > 8192 || s.height > 8192)
        throw fail("width/height", "must be 16..8192 pixels");
    if (!(s.fps > 0 && s.seconds > 0 && s.fps * s.seconds >= 1 && s.fps * s.seconds <= 1000))
        throw fail("fps/seconds", "must give 1 to 1000 frames");
    if (s.samplesPerPixel < 1 || s.samplesPerPixel > 65536) throw fail("spp", "must be 1..65536");
    if (s.repeats < 1 || s.repeats > 100) throw fail("repeats", "must be 1..100");
    for (int t : s.scalingTriangles)
        if (t < 8 || t > 20000000) throw fail("scaling.triangles", "each must be 8..20000000");
    for (int w : s.trackingWidths)
        if (w != 640 && w != 1280) throw fail("tracking.widths", "each must be 640 or 1280");
    return s;
}

// The summary table: per effect its default and cheapest setting, best error and the settings
// that do not beat the footage alone.
std::string summaryTable(const std::vector<EffectRun>& runs) {
    std::string md;
    md +=
        "| effect | default ms | default PSNR (dB) | footage only (dB) | best PSNR (dB) | "
        "cheapest ms (PSNR) | settings not beating the footage |\n|---|---|---|---|---|---|---|\n";
    for (const EffectRun& r : runs) {
        const BenchResult& d = r.results.front();
        double best = -1e9;
        std::string broken;
        for (size_t i = 0; i < r.results.size(); ++i) {
            if (std::isfinite(r.results[i].error.psnrInfluenced))
                best = std::max(best, r.results[i].error.psnrInfluenced);
            if (!beatsFootage(r.results[i], r.baseline))
                broken += (broken.empty() ? "" : ", ") + r.pointLabels[i];
        }
        const BenchResult& c = r.results[r.cheapest];
        md += fmt::format("| [{}](#{}) | {:.1f} | {} | {} | {} | {:.1f} ({}) | {} |\n",
                          r.effect->name, r.effect->name, d.medianWallMs,
                          fmtDb(d.error.psnrInfluenced), fmtDb(r.baseline.error.psnrInfluenced),
                          fmtDb(best), c.medianWallMs, fmtDb(c.error.psnrInfluenced),
                          broken.empty() ? "none" : broken);
    }

    return md;
}

// The stacked bars of every effect's default frame, pass by pass (results/passes.svg).
std::string passBars(const std::vector<EffectRun>& runs, const fs::path& out) {
    plot::StackedBarPlot bars;
    bars.title = "Time per pass of the default frame";
    bars.xLabel = "GPU ms per frame (median, passes synchronised)";
    for (const EffectRun& r : runs) {
        plot::Bar b{r.effect->name, {}};
        const BenchResult& d = r.results.front();
        for (const std::string& p : d.passOrder) {
            auto it = d.medianPassMs.find(p);
            if (it != d.medianPassMs.end() && it->second > 0) b.segments.push_back({p, it->second});
        }
        bars.bars.push_back(std::move(b));
    }
    writeText(out / "results" / "passes.svg", plot::svgStackedBars(bars));
    return "\n![time per pass](results/passes.svg)\n";
}

// One effect's section: its speed-against-error plot, the table of its settings and the
// first frame's side-by-side crops of the default and cheapest setting.
std::string effectSection(const EffectRun& r, const fs::path& out) {
    std::string md;
    const std::string name = safeName(r.effect->name);
    plot::ScatterPlot p;
    p.title = r.effect->name + ": speed against error";
    p.xLabel = "ms per frame (median wall)";
    p.yLabel = "PSNR over influenced pixels (dB)";
    for (size_t i = 0; i < r.results.size(); ++i)
        p.points.push_back({r.results[i].medianWallMs, r.results[i].error.psnrInfluenced,
                            r.pointLabels[i], i == 0, !beatsFootage(r.results[i], r.baseline)});
    p.hasBaseline = std::isfinite(r.baseline.error.psnrInfluenced);
    p.baselineY = r.baseline.error.psnrInfluenced;
    p.baselineLabel = "footage only";
    writeText(out / "results" / (name + "_time_error.svg"), plot::svgScatter(p));
    md += fmt::format("\n## {}\n\n{}. Session `{}`.\n\n![{} speed against error]({})\n\n",
                      r.effect->name, r.effect->title, fs::relative(r.session, out).string(),
                      r.effect->name, "results/" + name + "_time_error.svg");
    md +=
        "| setting | ms per frame | PSNR infl. (dB) | SSIM infl. | PSNR frame (dB) | "
        "Pareto |\n|---|---|---|---|---|---|\n";
    const std::vector<size_t> front = plot::paretoFront(p.points);
    for (size_t i = 0; i < r.results.size(); ++i) {
        const auto& e = r.results[i].error;
        md += fmt::format("| {}{} | {:.1f} | {} | {:.4f} | {} | {} |\n", r.pointLabels[i],
                          beatsFootage(r.results[i], r.baseline) ? "" : " (not above footage)",
                          r.results[i].medianWallMs, fmtDb(e.psnrInfluenced), e.ssimInfluenced,
                          fmtDb(e.psnrFrame),
                          std::find(front.begin(), front.end(), i) != front.end() ? "yes" : "");
    }
    md += fmt::format("| footage only | - | {} | {:.4f} | {} | |\n",
                      fmtDb(r.baseline.error.psnrInfluenced), r.baseline.error.ssimInfluenced,
                      fmtDb(r.baseline.error.psnrFrame));
    md += "\nFirst frame, real-time | ground truth | difference x4:\n\n";
    for (const auto& [which, idx] :
         std::vector<std::pair<std::string, size_t>>{{"default", 0}, {"cheapest", r.cheapest}}) {
        const cv::Mat crop = sideBySide(r.results[idx], r.frames.front().influence);
        if (crop.empty()) continue;
        const std::string file = fmt::format("results/images/{}_{}.png", name, which);
        writeBgr8(out / file, crop);
        md += fmt::format("- {} ({}): ![{} {}]({})\n", which, r.pointLabels[idx], r.effect->name,
                          which, file);
    }
    return md;
}

// The scaling section: frame time against pixels, VPLs and triangles.
std::string scalingSection(const EffectRun& first, const ScalingCurves& scaling,
                           const fs::path& out) {
    std::string md;
    md += fmt::format(
        "\n## Scaling\n\nThe default setting of `{}`, one quantity varied (times only: the "
        "ground truth is not rendered again). Expected: linear in pixels and in VPLs, "
        "sub-linear in triangles (most passes work per pixel or per VPL, only the G-buffer, "
        "shadow and impostor passes per triangle).\n\n",
        first.effect->name);
    const auto line = [&](const std::string& file, const std::string& title, const std::string& x,
                          plot::Series s, bool logX) {
        if (s.points.empty()) return;
        plot::LinePlot lp;
        lp.title = title;
        lp.xLabel = x;
        lp.yLabel = "ms per frame";
        lp.logX = logX;
        lp.series = {std::move(s)};
        writeText(out / "results" / file, plot::svgLines(lp));
        md += fmt::format("![{}](results/{})\n", title, file);
    };
    line("scaling_pixels.svg", "Frame time against pixels", "megapixels", scaling.pixels, false);
    line("scaling_vpls.svg", "Frame time against VPLs", "VPLs", scaling.vpls, false);
    line("scaling_triangles.svg", "Frame time against triangles", "triangles (log)",
         scaling.triangles, true);
    md += "\n" + scaling.table;
    return md;
}

void runSuite(const SuiteSpec& spec, const fs::path& out, const std::string& commandLine) {
    // Every scene is loaded (and every knob checked) before hours of synthesis.
    std::map<fs::path, Scene> loaded;
    for (const auto& e : spec.effects) {
        const fs::path file = effectSceneFile(spec, e);
        if (loaded.count(file)) continue;
        if (!fs::exists(file))
            throw FileError(file.string(),
                            e.scene.empty() ? "the suite's scene does not exist"
                                            : "effect '" + e.name + "': its scene does not exist");
        loaded.emplace(file, loadScene(file));
    }
    // Knob names and values are checked before hours of synthesis.
    {
        CameraIntrinsics probe;
        probe.width = spec.width;
        probe.height = spec.height;
        for (const auto& e : spec.effects)
            for (const auto& [k, v] : e.sweeps) {
                if (v.empty())
                    throw Error(
                        fmt::format("suite: effect '{}': knob '{}' has no values", e.name, k));
                render::benchGrid(probe, false, {{k, v}});
            }
    }
    std::vector<Scene> scenes;
    for (const auto& e : spec.effects) {
        const fs::path file = effectSceneFile(spec, e);
        scenes.push_back(sceneVariant(loaded.at(file), e.hideNodes, file));
    }
    fs::create_directories(out / "results" / "images");

    std::vector<EffectRun> runs(spec.effects.size());
    for (size_t i = 0; i < spec.effects.size(); ++i) {
        runs[i].effect = &spec.effects[i];
        runs[i].scene = scenes[i];
        runs[i].session = effectSession(spec, spec.effects[i], scenes[i], out);
        loadFrames(runs[i]);
    }

    gl::ContextOptions copt;
    copt.width = spec.width;
    copt.height = spec.height;
    gl::Context ctx = gl::Context::headless(copt);
    const std::string loadBefore = loadAverage();
    const std::string started = utcNow();
    for (EffectRun& r : runs) runEffect(r, spec.repeats);
    ScalingCurves scaling;
    const bool haveScaling = !spec.scalingResolutions.empty() || !spec.scalingVpls.empty() ||
                             !spec.scalingTriangles.empty();
    if (haveScaling) scaling = runScaling(spec, runs.front(), spec.repeats);
    std::vector<tracking::TrackerComparisonRow> trackingRows;
    for (int w : spec.trackingWidths) {
        spdlog::info("suite: the tracker against OpenCV ArUco at width {}", w);
        for (auto& r : tracking::compareTrackerWithAruco(w, spec.repeats))
            trackingRows.push_back(std::move(r));
    }
    const std::string loadAfter = loadAverage();

    // The page.
    std::string md = "# Results: speed against error\n\n";
    md +=
        "Written by `mirage bench --suite` (docs/bench.md): every effect's synthetic session "
        "rendered by the real-time renderer, one knob varied at a time from the default, each "
        "setting judged against the Embree reference's ground-truth composite.\n\n";
    md += fmt::format("- command: `{}`\n", commandLine);
    md += fmt::format("- machine: {} ({} cores), GL renderer: {} ({})\n", cpuModel(),
                      std::max(1u, std::thread::hardware_concurrency()), ctx.rendererName(),
                      ctx.versionString());
    md += fmt::format("- started {}, load average (1/5/15 min) {} before, {} after\n", started,
                      loadBefore, loadAfter);
    md += fmt::format(
        "- sessions: {}x{}, {} frame(s) each, ground truth at {} samples per pixel; times: "
        "median wall ms per frame (render + composite readback, passes synchronised so that the "
        "per-pass bars add up) over {} repeat(s); error: PSNR of the 8-bit sRGB composite over "
        "the pixels the virtual objects influence, pooled over frames\n",
        spec.width, spec.height, runs.front().frames.size(), spec.samplesPerPixel, spec.repeats);
    md +=
        "- a point drawn red does not beat the footage-only baseline (the dashed line): it "
        "shows nothing of the virtual objects that the footage alone does not\n\n";

    md += summaryTable(runs);
    md += passBars(runs, out);
    for (const EffectRun& r : runs) md += effectSection(r, out);
    if (haveScaling) md += scalingSection(runs.front(), scaling, out);
    if (!trackingRows.empty()) md += trackingSection(trackingRows, spec.repeats, out);
    writeText(out / "results.md", md);
    spdlog::info("suite: wrote {} (load average {} before, {} after)",
                 (out / "results.md").string(), loadBefore, loadAfter);
}

}  // namespace mirage::app
