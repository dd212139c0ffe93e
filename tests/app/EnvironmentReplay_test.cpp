// `mirage replay` with a session's environment camera (docs/environment.md), end to end on a
// synthetic session of the bundled diffuse tabletop: lit by its env.mkv the composite is as close
// to the ground truth as when lit by the exact environment file; a wrong extrinsic rotation of
// the environment camera is caught; bad environment input is reported and the replay continues
// with the static environment.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/Csv.h"
#include "core/camera/Radiometry.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

std::string readFile(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// The diffuse tabletop lit by its environment alone (the spot light's node taken out of the
// scene), so that what the environment camera delivers decides the virtual box's light.
std::string scene() {
    static const std::string path = [] {
        const fs::path src = dataDir() / "scenes" / "tabletop";
        // Per test: ctest runs the tests of this file in parallel processes.
        const fs::path dir =
            outputDir(std::string("env_only_tabletop_") +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        for (const char* f : {"tabletop.bin", "env.pfm", "board.json", "board.png"})
            fs::copy_file(src / f, dir / f, fs::copy_options::overwrite_existing);
        nlohmann::json g = nlohmann::json::parse(readFile(src / "tabletop_diffuse.gltf"));
        nlohmann::json nodes = nlohmann::json::array();
        for (const auto& n : g["scenes"][0]["nodes"])
            if (g["nodes"][n.get<size_t>()]["name"] != "spot") nodes.push_back(n);
        g["scenes"][0]["nodes"] = nodes;
        const fs::path out = dir / "tabletop_env_only.gltf";
        std::ofstream(out) << g.dump();
        return out.string();
    }();
    return path;
}
std::string envFile() {
    return (dataDir() / "scenes" / "tabletop" / "env.pfm").string();
}

// A tiny synthetic session with an environment camera (and the ground-truth composite).
// `orbitHeight`: of the main camera above the table (metres); 0.7 looks down at the table.
fs::path synthesise(const std::string& name, const std::string& seconds, bool groundTruth,
                    const std::vector<std::string>& extra = {},
                    const std::string& orbitHeight = "0.7") {
    const fs::path dir = outputDir(name) / "session";
    std::vector<std::string> args = {"synth",
                                     scene(),
                                     "-o",
                                     dir.string(),
                                     "--width",
                                     "160",
                                     "--height",
                                     "120",
                                     "--fps",
                                     "4",
                                     "--seconds",
                                     seconds,
                                     "--spp",
                                     "8",
                                     "--env-size",
                                     "96",
                                     "--threads",
                                     "2",
                                     "--image-sequence",
                                     "--orbit-radius",
                                     "0.9",
                                     "--orbit-height",
                                     orbitHeight};
    if (groundTruth) args.push_back("--ground-truth-composite");
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = runMirage(args);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return dir;
}

// The sessions keep one exposure: the per-frame exposure estimate (docs/camera-matching.md,
// judged in tests/render/ExposureMatch_test.cpp) is off, so that what is compared is the light
// alone (the estimate takes part of a light error on the table into the gain).
CommandResult replay(const fs::path& session, const fs::path& out,
                     const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"replay", session.string(), "--scene",        scene(),
                                     "-o",     out.string(),     "--ground-truth", "--vpls",
                                     "64",     "--off",          "exposure_match"};
    args.insert(args.end(), extra.begin(), extra.end());
    return runMirage(args);
}

// PSNR (dB) of the replayed frames against the ground-truth composite over the influenced
// pixels, pooled over the frames.
// `truthFrames[f]`: the session frame output frame f shows (default: f).
double influencedPsnr(const fs::path& session, const fs::path& out, int frames,
                      const std::vector<int>& truthFrames = {}) {
    double se = 0;
    long long n = 0;
    for (int f = 0; f < frames; ++f) {
        const cv::Mat got = cv::imread((out / cv::format("frame_%06d.png", f)).string());
        const int g = truthFrames.empty() ? f : truthFrames[size_t(f)];
        const cv::Mat truth =
            cv::imread((session / "gt_composite" / cv::format("%06d.png", g)).string());
        const cv::Mat infl = cv::imread(
            (session / "gt_influence" / cv::format("%06d.png", g)).string(), cv::IMREAD_GRAYSCALE);
        EXPECT_FALSE(got.empty() || truth.empty() || infl.empty()) << "frame " << f;
        if (got.empty() || truth.empty() || infl.empty()) return 0;
        for (int y = 0; y < got.rows; ++y)
            for (int x = 0; x < got.cols; ++x) {
                if (!infl.at<uchar>(y, x)) continue;
                for (int c = 0; c < 3; ++c) {
                    const double d = got.at<cv::Vec3b>(y, x)[c] - truth.at<cv::Vec3b>(y, x)[c];
                    se += d * d;
                }
                n += 3;
            }
    }
    EXPECT_GT(n, 300);
    return 10 * std::log10(255.0 * 255.0 / std::max(se / double(std::max(n, 1LL)), 1e-12));
}

// The `environment` column of each row of a replay CSV.
std::vector<std::string> environmentColumn(const fs::path& csv) {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);
    EXPECT_NE(line.find(",environment"), std::string::npos) << line;
    std::vector<std::string> out;
    while (std::getline(in, line))
        if (!line.empty()) out.push_back(line.substr(line.rfind(',') + 1));
    return out;
}

TEST(EnvironmentReplay, EnvironmentCameraIsAsGoodAsTheExactEnvironmentFile) {
    const fs::path s = synthesise("env_replay_accuracy", "0.5", true);  // 2 frames
    const fs::path dir = s.parent_path();
    const CommandResult cam = replay(s, dir / "camera");
    ASSERT_EQ(cam.exitCode, 0) << cam.output;
    EXPECT_NE(cam.output.find("the environment is camera 'env'"), std::string::npos) << cam.output;
    for (const std::string& e : environmentColumn(dir / "camera" / "frames.csv"))
        EXPECT_EQ(e, "camera");
    const CommandResult file = replay(s, dir / "file", {"--static-env", envFile()});
    ASSERT_EQ(file.exitCode, 0) << file.output;
    for (const std::string& e : environmentColumn(dir / "file" / "frames.csv"))
        EXPECT_EQ(e, "static");
    // The window of the room placed as a shadow-casting light (the ground truth has the box's
    // shadow from it).
    const CommandResult placed = replay(s, dir / "placed", {"--estimate-lights"});
    ASSERT_EQ(placed.exitCode, 0) << placed.output;
    EXPECT_NE(placed.output.find("placed as a shadow-casting light"), std::string::npos)
        << placed.output;
    const double psnrCamera = influencedPsnr(s, dir / "camera", 2);
    const double psnrFile = influencedPsnr(s, dir / "file", 2);
    const double psnrPlaced = influencedPsnr(s, dir / "placed", 2);
    std::printf(
        "[ env replay ] influenced PSNR: env.mkv %.2f dB, exact file %.2f dB, env.mkv with its "
        "light placed %.2f dB\n",
        psnrCamera, psnrFile, psnrPlaced);
    EXPECT_LE(std::abs(psnrCamera - psnrFile), 1.5);
    EXPECT_GT(psnrPlaced, psnrCamera + 0.8);  // fails when nothing is placed

    // Must fail: the environment camera's extrinsic turned 90 degrees about X (it would look at
    // the horizon, not up), so the window lands in the wrong place.
    std::string yaml = readFile(s / "env.yaml");
    const std::regex rot(
        R"(T_parent_camera: !!opencv-matrix\s+rows: 4\s+cols: 4\s+dt: d\s+data: \[[^\]]*\])");
    ASSERT_TRUE(std::regex_search(yaml, rot)) << yaml;
    // Upward camera (x = world x, y = world -z, z = world +y) turned to look along -Z.
    yaml =
        std::regex_replace(yaml, rot,
                           "T_parent_camera: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n"
                           "   data: [ 1., 0., 0., 0., 0., -1., 0., 0.02, 0., 0., -1., -0.4, 0., "
                           "0., 0., 1. ]");
    std::ofstream(s / "env.yaml") << yaml;
    const CommandResult wrong = replay(s, dir / "wrong");
    ASSERT_EQ(wrong.exitCode, 0) << wrong.output;
    const double psnrWrong = influencedPsnr(s, dir / "wrong", 2);
    std::printf("[ env replay ] with the extrinsic turned 90 degrees: %.2f dB\n", psnrWrong);
    EXPECT_GT(std::abs(psnrWrong - psnrFile), 1.5);
}

TEST(EnvironmentReplay, BadEnvironmentInputFallsBackToTheStaticEnvironmentAndSaysSo) {
    const fs::path s = synthesise("env_replay_bad", "0.75", false);  // 3 frames
    const fs::path dir = s.parent_path();
    // The environment video is shorter than the main one: frames 0-1 lit by it, then static.
    fs::remove(s / "env" / "000002.png");
    CommandResult r = replay(s, dir / "short");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("ends at frame 1, before frame 2 of the main camera"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("continues with the scene's static environment"), std::string::npos);
    EXPECT_EQ(environmentColumn(dir / "short" / "frames.csv"),
              (std::vector<std::string>{"camera", "camera", "static"}));

    // A calibration of another size than the environment video.
    std::string yaml = readFile(s / "env.yaml");
    const std::string good = yaml;
    yaml = std::regex_replace(yaml, std::regex(R"(image_width: 96)"), "image_width: 128");
    std::ofstream(s / "env.yaml") << yaml;
    r = replay(s, dir / "mismatch");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("is a calibration for 128x96, but env holds 96x96"), std::string::npos)
        << r.output;
    EXPECT_EQ(environmentColumn(dir / "mismatch" / "frames.csv"),
              (std::vector<std::string>{"static", "static", "static"}));

    // No extrinsic pose.
    yaml = std::regex_replace(good, std::regex(R"(extrinsic_parent: \w+\n)"), "");
    yaml =
        std::regex_replace(yaml, std::regex(R"(T_parent_camera: !!opencv-matrix[^\]]*\]\n?)"), "");
    std::ofstream(s / "env.yaml") << yaml;
    r = replay(s, dir / "noextrinsic");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("has no extrinsic pose"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("continues with the scene's static environment"), std::string::npos);

    // The calibration file is missing.
    fs::remove(s / "env.yaml");
    r = replay(s, dir / "nocalib");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("env.yaml"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("continues with the scene's static environment"), std::string::npos);
    EXPECT_EQ(environmentColumn(dir / "nocalib" / "frames.csv"),
              (std::vector<std::string>{"static", "static", "static"}));
}

// The room light moves (the environment turns 60 degrees per second about +Y, 15 degrees between
// frames at 4 fps): the light found in the environment camera's frames turns with it, frame by
// frame, is placed as a shadow-casting light, and the environment pass runs in every frame (the
// shadow that follows it: tests/render/EnvironmentLightPlacement_test.cpp).
TEST(EnvironmentReplay, RotatingEnvironmentIsFollowedWithinOneFrame) {
    const fs::path s = synthesise("env_replay_rotating", "0.75", false, {"--env-rotation", "60"});
    const fs::path dir = s.parent_path();
    const CommandResult r = replay(s, dir / "out", {"--estimate-lights", "-v"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    // "frame N: environment light 1: direction ... (elevation E deg, azimuth A deg ..."
    const std::regex line(
        R"(frame (\d+): environment light 1: direction \S+ \S+ \S+ \(elevation (\S+) deg, azimuth (\S+) deg)");
    std::vector<double> elevation, azimuth;
    for (auto it = std::sregex_iterator(r.output.begin(), r.output.end(), line);
         it != std::sregex_iterator(); ++it) {
        EXPECT_EQ(std::stoi((*it)[1]), int(azimuth.size()));
        elevation.push_back(std::stod((*it)[2]));
        azimuth.push_back(std::stod((*it)[3]));
    }
    ASSERT_EQ(azimuth.size(), 3u) << r.output;
    // Placed: the scene has no light of its own, so the direct pass lights with the one found,
    // and its shadow map is rendered.
    EXPECT_NE(r.output.find("placed as a shadow-casting light"), std::string::npos) << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(direct\s+ran\s.*1 light\(s\))")))
        << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(shadow\s+ran\s)"))) << r.output;
    for (size_t f = 1; f < azimuth.size(); ++f) {
        double step = azimuth[f] - azimuth[f - 1];
        step = std::remainder(step, 360.0);
        std::printf(
            "[ env rotating ] frame %zu: light azimuth %.1f deg (step %.1f), elevation %.1f\n", f,
            azimuth[f], step, elevation[f]);
        EXPECT_NEAR(std::abs(step), 15.0, 5.0);
        EXPECT_NEAR(elevation[f], elevation[0], 5.0);
    }
    for (const std::string& e : environmentColumn(dir / "out" / "frames.csv"))
        EXPECT_EQ(e, "camera");
}

// The ratio `mirage env-radiometry` prints ("radiometry_to_main: R G B ..."), if it printed one.
std::optional<glm::dvec3> printedRatio(const std::string& output) {
    std::smatch m;
    if (!std::regex_search(output, m,
                           std::regex(R"(radiometry_to_main: (\S+) (\S+) (\S+) \(R, G, B)")))
        return std::nullopt;
    return glm::dvec3(std::stod(m[1]), std::stod(m[2]), std::stod(m[3]));
}

// Both cameras in one radiometry: the environment camera's gain and white balance relative to
// the main camera, estimated from the directions both see (the main camera, 5 cm above the table,
// sees the room above the horizon, as the upward fish-eye does; one frame), against the exact
// ratio synth writes, for several exposures and white balances of the environment camera.
TEST(EnvironmentRadiometry, EstimatedFromDirectionsBothCamerasSee) {
    struct Setting {
        std::string exposure, whiteBalance;
    };
    const std::vector<Setting> settings = {
        {"0.5", "1,1,1"}, {"0.25", "1.2,1.0,0.8"}, {"1.5", "0.7,1.0,1.3"}};
    for (size_t k = 0; k < settings.size(); ++k) {
        const Setting& c = settings[k];
        const fs::path s = synthesise(
            "env_radiometry_" + std::to_string(k), "0.25", false,
            {"--env-exposure", c.exposure, "--env-white-balance", c.whiteBalance}, "0.05");
        const std::optional<glm::dvec3> truth = loadRadiometryToMain(s / "env.yaml");
        ASSERT_TRUE(truth.has_value());
        const CommandResult r = runMirage({"env-radiometry", s.string(), "--scene", scene()});
        ASSERT_EQ(r.exitCode, 0) << r.output;
        const std::optional<glm::dvec3> got = printedRatio(r.output);
        ASSERT_TRUE(got.has_value()) << r.output;
        std::printf(
            "[ env radiometry ] exposure %s, white balance %s: estimated %.4f %.4f %.4f, exact "
            "%.4f %.4f %.4f (ratio %.4f %.4f %.4f)\n",
            c.exposure.c_str(), c.whiteBalance.c_str(), got->r, got->g, got->b, truth->r, truth->g,
            truth->b, got->r / truth->r, got->g / truth->g, got->b / truth->b);
        for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR((*got)[ch] / (*truth)[ch], 1.0, 0.02) << k;
        if (k + 1 == settings.size()) {
            // --write stores it in the environment camera's calibration.
            const CommandResult w =
                runMirage({"env-radiometry", s.string(), "--scene", scene(), "--write"});
            ASSERT_EQ(w.exitCode, 0) << w.output;
            const std::optional<glm::dvec3> stored = loadRadiometryToMain(s / "env.yaml");
            ASSERT_TRUE(stored.has_value());
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR((*stored)[ch], (*got)[ch], 1e-3 * (*got)[ch]);
        }
    }
}

// The main camera looking down at the table (0.7 m above it) never sees what the upward fish-eye
// sees: a message saying what is missing, exit status 1, and no number.
TEST(EnvironmentRadiometry, ViewsThatDoNotOverlapGiveAMessageInsteadOfANumber) {
    const fs::path s = synthesise("env_radiometry_no_overlap", "0.25", false);
    const CommandResult r = runMirage({"env-radiometry", s.string(), "--scene", scene()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("that the environment camera also sees"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("Film part of the room beyond the modelled scene"), std::string::npos)
        << r.output;
    EXPECT_FALSE(printedRatio(r.output).has_value()) << r.output;
    // No environment camera at all.
    const fs::path none = outputDir("env_radiometry_no_env") / "session";
    const CommandResult synth = runMirage(
        {"synth", scene(), "-o", none.string(), "--width", "80", "--height", "60", "--fps", "4",
         "--seconds", "0.25", "--spp", "1", "--threads", "2", "--image-sequence", "--no-env"});
    ASSERT_EQ(synth.exitCode, 0) << synth.output;
    const CommandResult noEnv = runMirage({"env-radiometry", none.string(), "--scene", scene()});
    EXPECT_EQ(noEnv.exitCode, 1) << noEnv.output;
    EXPECT_NE(noEnv.output.find("no camera with role \"environment\""), std::string::npos)
        << noEnv.output;
}

// mirage live with the environment camera: a session stands in for both cameras (paced by its
// frame times); each main frame is lit by the environment frame nearest in time, so with the room
// light turning the composite follows it exactly as replay's does (the same environment frames),
// and differs from the same live run lit by the scene's static map. With --estimate-lights the
// window found in the environment frames is placed: the scene has no light of its own, so the
// shadow pass runs only then.
TEST(LiveEnvironment, EnvironmentCameraLightsEveryFrameNearestInTime) {
    const fs::path dir = outputDir("live_env");
    const fs::path s = dir / "session";
    for (const char* d :
         {"session", "env", "static", "replay", "rec", "rec_replay", "rec_static", "placed"})
        fs::remove_all(dir / d);  // reruns
    // 640x480 (live tracks the board: at 320x240 this scene's tags are too small for an ok pose),
    // 5 frames at 2 fps, the room light turning 120 degrees per second (60 per frame). Live takes
    // 3 of them: a frame slower than the camera's 500 ms drops the next, and the session still
    // has frames left for the third.
    const std::vector<std::string> synthArgs = {"synth",
                                                scene(),
                                                "-o",
                                                s.string(),
                                                "--width",
                                                "640",
                                                "--height",
                                                "480",
                                                "--fps",
                                                "2",
                                                "--seconds",
                                                "2.5",
                                                "--spp",
                                                "2",
                                                "--env-size",
                                                "96",
                                                "--threads",
                                                "2",
                                                "--image-sequence",
                                                "--ground-truth-composite",
                                                "--env-rotation",
                                                "120"};
    const CommandResult synth = runMirage(synthArgs);
    ASSERT_EQ(synth.exitCode, 0) << synth.output;
    auto live = [&](const std::string& name, bool env) {
        // At full quality (no frame-time budget) and with the pose as tracked (no prediction to
        // the display time), serial: each live frame must equal its replay.
        std::vector<std::string> args = {"live",         "--camera",
                                         s.string(),     "--scene",
                                         scene(),        "--headless",
                                         "--frames",     "3",
                                         "--budget-ms",  "0",
                                         "--no-predict", "--no-pipeline",
                                         "-o",           (dir / name).string()};
        if (env)
            args.insert(args.end(),
                        {"--env-camera", s.string(), "--record", (dir / "rec").string()});
        return runMirage(args);
    };
    const CommandResult withEnv = live("env", true), staticEnv = live("static", false);
    ASSERT_EQ(withEnv.exitCode, 0) << withEnv.output;
    ASSERT_EQ(staticEnv.exitCode, 0) << staticEnv.output;
    EXPECT_NE(withEnv.output.find("environment camera session"), std::string::npos)
        << withEnv.output;
    // Every frame is paired with an environment frame taken within half a frame (250 ms) of it.
    // A loaded machine may drop frames: each output frame is judged against the session frame it
    // shows (camera_frame).
    const CsvTable envCsv = readCsvTable(dir / "env" / "frames.csv");
    const CsvTable staticCsv = readCsvTable(dir / "static" / "frames.csv");
    ASSERT_EQ(envCsv.rows.size(), 3u);
    ASSERT_EQ(staticCsv.rows.size(), 3u);
    std::vector<int> envShown, staticShown;
    for (size_t k = 0; k < envCsv.rows.size(); ++k) {
        const std::string age = envCsv.field(k, "env_age_ms");
        ASSERT_FALSE(age.empty()) << "frame " << k << " has no environment frame";
        EXPECT_LT(std::abs(std::stod(age)), 250.0) << "frame " << k;
        EXPECT_GT(std::stod(envCsv.field(k, "environment_ms")), 0.0)
            << "the environment pass did not run in frame " << k;
        envShown.push_back(std::stoi(envCsv.field(k, "camera_frame")));
        staticShown.push_back(std::stoi(staticCsv.field(k, "camera_frame")));
        EXPECT_TRUE(staticCsv.field(k, "env_age_ms").empty());
    }
    const double psnrEnv = influencedPsnr(s, dir / "env", 3, envShown);
    const double psnrStatic = influencedPsnr(s, dir / "static", 3, staticShown);
    // replay of the session (tracked poses, env.mkv) renders the same frames with the same
    // environment frames: live must agree with it, and differ from the static-lit run.
    const CommandResult rep =
        runMirage({"replay", s.string(), "--scene", scene(), "-o", (dir / "replay").string()});
    ASSERT_EQ(rep.exitCode, 0) << rep.output;
    const double psnrReplay = influencedPsnr(s, dir / "replay", 3);
    std::printf(
        "[ live env ] influenced PSNR against the ground truth: live with the environment "
        "camera %.2f dB, live with the static map %.2f dB, replay with env.mkv %.2f dB\n",
        psnrEnv, psnrStatic, psnrReplay);
    int differsFromStatic = 0;
    for (int k = 0; k < 3; ++k) {
        const cv::Mat live = cv::imread((dir / "env" / cv::format("frame_%06d.png", k)).string());
        const cv::Mat still =
            cv::imread((dir / "static" / cv::format("frame_%06d.png", k)).string());
        const cv::Mat replayed = cv::imread(
            (dir / "replay" / cv::format("frame_%06d.png", envShown[size_t(k)])).string());
        ASSERT_FALSE(live.empty() || still.empty() || replayed.empty()) << "frame " << k;
        const double toReplay = cv::PSNR(live, replayed), toStatic = cv::PSNR(live, still);
        std::printf("[ live env ] frame %d: live vs replay %.1f dB, vs static-lit live %.1f dB\n",
                    k, toReplay, toStatic);
        EXPECT_GT(toReplay, 40.0) << "frame " << k;
        differsFromStatic += toStatic < 40.0;
    }
    EXPECT_GT(differsFromStatic, 0) << "the environment camera changed nothing";

    // The live recording holds the environment camera too: per frame the environment frame that
    // lit it, with its time, and a copy of its calibration. Its replay with the live poses
    // composites what live showed, up to the recording's JPEG encoding of both cameras.
    const fs::path rec = dir / "rec";
    SessionReadReport report;
    const Session recorded = readSession(rec, &report);
    EXPECT_TRUE(report.ok());
    ASSERT_EQ(recorded.cameras.size(), 2u);
    EXPECT_EQ(recorded.cameras[1].role, "environment");
    EXPECT_TRUE(fs::exists(rec / "env.yaml"));
    ASSERT_EQ(recorded.frames.size(), 3u);
    auto replayRecording = [&](const std::string& name, bool staticEnv) {
        std::vector<std::string> args = {"replay",  rec.string(),
                                         "--scene", scene(),
                                         "--poses", (rec / "poses.csv").string(),
                                         "-o",      (dir / name).string()};
        if (staticEnv) args.insert(args.end(), {"--static-env", envFile()});
        const CommandResult r = runMirage(args);
        EXPECT_EQ(r.exitCode, 0) << r.output;
        return r;
    };
    const CommandResult recReplay = replayRecording("rec_replay", false);
    EXPECT_NE(recReplay.output.find("the environment is camera"), std::string::npos)
        << recReplay.output;
    replayRecording("rec_static", true);
    const std::vector<cv::Mat> footage = sessionFrames(rec);
    ASSERT_EQ(footage.size(), 3u);
    // What the recording's JPEG encoding of the main footage does not explain (the environment
    // frames' own JPEG encoding is left in). Measured: 50.2-52.7 dB with the recorded environment
    // camera, 34.1-42.4 dB for the same recording lit by the static map; 45 dB between them.
    auto unexplained = [&](const std::string& name, int k) {
        const cv::Mat live = cv::imread((dir / "env" / cv::format("frame_%06d.png", k)).string());
        const cv::Mat replayed =
            cv::imread((dir / name / cv::format("frame_%06d.png", k)).string());
        const cv::Mat original =
            cv::imread((s / "main" / cv::format("%06d.png", envShown[size_t(k)])).string());
        if (live.empty() || replayed.empty() || original.empty()) return 0.0;
        return unexplainedDb(live, replayed, original, footage[size_t(k)]);
    };
    double worstRecorded = 1e9, worstStatic = 1e9;
    for (int k = 0; k < 3; ++k) {
        const double withEnv = unexplained("rec_replay", k), still = unexplained("rec_static", k);
        std::printf(
            "[ live env ] recording frame %d: replay with its environment camera %.1f dB "
            "unexplained, with the static map %.1f dB\n",
            k, withEnv, still);
        worstRecorded = std::min(worstRecorded, withEnv);
        worstStatic = std::min(worstStatic, still);
    }
    EXPECT_GT(worstRecorded, 45.0);
    EXPECT_LT(worstStatic, 45.0) << "the tolerance cannot tell the recorded environment apart";

    const CommandResult placed = runMirage(
        {"live", "--camera", s.string(), "--scene", scene(), "--headless", "--frames", "2", "-o",
         (dir / "placed").string(), "--env-camera", s.string(), "--estimate-lights"});
    ASSERT_EQ(placed.exitCode, 0) << placed.output;
    const CsvTable placedCsv = readCsvTable(dir / "placed" / "frames.csv");
    ASSERT_GE(placedCsv.rows.size(), 1u);
    EXPECT_GT(std::stod(placedCsv.field(0, "shadow_ms")), 0.0) << "no light was placed";
    EXPECT_EQ(std::stod(envCsv.field(0, "shadow_ms")), 0.0);
}

// Lights are found in the environment camera's frames: live without one says so.
TEST(LiveEnvironment, EstimateLightsWithoutAnEnvironmentCameraIsRefused) {
    const fs::path dir = outputDir("live_estimate_lights_no_env");
    const CommandResult r = runMirage(
        {"live", "--camera", (dataDir() / "sessions" / "sample").string(), "--scene", scene(),
         "--headless", "--frames", "1", "--estimate-lights", "-o", (dir / "out").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("name the environment camera with --env-camera"), std::string::npos)
        << r.output;
}

}  // namespace
}  // namespace mirage::test
