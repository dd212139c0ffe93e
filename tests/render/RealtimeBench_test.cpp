// `mirage bench` and the ground-truth composite of synthetic sessions: a
// tiny session with the reference renderer's ground-truth composite is synthesised, the real-time
// renderer is run over it at the ground-truth poses and judged by PSNR/SSIM over the whole frame
// and over the pixels the virtual object influences; floors are asserted, and the same comparison
// fails for deliberately broken renders (the footage alone; a render without the virtual object).
// The command line is run end to end on the bundled scene, with its error paths.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>

#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "core/session/Session.h"
#include "render/Renderer.h"
#include "render/evaluation/ImageComparison.h"
#include "render/evaluation/RealtimeBench.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/GroundTruthComposite.h"
#include "render/raytrace/SyntheticSession.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::render {
namespace {

namespace fs = std::filesystem;

// Floors, ~2 dB / ~0.01-0.03 SSIM below what the renderer measures here (36.4 dB / 0.981 frame,
// 24.2 dB / 0.829 influenced; llvmpipe, 160x120, reference 32 spp, 3 frames, 256 VPLs). The
// footage alone scores 25.2 dB / 0.952 and 12.8 dB / 0.392 (docs/bench.md).
constexpr double kMinPsnrFrame = 34.0, kMinSsimFrame = 0.97;
constexpr double kMinPsnrInfluenced = 22.5, kMinSsimInfluenced = 0.80;

bool passesFloors(const CompositeError& e) {
    return e.psnrFrame >= kMinPsnrFrame && e.ssimFrame >= kMinSsimFrame &&
           e.psnrInfluenced >= kMinPsnrInfluenced && e.ssimInfluenced >= kMinSsimInfluenced;
}

std::ostream& operator<<(std::ostream& o, const CompositeError& e) {
    return o << "frame PSNR " << e.psnrFrame << " dB, SSIM " << e.ssimFrame << "; influenced PSNR "
             << e.psnrInfluenced << " dB, SSIM " << e.ssimInfluenced << " (" << e.influencedPixels
             << " px)";
}

// The accuracy scene (RealtimeAccuracy_test): a real table under a real spot light, a virtual
// diffuse box at the origin throwing its shadow towards -X.
Scene benchScene(bool withVirtualBox) {
    Scene s;
    const int table = test::addMaterial(s, glm::vec3(0.7f));
    const int boxMat = test::addMaterial(s, glm::vec3(0.8f, 0.3f, 0.2f));
    test::addFloor(s, "table", 0.0f, 4.0f, table, Origin::Real);
    if (withVirtualBox)
        test::addBox(s, "virtual box", {-0.2f, 0.0f, -0.2f}, {0.2f, 0.4f, 0.2f}, boxMat,
                     Origin::Virtual);
    const glm::vec3 lightPos{1.2f, 2.0f, 0.0f};
    const glm::vec3 axis = glm::normalize(glm::vec3(-0.6f, 0.0f, 0.0f) - lightPos);
    test::addLight(s, Light::Type::Spot, lightPos, axis, 8.0f, Origin::Real, 1.0f, 0.9f);
    return s;
}

raytrace::SyntheticSessionOptions tinySessionOptions() {
    raytrace::SyntheticSessionOptions o;
    o.width = 160;
    o.height = 120;
    o.hfovDeg = 63.2;  // f = 130 px, as the accuracy test's camera
    o.fps = 6.0;
    o.seconds = 0.5;  // 3 frames: two on the orbit, one hand-held
    o.samplesPerPixel = 32;
    o.threads = 2;
    o.seed = 7;
    o.environmentCamera = false;
    o.imageSequence = true;  // lossless footage: the comparison sees rendering error only
    o.groundTruthComposite = true;
    o.path.radius = 2.5;
    o.path.height = 2.5;
    o.sceneName = "in-memory bench scene";
    return o;
}

// One synthetic session shared by the tests of this file (rendered once per process, ~2 s).
// ctest runs each test in its own process, in parallel: every test gets its own folder, named
// after it, so one never reads a session another is still writing. (Its own top-level folder:
// outputDir() empties the folder it is given, so a shared parent would be wiped under the feet
// of a test that is still reading its session — a flaky failure seen under load.)
const fs::path& tinySession() {
    static const fs::path dir = [] {
        const fs::path d = mirage::test::outputDirForThisTest("bench_session");
        raytrace::writeSyntheticSession(benchScene(true), d, tinySessionOptions());
        return d;
    }();
    return dir;
}

// A synthetic session's main-camera intrinsics and its bench frames (pose, footage, ground truth).
struct LoadedBenchSession {
    CameraIntrinsics camera;
    std::vector<BenchFrame> frames;
};
LoadedBenchSession loadBenchSession(const fs::path& dir) {
    const Session session = readSession(dir);
    const auto info = readGroundTruthInfo(dir);
    EXPECT_TRUE(info.has_value()) << dir;
    if (!info) return {};
    const CameraCalibration calib = loadSessionCalibration(session, "main");
    return {calib.intrinsics, loadBenchFrames(session, *info, calib.intrinsics)};
}

TEST(GroundTruthComposite, SynthWritesCompositeAndInfluenceThatMatchTheReferenceComposite) {
    const fs::path dir = tinySession();
    SessionReadReport report;
    const Session session = readSession(dir, &report);
    ASSERT_EQ(session.frames.size(), 3u);
    const auto info = readGroundTruthInfo(dir);
    ASSERT_TRUE(info.has_value());
    EXPECT_EQ(info->samplesPerPixel, 32);
    const CameraCalibration calib = loadSessionCalibration(session, "main");

    auto frames = openCameraFrames(session, "main");
    cv::Mat footage;
    ASSERT_TRUE(frames->read(footage));
    const auto gt = readGroundTruthFrame(dir, *info, session.frames[0].index);
    ASSERT_TRUE(gt.has_value());
    ASSERT_EQ(gt->compositeSrgb.size(), footage.size());
    const int virtualPx = cv::countNonZero(gt->influence == kInfluenceVirtual);
    const int changedPx = cv::countNonZero(gt->influence == kInfluenceChanged);
    EXPECT_GT(virtualPx, 200);  // the box
    EXPECT_GT(changedPx, 200);  // its shadow
    // Outside the influenced pixels the ground truth is the footage up to changes below the
    // threshold (same seeds: paths that touch no virtual object are the same paths; the rest
    // differ by less than 0.01).
    const cv::Mat untouched = gt->influence == kInfluenceNone;
    EXPECT_GT(psnr(gt->compositeSrgb, footage, 255.0, untouched), 48.0);
    EXPECT_LT(psnr(gt->compositeSrgb, footage, 255.0, gt->influence > 0), 25.0);

    // The stored composite is the reference renderer's differential composite (Eqs. 1-2) of the
    // footage at the same pose and seed: what docs/session.md claims.
    const raytrace::EmbreeDevice device("threads=2");
    raytrace::RenderSettings st;
    st.samplesPerPixel = 32;
    st.threads = 2;
    st.seed = 7;  // synth: seed + frame * 1000
    const raytrace::DifferentialImages ref = raytrace::renderDifferential(
        benchScene(true), device, {calib.intrinsics, *session.frames[0].groundTruth}, st);
    const cv::Mat composite =
        linearRgbToSrgbBgr8(raytrace::compositeDifferential(srgbBgr8ToLinearRgb(footage), ref));
    const double p = psnr(gt->compositeSrgb, composite, 255.0);
    std::cout << "[ ground truth ] stored vs differential composite: " << p << " dB\n";
    EXPECT_GT(p, 45.0);
    // The mask is the reference's: recomputing it from L_r, L_rv and the coverage agrees.
    const cv::Mat mask =
        influenceMask(ref.realOnly, ref.realAndVirtual, ref.virtualCoverage, 1.0, 0.01);
    EXPECT_EQ(cv::countNonZero(mask != gt->influence), 0);
}

TEST(GroundTruthComposite, InvalidOrAbsentFilesAreHandled) {
    const fs::path dir = mirage::test::outputDir("bench_gt_invalid");
    EXPECT_FALSE(readGroundTruthInfo(dir).has_value());  // absent: no ground truth, no error
    std::ofstream(dir / kGroundTruthFile) << "{\"format\": \"something else\", \"version\": 1}";
    EXPECT_THROW(readGroundTruthInfo(dir), FileError);
    std::ofstream(dir / kGroundTruthFile)
        << "{\"format\": \"mirage-ground-truth-composite\", \"version\": 1, \"composite\": "
           "\"../elsewhere\"}";
    EXPECT_THROW(readGroundTruthInfo(dir), FileError);
    std::ofstream(dir / kGroundTruthFile)
        << "{\"format\": \"mirage-ground-truth-composite\", \"version\": 99}";
    EXPECT_THROW(readGroundTruthInfo(dir), FileError);
    // A frame whose files are missing is absent, not an error.
    GroundTruthInfo info;
    EXPECT_FALSE(readGroundTruthFrame(dir, info, 0).has_value());
    // A scene without virtual objects has no composite to write.
    raytrace::SyntheticSessionOptions o = tinySessionOptions();
    o.seconds = 0.1;
    EXPECT_THROW(raytrace::writeSyntheticSession(benchScene(false), dir / "s", o), Error);
}

TEST(RealtimeBench, RealtimeCompositeMeetsFloorsAndBrokenRendersFail) {
    const auto [camera, frames] = loadBenchSession(tinySession());
    ASSERT_EQ(frames.size(), 3u);

    gl::Context context = gl::Context::headless();
    const std::vector<BenchConfig> grid = benchGrid(camera, true, {{"vpls", {"256"}}});
    ASSERT_EQ(grid.size(), 1u);
    EXPECT_EQ(
        grid[0].label(),
        "resolution=160x120 vpls=256 indirect_scale=auto static_reuse=on sync_passes=on "
        "shadow_filter=off shadow_map=512 shadow_rsm=512 specular_trace=impostors "
        "impostor_resolution=256 "
        "impostor_steps=2 "
        "refraction_steps=16 specular_vpl_stride=16 specular_trace_resolution=full "
        "specular_resolution=" +
            std::string(RendererOptions{}.specular.halfResolution ? "half" : "full") +
            " virtual=on "
            "caustics=on glass_shadows=on refl_refr_vpls=on caustic_map=256 caustic_quad=1.5 "
            "caustic_gather=on rough_highlight=on rough_photons=on caustic_radius=1 "
            "caustic_gather_cap=64 caustic_refresh=1 caustic_temporal=on "
            "specular_temporal=on specular_refresh=1 "
            "pose_jitter=0 "
            "fuzzy=on fuzzy_cone=20 fuzzy_taps=12 rough_method=lean gsr_subdivisions=4 "
            "lean_mip_levels=8 translucent_shadows=on vnm_resolution=16 vnm_kernel=extinction "
            "vnm_surface=occupancy vnm_albedo=hapke vnm_lookup=smooth moving_objects=off "
            "env_source=static env_resolution=512 env_lights=0 exposure_match=off "
            "motion_blur=off aa=off noise_match=off vignette_match=off camera_response=session "
            "shadow_focus=on shadow_footprint=on "
            "vpl_rotate=off ism_tile=64 ism_points=1024 ism_pullpush=off vnm_see_through=on "
            "vnm_reflection=on rough_transmission=on second_exit=on rough_footprint=differentials "
            "view=off");
    const BenchResult good = runBenchConfig(benchScene(true), camera, frames, grid[0]);
    std::cout << "[ bench ] real-time: " << good.error << ", " << good.medianGpuMs
              << " GPU ms/frame\n";
    RecordProperty("psnr_frame_db", std::to_string(good.error.psnrFrame));
    RecordProperty("psnr_influenced_db", std::to_string(good.error.psnrInfluenced));
    EXPECT_GE(good.error.psnrFrame, kMinPsnrFrame);
    EXPECT_GE(good.error.ssimFrame, kMinSsimFrame);
    EXPECT_GE(good.error.psnrInfluenced, kMinPsnrInfluenced);
    EXPECT_GE(good.error.ssimInfluenced, kMinSsimInfluenced);
    EXPECT_EQ(good.frames.size(), 3u);
    EXPECT_GT(good.medianGpuMs, 0.0);
    EXPECT_TRUE(good.medianPassMs.count("composite"));
    EXPECT_TRUE(good.medianPassMs.count("indirect"));  // a virtual object: VPLs run

    // Broken (1): the footage as the composite (what the bench's baseline row reports).
    const BenchResult footage = footageBaseline(frames);
    std::cout << "[ bench ] footage only: " << footage.error << "\n";
    EXPECT_FALSE(passesFloors(footage.error));
    EXPECT_LT(footage.error.psnrInfluenced, kMinPsnrInfluenced);
    // Broken (2): the real-time renderer without the virtual object (its contribution removed).
    const BenchResult removed = runBenchConfig(benchScene(false), camera, frames, grid[0]);
    std::cout << "[ bench ] virtual object removed: " << removed.error << "\n";
    EXPECT_FALSE(passesFloors(removed.error));
    EXPECT_LT(removed.error.psnrInfluenced, kMinPsnrInfluenced);
    // Broken (3): the renderer told to hide the virtual objects (knob virtual=off) scores as the
    // footage: the sanity point the results page flags.
    const BenchResult hidden =
        runBenchConfig(benchScene(true), camera, frames,
                       benchGrid(camera, true, {{"vpls", {"256"}}, {"virtual", {"off"}}})[0]);
    std::cout << "[ bench ] virtual=off: " << hidden.error << "\n";
    EXPECT_NEAR(hidden.error.psnrInfluenced, footage.error.psnrInfluenced, 0.05);
    EXPECT_NEAR(hidden.error.psnrFrame, footage.error.psnrFrame, 0.05);

    // Objects moving before every frame (knob moving_objects=on: away and back): every frame
    // redoes the camera-independent passes, which the static run reuses.
    const BenchResult moving =
        runBenchConfig(benchScene(true), camera, frames,
                       benchGrid(camera, true, {{"vpls", {"256"}}, {"moving_objects", {"on"}}})[0]);
    std::cout << "[ bench ] moving_objects=on: " << moving.error << "\n";
    for (size_t k = 0; k < frames.size(); ++k) {
        EXPECT_TRUE(moving.frames[k].passMs.count("shadow")) << "frame " << k;
        EXPECT_FALSE(good.frames[k].passMs.count("shadow")) << "frame " << k;
    }
    // It meets the same floors; what it loses is the temporal history, dropped in every frame
    // in which objects moved (measured 0.59 dB over the influenced pixels).
    EXPECT_TRUE(passesFloors(moving.error));
    EXPECT_NEAR(moving.error.psnrInfluenced, good.error.psnrInfluenced, 1.0);
    EXPECT_THROW(benchGrid(camera, true, {{"moving_objects", {"sometimes"}}}), Error);

    // Downsampled judging (the resolution knob): the ground truth is box-filtered, so the same
    // renderer still scores about as well at half size (23.1 dB measured; footage alone ~13 dB).
    const std::vector<BenchConfig> half =
        benchGrid(camera, true, {{"vpls", {"256"}}, {"resolution", {"80x60"}}});
    const BenchResult small = runBenchConfig(benchScene(true), camera, frames, half[0]);
    std::cout << "[ bench ] 80x60: " << small.error << "\n";
    EXPECT_EQ(small.config.width, 80);
    EXPECT_GE(small.error.psnrInfluenced, kMinPsnrInfluenced - 1.5);
}

// Hard cases through the whole ground-truth pipeline: a black real table (L_r = 0 where
// the light falls), a very bright real light (10^5 W/sr: the footage saturates) and a virtual box
// the camera sits inside of for the first frame (it crosses the near plane). Nothing may be NaN or
// Inf: the reference's samples, the real-time buffers, the composites, the error figures.
TEST(RealtimeBench, HardCasesStayFiniteThroughGroundTruthAndBench) {
    Scene scene;
    const int black = test::addMaterial(scene, glm::vec3(0.0f));
    const int grey = test::addMaterial(scene, glm::vec3(0.5f));
    test::addFloor(scene, "black table", 0.0f, 4.0f, black, Origin::Real);
    test::addFloor(scene, "grey tile", 0.001f, 0.6f, grey, Origin::Real, 0.8f, 0.0f);
    test::addBox(scene, "virtual box", {-0.15f, 0.0f, -0.15f}, {0.15f, 0.3f, 0.15f}, grey,
                 Origin::Virtual);
    // A large virtual shell around the first camera position (orbit start: azimuth -30 deg,
    // radius 2.5, height 2.5): the camera is inside it, so its walls cross the near plane.
    test::addBox(scene, "virtual shell", {-1.35f, 2.4f, 2.07f}, {-1.15f, 2.6f, 2.27f}, grey,
                 Origin::Virtual);
    test::addLight(scene, Light::Type::Spot, {0.0f, 2.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, 1e5f,
                   Origin::Real, 1.0f, 0.9f);

    const fs::path dir = mirage::test::outputDir("bench_hard") / "session";
    raytrace::SyntheticSessionOptions o = tinySessionOptions();
    o.seconds = 2.0 / 6.0;  // 2 frames
    o.samplesPerPixel = 4;
    raytrace::writeSyntheticSession(scene, dir, o);
    const auto [camera, frames] = loadBenchSession(dir);
    ASSERT_EQ(frames.size(), 2u);
    const cv::Mat& first = frames[0].influence;
    EXPECT_GT(cv::countNonZero(first == kInfluenceVirtual), first.total() / 2)
        << "the camera should start inside the virtual shell";

    gl::Context context = gl::Context::headless();
    const std::vector<BenchConfig> grid = benchGrid(camera, true, {{"vpls", {"64"}}});
    const BenchResult r = runBenchConfig(scene, camera, frames, grid[0]);
    std::cout << "[ bench ] hard cases: " << r.error << "\n";
    for (double v : {r.error.psnrFrame, r.error.ssimFrame, r.error.psnrInfluenced,
                     r.error.ssimInfluenced, r.medianGpuMs})
        EXPECT_FALSE(std::isnan(v));
    EXPECT_GT(r.error.psnrFrame, 10.0);

    // The linear buffers of the real-time renderer on the same frames.
    Renderer renderer(scene, camera);
    for (const auto& f : frames) {
        renderer.render({f.T_world_camera, f.footage, true});
        for (const cv::Mat& m :
             {renderer.compositeLinear(), renderer.readBuffer(kLRv), renderer.readBuffer(kLR)})
            EXPECT_TRUE(cv::checkRange(m, true, nullptr, -1e30, 1e30));
    }
}

TEST(RealtimeBench, GridIsTheProductOfTheKnobsAndRejectsBadValues) {
    CameraIntrinsics cam = test::smallCamera(1024, 768);
    const auto full = benchGrid(cam, false, {});
    EXPECT_EQ(full.size(), 3u * 3u * 3u);  // 1024x768, 640x480, 320x240 x 64/256/1024 x auto/2/1
    for (const auto& c : full) EXPECT_TRUE(c.options.graph.syncPasses);
    const auto quick = benchGrid(cam, true, {});
    ASSERT_EQ(quick.size(), 2u);
    EXPECT_EQ(quick[0].width, 640);
    EXPECT_THROW(benchGrid(cam, true, {{"nonsense", {"1"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"vpls", {"many"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"indirect_scale", {"5"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"sync_passes", {"maybe"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"static_reuse", {"yes"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"resolution", {"2048x1536"}}}), Error);  // upsampling
    EXPECT_THROW(benchGrid(cam, true, {{"resolution", {"640x640"}}}), Error);    // aspect
    EXPECT_THROW(benchGrid(cam, true, {{"caustic_map", {"100"}}}), Error);  // not a multiple of 8
    EXPECT_THROW(benchGrid(cam, true, {{"caustic_quad", {"wide"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"caustic_quad", {"9"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"caustic_gather", {"maybe"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"caustic_radius", {"0"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"fuzzy_cone", {"0"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"fuzzy_cone", {"wide"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"fuzzy_taps", {"0"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"caustics", {"sometimes"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"vnm_resolution", {"1"}}}), Error);
    EXPECT_EQ(
        benchGrid(cam, true, {{"vnm_resolution", {"48"}}})[0].options.translucency.vnmResolution,
        48);
    const auto caustic = benchGrid(cam, true, {{"caustic_map", {"128", "512"}}});
    ASSERT_EQ(caustic.size(), 4u);  // x the quick grid's 64 / 256 VPLs
    EXPECT_EQ(caustic[0].options.caustic.mapSize, 128);
    EXPECT_EQ(caustic[1].options.caustic.mapSize, 512);
    EXPECT_THROW(benchGrid(cam, true, {{"virtual", {"hidden"}}}), Error);

    // Every knob reads back the value it applied (the results page's "default" is read this way),
    // and the default configuration is RendererOptions' defaults.
    for (const auto& knob : benchKnobs()) {
        ASSERT_TRUE(knob.value) << knob.name << " has no value reader";
        for (const std::string& v : knob.defaults(cam, false)) {
            BenchConfig c = benchDefaultConfig();
            knob.apply(c, v);
            EXPECT_EQ(knob.value(c), v) << knob.name;
        }
    }
    const auto defaults = benchDefaultKnobs();
    EXPECT_EQ(defaults.at("vpls"), std::to_string(RendererOptions{}.vpl.count));
    EXPECT_EQ(defaults.at("resolution"), "session");
    EXPECT_EQ(defaults.at("virtual"), "on");
    EXPECT_EQ(defaults.at("impostor_steps"),
              std::to_string(RendererOptions{}.impostor.refineSteps));
    EXPECT_EQ(defaults.at("refraction_steps"),
              std::to_string(RendererOptions{}.specular.refractionMarchSteps));
    EXPECT_EQ(defaults.at("specular_vpl_stride"),
              std::to_string(RendererOptions{}.specular.vplStride));
    EXPECT_THROW(benchGrid(cam, true, {{"specular_vpl_stride", {"8"}}}), Error);
    EXPECT_EQ(defaults.at("specular_resolution"),
              RendererOptions{}.specular.halfResolution ? "half" : "full");
    EXPECT_THROW(benchGrid(cam, true, {{"specular_resolution", {"quarter"}}}), Error);
    EXPECT_THROW(benchGrid(cam, true, {{"refraction_steps", {"1"}}}), Error);
}

TEST(RealtimeBench, CommandRunsOnASynthesisedSessionAndRejectsBadInput) {
    const fs::path out = mirage::test::outputDir("bench_cli");
    const std::string scene = (mirage::test::dataDir() / "scenes/tabletop/tabletop.gltf").string();
    auto synth = mirage::test::runMirage(
        {"synth", scene, "-o", (out / "session").string(), "--width", "160", "--height", "120",
         "--fps", "10", "--seconds", "0.2", "--spp", "2", "--threads", "2", "--no-env",
         "--image-sequence", "--ground-truth-composite"});
    ASSERT_EQ(synth.exitCode, 0) << synth.output;
    ASSERT_TRUE(fs::exists(out / "session" / kGroundTruthFile));
    ASSERT_TRUE(fs::exists(out / "session/gt_composite/000001.png"));
    ASSERT_TRUE(fs::exists(out / "session/gt_influence/000001.png"));

    auto bench =
        mirage::test::runMirage({"bench", (out / "session").string(), "-o",
                                 (out / "bench").string(), "--quick", "--knob", "vpls=64"});
    ASSERT_EQ(bench.exitCode, 0) << bench.output;
    std::ifstream csv(out / "bench/bench.csv");
    std::string line;
    int rows = 0;
    while (std::getline(csv, line))
        if (!line.empty() && line[0] != '#') ++rows;
    EXPECT_EQ(rows, 3);  // header, one configuration, one footage baseline
    EXPECT_TRUE(fs::exists(out / "bench/bench.md"));
    EXPECT_TRUE(fs::exists(out / "bench/bench_frames.csv"));

    // Bad input: a clear message and a non-zero exit.
    auto badKnob = mirage::test::runMirage(
        {"bench", (out / "session").string(), "-o", (out / "bench2").string(), "--knob", "warp=9"});
    EXPECT_NE(badKnob.exitCode, 0);
    EXPECT_NE(badKnob.output.find("unknown knob 'warp'"), std::string::npos) << badKnob.output;
    auto noTruth =
        mirage::test::runMirage({"bench", (mirage::test::dataDir() / "sessions/sample").string(),
                                 "-o", (out / "bench3").string()});
    EXPECT_NE(noTruth.exitCode, 0);
    EXPECT_NE(noTruth.output.find("--ground-truth-composite"), std::string::npos) << noTruth.output;
}

}  // namespace
}  // namespace mirage::render
