// `mirage replay` with a session's environment camera (docs/environment.md), end to end on a
// synthetic session of the bundled diffuse tabletop: lit by its env.mkv the composite is as close
// to the ground truth as when lit by the exact environment file; a wrong extrinsic rotation of
// the environment camera is caught; bad environment input is reported and the replay continues
// with the static environment.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

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
fs::path synthesise(const std::string& name, const std::string& seconds, bool groundTruth,
                    const std::vector<std::string>& extra = {}) {
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
                                     "0.7"};
    if (groundTruth) args.push_back("--ground-truth-composite");
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = runMirage(args);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return dir;
}

CommandResult replay(const fs::path& session, const fs::path& out,
                     const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"replay",     session.string(), "--scene", scene(), "-o",
                                     out.string(), "--ground-truth", "--vpls",  "64"};
    args.insert(args.end(), extra.begin(), extra.end());
    return runMirage(args);
}

// PSNR (dB) of the replayed frames against the ground-truth composite over the influenced
// pixels, pooled over the frames.
double influencedPsnr(const fs::path& session, const fs::path& out, int frames) {
    double se = 0;
    long long n = 0;
    for (int f = 0; f < frames; ++f) {
        const cv::Mat got = cv::imread((out / cv::format("frame_%06d.png", f)).string());
        const cv::Mat truth =
            cv::imread((session / "gt_composite" / cv::format("%06d.png", f)).string());
        const cv::Mat infl = cv::imread(
            (session / "gt_influence" / cv::format("%06d.png", f)).string(), cv::IMREAD_GRAYSCALE);
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
    const double psnrCamera = influencedPsnr(s, dir / "camera", 2);
    const double psnrFile = influencedPsnr(s, dir / "file", 2);
    std::printf("[ env replay ] influenced PSNR: env.mkv %.2f dB, exact file %.2f dB\n", psnrCamera,
                psnrFile);
    EXPECT_LE(std::abs(psnrCamera - psnrFile), 1.5);

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
// frame, and the environment pass runs in every frame.
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

}  // namespace
}  // namespace mirage::test
