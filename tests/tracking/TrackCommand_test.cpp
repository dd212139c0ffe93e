// End to end: a synthetic session (rendered board views with ground truth) through `mirage track`.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/camera/CalibrationFile.h"
#include "core/image/ImageIO.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"
#include "testscenes/TrackingViews.h"
#include "tracking/EnvironmentMap.h"

namespace mirage::tracking {
namespace {

std::filesystem::path makeSession(const std::string& name, int frames, bool mkv = false) {
    const auto dir = test::outputDir("track_" + name) / "session";
    const Board board = BoardLayout().makeBoard();
    const BoardRaster tex = renderBoard(board, 8000, false);
    const auto cam = testing::pinholeCamera();
    Session meta;
    meta.cameras = {{"main", "", "main.yaml", "main"}};
    SessionWriter::Options opt;
    opt.imageSequence = !mkv;  // lossless PNG: the accuracy figures are the tracker's own
    {
        SessionWriter w(dir, meta, opt);
        for (int i = 0; i < frames; ++i) {
            // Orbit at 0.35 m, 50-60 degrees elevation.
            const double a = glm::radians(-40.0 + 80.0 * i / std::max(1, frames - 1));
            const double el = glm::radians(55.0 + 5.0 * std::sin(a));
            const glm::dvec3 eye = 0.35 * glm::dvec3(std::cos(el) * std::sin(a), std::sin(el),
                                                     std::cos(el) * std::cos(a));
            const Pose T = testing::lookAt(eye, {0, 0, 0});
            cv::Mat grey = renderSyntheticBoardView(board, tex, cam, T), bgr;
            cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
            if (name == "noise" && i == frames / 2) cv::randu(bgr, 0, 256);  // a frame of noise
            w.append({bgr}, {i / 30.0}, T);
        }
        w.close();
    }
    CameraCalibration calib;
    calib.intrinsics = cam;
    saveCalibration(dir / "main.yaml", calib);
    board.save(dir / "board.json");
    return dir;
}

std::vector<std::vector<std::string>> readCsv(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::vector<std::vector<std::string>> rows;
    std::string line;
    while (std::getline(in, line)) {
        std::vector<std::string> cols;
        std::string cur;
        bool quoted = false;
        for (char c : line) {
            if (c == '"')
                quoted = !quoted;
            else if (c == ',' && !quoted) {
                cols.push_back(cur);
                cur.clear();
            } else
                cur += c;
        }
        cols.push_back(cur);
        rows.push_back(cols);
    }
    return rows;
}

TEST(TrackCommand, SyntheticSessionMeetsAccuracyWithAFrameOfNoise) {
    const auto dir = makeSession("noise", 12);
    const auto csv = dir.parent_path() / "poses.csv";
    const auto r = test::runMirage({"track", dir.string(), "-o", csv.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const auto rows = readCsv(csv);
    ASSERT_EQ(rows.size(), 13u);
    const std::vector<std::string> head = {"frame", "t",  "state", "reason", "tx",   "ty",    "tz",
                                           "qw",    "qx", "qy",    "qz",     "tags", "rms_px"};
    for (size_t i = 0; i < head.size(); ++i) EXPECT_EQ(rows[0][i], head[i]);
    int ok = 0;
    for (size_t i = 1; i < rows.size(); ++i) {
        if (i - 1 == 6) {
            EXPECT_EQ(rows[i][2], "no_tags") << rows[i][3];
            EXPECT_TRUE(rows[i][4].empty());
        } else {
            EXPECT_EQ(rows[i][2], "ok") << rows[i][3];
            ok += rows[i][2] == "ok";
        }
    }
    EXPECT_EQ(ok, 11);
    // The summary states the ground-truth errors; the accuracy goal holds on these views.
    EXPECT_NE(r.output.find("ground truth"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("wrong-but-ok frames (> 2 deg or > 2 %): 0"), std::string::npos)
        << r.output;
    double rotMax = 0;
    for (size_t i = 1; i < rows.size(); ++i)
        if (rows[i][2] == "ok") rotMax = std::max(rotMax, std::stod(rows[i][25]));
    EXPECT_LT(rotMax, 0.3);
}

// A recording cut short (crash while writing): the frames lost are counted, the rest tracked, and
// the exit status (2) says the input was not read in full.
TEST(TrackCommand, TruncatedVideoCountsLostFramesAndContinues) {
    const auto dir = makeSession("truncated", 8, true);
    const auto video = dir / "main.mkv";
    ASSERT_TRUE(std::filesystem::exists(video));
    const auto size = std::filesystem::file_size(video);
    std::filesystem::resize_file(video, size * 6 / 10);
    const auto csv = dir.parent_path() / "poses.csv";
    const auto r = test::runMirage({"track", dir.string(), "-o", csv.string()});
    ASSERT_EQ(r.exitCode, 2) << r.output;
    const auto rows = readCsv(csv);
    ASSERT_GE(rows.size(), 3u);  // header + some frames
    ASSERT_LT(rows.size(), 9u);  // not all 8 frames survived
    for (size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(rows[i][2], "ok") << rows[i][3];
    const int lost = 8 - int(rows.size() - 1);
    EXPECT_NE(r.output.find("frames: 8 (" + std::to_string(lost) + " unreadable"),
              std::string::npos)
        << r.output;
}

// A session with a fish-eye environment camera rigidly mounted on the main camera: the map built
// from its frames (posed by the tracked main camera and the extrinsic) matches the environment.
TEST(TrackCommand, EnvironmentMapFromTheSessionsFisheye) {
    const auto dir = test::outputDir("track_envmap") / "session";
    const Board board = BoardLayout().makeBoard();
    const BoardRaster tex = renderBoard(board, 8000, false);
    const auto cam = testing::pinholeCamera();
    const auto fish = testing::hemisphereFisheye(240);
    // The fish-eye looks up: camera +Z (forward) = main camera's -Y (up in the image).
    const Pose T_main_env =
        Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, 0, 1, 0, -1, 0), {0.0, -0.02, 0.0});
    Session meta;
    meta.cameras = {{"main", "", "main.yaml", "main"}, {"env", "", "env.yaml", "environment"}};
    SessionWriter::Options opt;
    opt.imageSequence = true;
    std::vector<Pose> truths;
    {
        SessionWriter w(dir, meta, opt);
        for (int i = 0; i < 3; ++i) {
            const Pose T = testing::lookAt(0.35 * glm::dvec3(0.2 * i - 0.2, 0.85, 0.45), {0, 0, 0});
            cv::Mat grey = renderSyntheticBoardView(board, tex, cam, T), bgr;
            cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
            w.append({bgr, testing::renderFisheye(fish, T * T_main_env)}, {i / 30.0, i / 30.0}, T);
        }
        w.close();
    }
    CameraCalibration mainCal, envCal;
    mainCal.intrinsics = cam;
    envCal.intrinsics = fish;
    envCal.T_parent_camera = T_main_env;
    envCal.extrinsicParent = "main";
    saveCalibration(dir / "main.yaml", mainCal);
    saveCalibration(dir / "env.yaml", envCal);
    board.save(dir / "board.json");
    const auto out = dir.parent_path();
    const auto r =
        test::runMirage({"track", dir.string(), "-o", (out / "p.csv").string(), "--envmap",
                         (out / "env.exr").string(), "--envmap-width", "128"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const cv::Mat env = readLinearRgb(out / "env.exr");
    const cv::Mat valid = cv::imread((out / "env_valid.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(env.cols, 128);
    ASSERT_EQ(valid.size(), env.size());
    double err = 0;
    int n = 0;
    for (int y = 0; y < env.rows; ++y)
        for (int x = 0; x < env.cols; ++x) {
            if (!valid.at<uint8_t>(y, x)) continue;
            const glm::dvec3 d = EnvironmentMap::direction(x + 0.5, y + 0.5, env.cols, env.rows);
            const glm::dvec3 want = testing::trueEnvironment(d);
            const cv::Vec3f got = env.at<cv::Vec3f>(y, x);
            for (int k = 0; k < 3; ++k) err += std::abs(got[k] - want[k]);
            n += 3;
        }
    ASSERT_GT(n, 3 * 128 * 64 / 4);  // about the upper hemisphere
    EXPECT_LT(err / n, 0.02);
    // Straight down was never seen.
    EXPECT_EQ(valid.at<uint8_t>(63, 64), 0);
    // The fish-eye (axis tilted about 60 degrees from straight up) sees the zenith (top row)
    // without a stated reach...
    EXPECT_GT(cv::countNonZero(valid.row(0)), 0);
    EXPECT_EQ(r.output.find("not sampled"), std::string::npos) << r.output;

    // ...but not with a calibration whose data reaches only 45 degrees off-axis: directions
    // beyond it are left unseen, and a warning says so once.
    envCal.reachDeg = 45.0;
    saveCalibration(dir / "env.yaml", envCal);
    const auto r45 =
        test::runMirage({"track", dir.string(), "-o", (out / "p45.csv").string(), "--envmap",
                         (out / "env45.exr").string(), "--envmap-width", "128"});
    ASSERT_EQ(r45.exitCode, 0) << r45.output;
    const cv::Mat valid45 = cv::imread((out / "env45_valid.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(valid45.size(), env.size());
    EXPECT_EQ(cv::countNonZero(valid45.row(0)), 0);
    EXPECT_GT(cv::countNonZero(valid45), 0);
    EXPECT_LT(cv::countNonZero(valid45), 0.7 * cv::countNonZero(valid));
    const auto first = r45.output.find("reaches 45.0 deg off-axis");
    ASSERT_NE(first, std::string::npos) << r45.output;
    EXPECT_EQ(r45.output.find("reaches 45.0 deg off-axis", first + 1), std::string::npos)
        << r45.output;
}

TEST(TrackCommand, BadInputNamesTheFile) {
    const auto out = test::outputDir("track_bad");
    auto r = test::runMirage({"track", "--video", (out / "none.mkv").string(), "--calib",
                              (out / "none.yaml").string(), "--board",
                              (test::dataDir() / "boards" / "board_4x6_a4.json").string(), "-o",
                              (out / "p.csv").string()});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.output.find("none"), std::string::npos) << r.output;
    std::ofstream(out / "bad.json") << "{\"family\": \"tag36h11\", \"tags\": [{\"id\": 1}]}";
    const auto dir = makeSession("badboard", 1);
    r = test::runMirage({"track", dir.string(), "--board", (out / "bad.json").string(), "-o",
                         (out / "p.csv").string()});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("tags[0].size"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mirage::tracking
