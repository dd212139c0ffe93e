// `mirage live` without a webcam: the bundled sample session stands in for a camera, paced at a
// frame rate the renderer cannot keep up with on llvmpipe (so frames are dropped, as a camera's
// are), headless. Checked against `mirage replay` of exactly the frames live processed, with
// the poses live tracked: the same per-frame code must give the same images.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Csv.h"
#include "core/scene/Scene.h"
#include "core/session/PosesCsv.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"
#include "tracking/PosePredictor.h"

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

fs::path sampleSession() {
    return dataDir() / "sessions" / "sample";
}
// The scene the sample session was synthesised from: its real spot light lights the footage.
std::string sampleScene() {
    return (dataDir() / "scenes" / "tabletop" / "tabletop_backlit.gltf").string();
}
std::string diffuseScene() {
    return (dataDir() / "scenes" / "tabletop" / "tabletop_diffuse.gltf").string();
}

struct LiveRow {
    int frame = 0;
    double t = 0;
    int64_t cameraFrame = 0;
    int dropped = 0;
    std::string state;
};

// The live CSV's rows (columns found by name).
std::vector<LiveRow> readLiveCsv(const fs::path& path) {
    std::ifstream in(path);
    std::string line;
    std::vector<LiveRow> rows;
    if (!std::getline(in, line)) return rows;
    const auto header = splitCsvLine(line);
    auto col = [&](const std::string& n) {
        for (size_t i = 0; i < header.size(); ++i)
            if (header[i] == n) return i;
        ADD_FAILURE() << "no column " << n << " in " << path;
        return size_t(0);
    };
    const size_t cf = col("frame"), ct = col("t"), cc = col("camera_frame"), cd = col("dropped"),
                 cs = col("state");
    while (std::getline(in, line)) {
        const auto f = splitCsvLine(line);
        LiveRow r;
        r.frame = std::stoi(f[cf]);
        r.t = std::stod(f[ct]);
        r.cameraFrame = std::stoll(f[cc]);
        r.dropped = std::stoi(f[cd]);
        r.state = f[cs];
        rows.push_back(r);
    }
    return rows;
}

// The sample's frames at the given camera positions (the stand-in's frame counter is the
// position in the session's frame list).
std::vector<cv::Mat> sampleFrames(const std::vector<LiveRow>& rows) {
    const Session s = readSession(sampleSession());
    auto src = openCameraFrames(s, "main");
    std::vector<cv::Mat> out;
    cv::Mat bgr;
    int64_t pos = 0;
    for (const auto& r : rows) {
        for (; pos <= r.cameraFrame; ++pos) EXPECT_TRUE(src->read(bgr));
        out.push_back(bgr.clone());
    }
    return out;
}

// A copy of a poses file with every pose moved by `dx` metres along world x: what a small
// tracking error would give.
fs::path shiftedPoses(const fs::path& poses, double dx, const fs::path& out) {
    std::map<int, PoseRow> rows = readPosesCsv(poses);
    std::ofstream o(out);
    o << posesCsvHeader();
    for (auto& [frame, r] : rows) {
        if (r.pose) r.pose->translation.x += dx;
        o << posesCsvRow(frame, 0, r);
    }
    return out;
}

// Comparison of two PNG frames: the 99th percentile of the per-pixel absolute difference (8-bit
// levels, max over channels) and the PSNR (dB).
struct Diff {
    double p99 = 0, psnrDb = 0;
};
Diff compareFrame(const fs::path& a, const fs::path& b) {
    const cv::Mat x = cv::imread(a.string()), y = cv::imread(b.string());
    EXPECT_FALSE(x.empty()) << a;
    EXPECT_FALSE(y.empty()) << b;
    if (x.empty() || y.empty() || x.size() != y.size()) return {255, 0};
    const Diff d{percentileAbsDiff(x, y, 0.99), psnr(x, y, 255)};
    std::printf("%s vs %s: 99th percentile %.1f levels, PSNR %.1f dB\n", a.string().c_str(),
                b.string().c_str(), d.p99, d.psnrDb);
    return d;
}
constexpr double kSameImageDb = 50.0;

fs::path frameFile(const fs::path& dir, int k) {
    return dir / cv::format("frame_%06d.png", k);
}

TEST(LiveHeadless, CompositesEqualReplayOfTheSameFramesAndPoses) {
    const fs::path dir = outputDir("live_headless");
    // 15 frames/s: faster than llvmpipe renders this scene at 640x480 (2-4 frames/s on the
    // loaded 2-core test machine, about 7 when it is quiet), so the stand-in drops frames like a
    // camera; its 36 frames last 2.4 s, enough for 4 frames at 0.5 s each.
    auto live = runMirage({"live", "--camera", sampleSession().string(), "--scene", diffuseScene(),
                           "--headless", "--camera-fps", "15", "--frames", "4", "-o",
                           (dir / "live").string()});
    ASSERT_EQ(live.exitCode, 0) << live.output;
    const std::vector<LiveRow> rows = readLiveCsv(dir / "live" / "frames.csv");
    ASSERT_EQ(rows.size(), 4u) << live.output;
    for (size_t k = 0; k < rows.size(); ++k) {
        EXPECT_EQ(rows[k].frame, int(k));
        EXPECT_EQ(rows[k].state, "ok") << "frame " << k;
        if (k > 0) {
            EXPECT_GT(rows[k].cameraFrame, rows[k - 1].cameraFrame);
            EXPECT_GT(rows[k].t, rows[k - 1].t);
            EXPECT_GE(rows[k].dropped, rows[k - 1].dropped);
        }
    }
    // Latest-frame hand-off: every camera frame before a processed one was either processed or
    // counted as dropped (the stand-in's counter has no gaps of its own), and some were dropped.
    for (size_t k = 0; k < rows.size(); ++k)
        EXPECT_EQ(rows[k].dropped, int(rows[k].cameraFrame) - int(k)) << "frame " << k;
    EXPECT_GT(rows.back().dropped, 0);
    EXPECT_NE(live.output.find("dropped"), std::string::npos) << live.output;

    // The processed frames, losslessly (PNG), as a session of their own, with live's times.
    const fs::path same = dir / "same_frames";
    {
        Session meta;
        meta.cameras.push_back({"main", "", "main.yaml", "main"});
        fs::create_directories(same);
        fs::copy_file(sampleSession() / "main.yaml", same / "main.yaml");
        fs::copy_file(sampleSession() / "board.json", same / "board.json");
        SessionWriter::Options o;
        o.imageSequence = true;
        o.fps = 15;
        SessionWriter w(same, meta, o);
        const std::vector<cv::Mat> frames = sampleFrames(rows);
        for (size_t k = 0; k < rows.size(); ++k) w.append({frames[k]}, {rows[k].t}, std::nullopt);
    }
    // The live CSV is a poses file (frame = processed frame number, exact numbers).
    const fs::path poses = dir / "live" / "frames.csv";
    auto replay = runMirage({"replay", same.string(), "--scene", diffuseScene(), "--poses",
                             poses.string(), "-o", (dir / "replay").string()});
    ASSERT_EQ(replay.exitCode, 0) << replay.output;
    // Same frames, poses, times and order (so the same temporal history and VPL seeds) on the
    // same GL: the images must agree to rounding. Tolerance: 99 % of the pixels within 2 of 255
    // levels and PSNR above 45 dB (a one-level difference everywhere is 48 dB): llvmpipe's
    // threads may sum in a different order, nothing else may differ.
    for (size_t k = 0; k < rows.size(); ++k) {
        const Diff d =
            compareFrame(frameFile(dir / "live", int(k)), frameFile(dir / "replay", int(k)));
        EXPECT_LE(d.p99, 2.0) << "frame " << k;
        EXPECT_GT(d.psnrDb, 45.0) << "frame " << k;
    }
    // The tolerance catches a small error: the same replay with every pose 3 mm off.
    const fs::path off = shiftedPoses(poses, 0.003, dir / "poses_3mm.csv");
    auto wrong = runMirage({"replay", same.string(), "--scene", diffuseScene(), "--poses",
                            off.string(), "-o", (dir / "replay_3mm").string()});
    ASSERT_EQ(wrong.exitCode, 0) << wrong.output;
    // Only where the virtual objects show: a frame whose composite is its footage (the box out
    // of view, as in the sample's last frames, which a loaded machine reaches) cannot show a
    // pose error.
    int showing = 0, caught = 0;
    for (size_t k = 0; k < rows.size(); ++k) {
        const fs::path footage = same / "main" / cv::format("%06d.png", int(k));
        if (compareFrame(frameFile(dir / "live", int(k)), footage).psnrDb > kSameImageDb) continue;
        ++showing;
        const Diff d =
            compareFrame(frameFile(dir / "live", int(k)), frameFile(dir / "replay_3mm", int(k)));
        caught += d.psnrDb <= kSameImageDb;
    }
    EXPECT_GE(showing, 2);
    EXPECT_EQ(caught, showing);
}

// The loop both ways: pipelined with prediction (the default) and serial without
// (--no-pipeline --no-predict). Serial, the tracked frame never waits and no pose is predicted;
// pipelined, the frames after the first two (a velocity needs two tracked poses) are rendered
// with the pose predicted ahead of their capture, and the log says which loop ran.
TEST(LiveHeadless, PipelinedPredictsAndSerialDoesNot) {
    const fs::path dir = outputDir("live_pipeline");
    for (const bool serial : {false, true}) {
        const fs::path out = dir / (serial ? "serial" : "pipelined");
        std::vector<std::string> args = {"live",
                                         "--camera",
                                         sampleSession().string(),
                                         "--scene",
                                         diffuseScene(),
                                         "--headless",
                                         "--camera-fps",
                                         "15",
                                         "--frames",
                                         "6",
                                         "-o",
                                         out.string()};
        if (serial) args.insert(args.end(), {"--no-pipeline", "--no-predict"});
        auto live = runMirage(args);
        ASSERT_EQ(live.exitCode, 0) << live.output;
        EXPECT_NE(live.output.find(serial ? "serial" : "pipelined"), std::string::npos)
            << live.output;
        const CsvTable csv = readCsvTable(out / "frames.csv");
        ASSERT_EQ(csv.rows.size(), 6u);
        // A velocity needs two tracked poses at most PosePredictorOptions::maxGapS (0.5 s) of
        // capture time apart: on a loaded machine a slow frame can leave a longer gap, after
        // which the pose is shown as tracked.
        const double maxGapS = tracking::PosePredictorOptions{}.maxGapS;
        int predicted = 0, predictable = 0;
        for (size_t k = 0; k < csv.rows.size(); ++k) {
            const std::string ahead = csv.field(k, "predict_ms");
            if (serial) {
                EXPECT_EQ(ahead, "") << "frame " << k;
                EXPECT_EQ(std::stod(csv.field(k, "handoff_ms")), 0.0);
            } else if (k >= 2 && csv.field(k, "state") == "ok" &&
                       csv.field(k - 1, "state") == "ok" &&
                       std::stod(csv.field(k, "t")) - std::stod(csv.field(k - 1, "t")) <= maxGapS) {
                ++predictable;
                ASSERT_NE(ahead, "") << "frame " << k << " was not predicted";
                EXPECT_GT(std::stod(ahead), 0.0);
                ++predicted;
            }
        }
        if (!serial) {
            EXPECT_GE(predictable, 1) << "no two tracked frames within " << maxGapS << " s";
            EXPECT_EQ(predicted, predictable);
        }
    }
}

// The footage as recorded (main.mkv, JPEG) against the frames the stand-in delivered.
TEST(LiveRecording, ReplayOfTheRecordingReproducesTheLiveComposite) {
    const fs::path dir = outputDir("live_record");
    const std::string scene = sampleScene();
    const fs::path rec = dir / "rec";
    // 2 frames/s: the sample's 36 frames last 18 s, so 3 frames get processed even on a loaded
    // machine (at 6 frames/s the stand-in ended after 2 frames under a load average of 10).
    // Full quality (no frame-time budget): the replay, which has none, must give the same images.
    auto live = runMirage({"live", "--camera", sampleSession().string(), "--scene", scene,
                           "--headless", "--camera-fps", "2", "--frames", "3", "-o",
                           (dir / "live").string(), "--record", rec.string(), "--budget-ms", "0"});
    ASSERT_EQ(live.exitCode, 0) << live.output;
    const std::vector<LiveRow> rows = readLiveCsv(dir / "live" / "frames.csv");
    ASSERT_EQ(rows.size(), 3u);

    // The recording: a session with the calibration, the board, every processed frame (with
    // live's capture time) and the live poses.
    SessionReadReport report;
    const Session s = readSession(rec, &report);
    EXPECT_TRUE(report.ok());
    ASSERT_EQ(s.frames.size(), rows.size());
    for (size_t k = 0; k < rows.size(); ++k) EXPECT_EQ(s.frames[k].timestamps.at(0), rows[k].t);
    EXPECT_TRUE(fs::exists(rec / "board.json"));
    EXPECT_EQ(s.cameras.at(0).calibration, "main.yaml");
    const std::map<int, PoseRow> poses = readPosesCsv(rec / "poses.csv");
    ASSERT_EQ(poses.size(), rows.size());
    for (const auto& [frame, row] : poses) EXPECT_EQ(row.state, rows[size_t(frame)].state);

    auto replay = runMirage({"replay", rec.string(), "--scene", scene, "--poses",
                             (rec / "poses.csv").string(), "-o", (dir / "replay").string()});
    ASSERT_EQ(replay.exitCode, 0) << replay.output;
    const std::vector<cv::Mat> original = sampleFrames(rows), recorded = sessionFrames(rec);
    ASSERT_EQ(recorded.size(), rows.size());
    // The recording stores the footage as JPEG (quality 92), so the replay composites slightly
    // different footage; everything else is the same (frames, order, times, poses). Tolerance:
    // what the footage's difference does not explain stays above 55 dB (measured 72-76 dB; the
    // sample's footage is itself MJPEG, so re-encoding changes it little: 60-64 dB), and the
    // composites differ no more than the footage does, to 1 dB. Every pose 3 mm off: 30-33 dB.
    auto check = [&](const fs::path& replayDir, double& worstUnexplained) {
        worstUnexplained = 1e9;
        bool ok = true;
        for (size_t k = 0; k < rows.size(); ++k) {
            const cv::Mat l = cv::imread(frameFile(dir / "live", int(k)).string());
            const cv::Mat r = cv::imread(frameFile(replayDir, int(k)).string());
            if (l.empty() || r.empty()) return false;
            const double footageDb = psnr(original[k], recorded[k], 255);
            const double compositeDb = psnr(l, r, 255);
            const double unexplained = unexplainedDb(l, r, original[k], recorded[k]);
            std::printf(
                "frame %zu: footage JPEG %.1f dB, composites %.1f dB, unexplained %.1f dB\n", k,
                footageDb, compositeDb, unexplained);
            worstUnexplained = std::min(worstUnexplained, unexplained);
            ok = ok && unexplained > 55.0 && compositeDb > footageDb - 1.0;
        }
        return ok;
    };
    double worst = 0;
    EXPECT_TRUE(check(dir / "replay", worst)) << "worst unexplained " << worst << " dB";
    // The tolerance catches a small error: the replay with every pose 3 mm off.
    const fs::path off = shiftedPoses(rec / "poses.csv", 0.003, dir / "poses_3mm.csv");
    auto wrong = runMirage({"replay", rec.string(), "--scene", scene, "--poses", off.string(), "-o",
                            (dir / "replay_3mm").string()});
    ASSERT_EQ(wrong.exitCode, 0) << wrong.output;
    EXPECT_FALSE(check(dir / "replay_3mm", worst)) << "worst unexplained " << worst << " dB";
}

// kill -9 while recording: every frame with a frames.csv row is readable, every one but at most
// the last has its live pose, and the session replays.
TEST(LiveRecording, KilledLeavesEveryEarlierFrameReadable) {
    const fs::path dir = outputDir("live_record_kill");
    const fs::path rec = dir / "rec";
    const std::string log = (dir / "live.log").string();
    const std::vector<std::string> args = {
        MIRAGE_BINARY, "live",         "--camera",   sampleSession().string(),
        "--scene",     diffuseScene(), "--headless", "--camera-fps",
        "6",           "--record",     rec.string()};
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::vector<char*> argv;
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        FILE* f = std::freopen(log.c_str(), "w", stderr);
        (void)f;
        ::execv(argv[0], argv.data());
        _exit(127);
    }
    ASSERT_GT(pid, 0);
    // Wait for three recorded frames (rows after the header), then kill without warning.
    auto rowsOnDisk = [&] {
        std::ifstream in(rec / "frames.csv");
        std::string line;
        int n = -1;
        while (std::getline(in, line)) ++n;
        return n;
    };
    const auto t0 = std::chrono::steady_clock::now();
    while (rowsOnDisk() < 3 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(90))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the recording ended before it was killed";
    const int rows = rowsOnDisk();
    ASSERT_GE(rows, 3);

    SessionReadReport report;
    const Session s = readSession(rec, &report);
    EXPECT_EQ(report.framesListed, rows);
    EXPECT_EQ(report.framesReadable, rows);
    auto src = openCameraFrames(s, "main");
    cv::Mat bgr;
    int decoded = 0;
    while (src->read(bgr)) {
        EXPECT_FALSE(bgr.empty()) << src->lastProblem();
        EXPECT_EQ(bgr.size(), cv::Size(640, 480));
        ++decoded;
    }
    EXPECT_EQ(decoded, rows);
    const std::map<int, PoseRow> poses = readPosesCsv(rec / "poses.csv");
    EXPECT_GE(int(poses.size()), rows - 1);
    EXPECT_LE(int(poses.size()), rows);
    for (const auto& [frame, row] : poses) {
        EXPECT_LT(frame, rows);
        EXPECT_EQ(row.state, "ok") << "frame " << frame;
    }
    auto replay =
        runMirage({"replay", rec.string(), "--scene", diffuseScene(), "--poses",
                   (rec / "poses.csv").string(), "--frames", "2", "-o", (dir / "replay").string()});
    EXPECT_EQ(replay.exitCode, 0) << replay.output;
}

// The window with its HUD under a virtual X server (xvfb-run, from scripts/install-deps.sh):
// the view shows the footage with the virtual objects, the HUD beside it.
TEST(LiveWindow, ShowsTheCompositeAndTheHudUnderXvfb) {
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
    const fs::path dir = outputDir("live_window");
    const fs::path shot = dir / "window.png";
    const std::string cmd = "xvfb-run -a -s '-screen 0 1280x1024x24' '" +
                            std::string(MIRAGE_BINARY) + "' live --camera '" +
                            sampleSession().string() + "' --scene '" + diffuseScene() +
                            "' --camera-fps 6 --screenshot '" + shot.string() +
                            "' --screenshot-after 3 > '" + (dir / "log.txt").string() + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const cv::Mat png = cv::imread(shot.string());
    ASSERT_FALSE(png.empty());
    // 640x480 view + 330 px HUD, at least 560 rows.
    EXPECT_EQ(png.cols, 640 + 330);
    EXPECT_EQ(png.rows, 560);
    // The view is the sample's footage (a lit table), not an empty window.
    const cv::Mat view = png(cv::Rect(0, 0, 640, 480));
    EXPECT_GT(cv::mean(view)[1], 40.0);
    // The HUD: a dark panel with text (bright pixels of the glyphs).
    const cv::Mat hud = png(cv::Rect(640, 0, 330, 560));
    cv::Mat grey;
    cv::cvtColor(hud, grey, cv::COLOR_BGR2GRAY);
    EXPECT_LT(cv::mean(grey)[0], 60.0);
    EXPECT_GT(cv::countNonZero(grey > 180), 500);
}

// Bad input and missing defaults: a clear message and a non-zero exit, before any work.
TEST(LiveBadInput, SaysWhatIsMissingAndWhatToDo) {
    const fs::path dir = outputDir("live_bad_input");
    const std::string video = (sampleSession() / "main.mkv").string();
    const std::string calib = (sampleSession() / "main.yaml").string();
    const std::string board = (sampleSession() / "board.json").string();
    auto expectError = [](const CommandResult& r, const std::string& text) {
        EXPECT_NE(r.exitCode, 0) << r.output;
        EXPECT_NE(r.output.find(text), std::string::npos) << "expected '" << text << "' in\n"
                                                          << r.output;
    };
    expectError(runMirage({"live", "--headless", "--camera", sampleSession().string()}),
                "--scene SCENE is required");
    expectError(runMirage({"live", "--scene", diffuseScene(), "--headless", "--camera",
                           (dir / "no-such-video.mkv").string()}),
                "no such camera, session or video");
    // A video brings no calibration or board.
    expectError(runMirage({"live", "--scene", diffuseScene(), "--headless", "--camera", video}),
                "pass --calibration CAM.yaml");
    expectError(runMirage({"live", "--scene", diffuseScene(), "--headless", "--camera", video,
                           "--calibration", calib}),
                "pass --board BOARD.json");
    // A calibration for another frame size.
    {
        std::ifstream in(calib);
        std::stringstream text;
        text << in.rdbuf();
        std::string yaml = text.str();
        yaml.replace(yaml.find("image_width: 640"), 16, "image_width: 800");
        yaml.replace(yaml.find("image_height: 480"), 17, "image_height: 600");
        std::ofstream(dir / "other_size.yaml") << yaml;
    }
    expectError(runMirage({"live", "--scene", diffuseScene(), "--headless", "--camera", video,
                           "--calibration", (dir / "other_size.yaml").string(), "--board", board,
                           "--frames", "1"}),
                "delivers 640x480 frames but the calibration");
    // Recording never mixes with other files.
    fs::create_directories(dir / "busy");
    std::ofstream(dir / "busy" / "notes.txt") << "mine\n";
    expectError(runMirage({"live", "--scene", diffuseScene(), "--headless", "--camera",
                           sampleSession().string(), "--record", (dir / "busy").string()}),
                "is not an empty folder");
    EXPECT_TRUE(fs::exists(dir / "busy" / "notes.txt"));
    // The defaults: where calibrations are looked for, and what to do without a camera.
    auto list = runMirage({"live", "--list-cameras"});
    EXPECT_EQ(list.exitCode, 0) << list.output;
    EXPECT_NE(list.output.find("calibrations are looked for in"), std::string::npos) << list.output;
    if (!fs::exists("/dev/video0")) {
        expectError(runMirage({"live", "--scene", diffuseScene(), "--headless"}),
                    "no camera found (looked at /dev/video*");
    }
}

// A stand-in played in a loop delivers more frames than it holds.
TEST(LiveHeadless, LoopedStandInGoesOnPastItsEnd) {
    const fs::path dir = outputDir("live_loop");
    auto r = runMirage({"live", "--camera", sampleSession().string(), "--camera-loop",
                        "--camera-fps", "200", "--scene", diffuseScene(), "--headless", "--vpls",
                        "16", "--frames", "3", "-o", (dir / "out").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::vector<LiveRow> rows = readLiveCsv(dir / "out" / "frames.csv");
    ASSERT_EQ(rows.size(), 3u);
    // 36 frames at 200 frames/s last 0.18 s; three renders on llvmpipe take longer, so the
    // camera counter passes the session's end.
    EXPECT_GT(rows.back().cameraFrame, 36) << r.output;
}

// Virtual objects placed elsewhere on the board: live composites them there, and a replay of the
// recording with the same placement file reproduces that; without it, it does not.
TEST(LivePlacement, ReplayAppliesTheSamePlacement) {
    const fs::path dir = outputDir("live_placement");
    const fs::path placement = dir / "moved.placement.json";
    std::ofstream(placement) << R"({"format": "mirage-placement", "version": 1, "move_u_m": 0.06,
                                    "move_v_m": 0.02, "turn_deg": 30, "scale": 1.2})";
    const fs::path none = dir / "none.placement.json";
    std::ofstream(none) << R"({"format": "mirage-placement", "version": 1})";
    const fs::path rec = dir / "rec";
    auto live =
        runMirage({"live", "--camera", sampleSession().string(), "--scene", diffuseScene(),
                   "--headless", "--camera-fps", "6", "--frames", "2", "--placement",
                   placement.string(), "-o", (dir / "live").string(), "--record", rec.string()});
    ASSERT_EQ(live.exitCode, 0) << live.output;
    EXPECT_NE(live.output.find("placement from"), std::string::npos) << live.output;
    const std::vector<LiveRow> rows = readLiveCsv(dir / "live" / "frames.csv");
    ASSERT_EQ(rows.size(), 2u);
    const std::vector<cv::Mat> original = sampleFrames(rows), recorded = sessionFrames(rec);
    auto worstUnexplained = [&](const std::string& placementFile, const std::string& name) {
        auto r = runMirage({"replay", rec.string(), "--scene", diffuseScene(), "--poses",
                            (rec / "poses.csv").string(), "--placement", placementFile, "-o",
                            (dir / name).string()});
        EXPECT_EQ(r.exitCode, 0) << r.output;
        double worst = 1e9;
        for (size_t k = 0; k < rows.size(); ++k) {
            const cv::Mat l = cv::imread(frameFile(dir / "live", int(k)).string());
            const cv::Mat p = cv::imread(frameFile(dir / name, int(k)).string());
            if (l.empty() || p.empty()) return 0.0;
            worst = std::min(worst, unexplainedDb(l, p, original[k], recorded[k]));
        }
        std::printf("replay with %s: worst unexplained difference %.1f dB\n", placementFile.c_str(),
                    worst);
        return worst;
    };
    // The tolerance of LiveRecording (55 dB): the same placement passes, none fails.
    EXPECT_GT(worstUnexplained(placement.string(), "replay_placed"), 55.0);
    EXPECT_LT(worstUnexplained(none.string(), "replay_unplaced"), 55.0);
}

// --off switches effects off by their bench knob names, in live and in replay alike: their passes
// leave the frame graph (0 ms in the timing CSV) and the composite changes. An unknown name is
// refused before any work, with the names known.
TEST(LiveHeadless, EffectsSwitchedOffLeaveTheFrameGraph) {
    const fs::path dir = outputDir("live_effects_off");
    const std::string scene = sampleScene();
    auto live = runMirage({"live", "--camera", sampleSession().string(), "--scene", scene,
                           "--headless", "--camera-fps", "2", "--frames", "1", "--off",
                           "caustics,glass_shadows", "-o", (dir / "live_off").string()});
    ASSERT_EQ(live.exitCode, 0) << live.output;
    auto replay = [&](const std::string& name, const std::vector<std::string>& extra) {
        std::vector<std::string> args = {
            "replay", sampleSession().string(), "--scene", scene, "--frames", "1",
            "-o",     (dir / name).string()};
        args.insert(args.end(), extra.begin(), extra.end());
        return runMirage(args);
    };
    const CommandResult off = replay("replay_off", {"--off", "caustics", "--off", "glass_shadows"});
    const CommandResult on = replay("replay_on", {});
    ASSERT_EQ(off.exitCode, 0) << off.output;
    ASSERT_EQ(on.exitCode, 0) << on.output;
    const CsvTable liveCsv = readCsvTable(dir / "live_off" / "frames.csv");
    const CsvTable offCsv = readCsvTable(dir / "replay_off" / "frames.csv");
    const CsvTable onCsv = readCsvTable(dir / "replay_on" / "frames.csv");
    for (const char* pass : {"photongbuf_ms", "caustic_ms"}) {
        EXPECT_EQ(std::stod(liveCsv.field(0, pass)), 0.0) << pass;
        EXPECT_EQ(std::stod(offCsv.field(0, pass)), 0.0) << pass;
        EXPECT_GT(std::stod(onCsv.field(0, pass)), 0.0) << pass;
    }
    const cv::Mat replayOff = cv::imread(frameFile(dir / "replay_off", 0).string());
    const cv::Mat replayOn = cv::imread(frameFile(dir / "replay_on", 0).string());
    ASSERT_FALSE(replayOff.empty() || replayOn.empty());
    // The caustic and the glass's tinted shadow change the composite (measured 33.8 dB between
    // the two; a difference of one level everywhere would be 48 dB).
    EXPECT_LT(psnr(replayOn, replayOff, 255), 45.0);

    const fs::path refused = dir / "refused";
    const CommandResult bad = replay("refused", {"--off", "caustic"});
    EXPECT_EQ(bad.exitCode, 1) << bad.output;
    EXPECT_NE(bad.output.find("'caustic' is not an effect; the effects are: caustics"),
              std::string::npos)
        << bad.output;
    EXPECT_FALSE(fs::exists(refused));
}

}  // namespace
}  // namespace mirage::test

namespace mirage::test {
namespace {

// `mirage ARGS...` started in the background with its log in `log`; its process id.
pid_t startMirage(const std::vector<std::string>& args, const fs::path& log) {
    std::vector<std::string> all = {MIRAGE_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::vector<char*> argv;
        for (const auto& a : all) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        FILE* f = std::freopen(log.c_str(), "w", stderr);
        (void)f;
        ::dup2(STDERR_FILENO, STDOUT_FILENO);  // the log lines (stdout) in the same file
        ::execv(argv[0], argv.data());
        _exit(127);
    }
    return pid;
}

// Whether a Matroska file was closed: its Segment's size is written (not the "unknown" size a
// writer leaves until it closes) and covers the rest of the file, and its Duration is set.
::testing::AssertionResult matroskaClosed(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t seg = b.find(std::string("\x18\x53\x80\x67", 4));
    if (seg == std::string::npos || seg + 12 > b.size())
        return ::testing::AssertionFailure() << path << ": no Segment (" << b.size() << " bytes)";
    if (uint8_t(b[seg + 4]) != 0x01)
        return ::testing::AssertionFailure() << path << ": Segment size not in 8-byte form";
    uint64_t size = 0;
    for (size_t i = 5; i < 12; ++i) size = size << 8 | uint8_t(b[seg + i]);
    if (size == 0x00FFFFFFFFFFFFFFull)
        return ::testing::AssertionFailure() << path << ": Segment size unknown (never closed)";
    if (size != b.size() - (seg + 12))
        return ::testing::AssertionFailure() << path << ": Segment size " << size << " but "
                                             << b.size() - (seg + 12) << " bytes follow";
    if (b.find(std::string("\x44\x89\x88", 3)) == std::string::npos)
        return ::testing::AssertionFailure() << path << ": no Duration";
    return ::testing::AssertionSuccess();
}

// Interrupted at any moment, `live --record` leaves no recording or a complete one: its video
// closed (Segment size and Duration written), a frames.csv and poses.csv row per frame, every
// frame decodable, replayable. Stopped before its first frame, the recording would be a session
// without footage: nothing is left. SIGINT always ends with exit 130, also during start-up.
TEST(LiveRecording, InterruptedLeavesNoRecordingOrAPlayableOne) {
    const fs::path dir = outputDir("live_record_interrupted");
    const std::vector<std::string> live = {
        "live",         "--camera",   sampleSession().string(), "--scene",
        diffuseScene(), "--headless", "--camera-fps",           "6"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = live;
        a.insert(a.end(), extra.begin(), extra.end());
        return a;
    };
    // No frame processed: no recording.
    const fs::path none = dir / "none";
    const CommandResult r0 = runMirage(with({"--frames", "0", "--record", none.string()}));
    EXPECT_EQ(r0.exitCode, 0) << r0.output;
    EXPECT_FALSE(fs::exists(none)) << "a recording without a frame was left:\n" << r0.output;

    auto rowsOnDisk = [](const fs::path& rec) {
        std::ifstream in(rec / "frames.csv");
        std::string line;
        int n = -1;
        while (std::getline(in, line)) ++n;
        return n;
    };
    auto logText = [](const fs::path& log) {
        std::ifstream in(log);
        return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    };
    // SIGINT during start-up (once the calibration is read: scene loading and shader
    // compilation follow), when the loop is about to start, and after three recorded frames.
    const std::vector<std::pair<std::string, std::string>> moments = {
        {"startup", "live: calibration"}, {"loop", "tracking on"}, {"frames", ""}};
    for (const auto& [name, logLine] : moments) {
        const bool afterFrames = logLine.empty();
        const fs::path rec = dir / ("rec-" + name);
        const fs::path log = dir / ("live-" + name + ".log");
        const pid_t pid = startMirage(with({"--record", rec.string()}), log);
        ASSERT_GT(pid, 0);
        const auto t0 = std::chrono::steady_clock::now();
        while (
            (afterFrames ? rowsOnDisk(rec) < 3 : logText(log).find(logLine) == std::string::npos) &&
            std::chrono::steady_clock::now() - t0 < std::chrono::seconds(90))
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ::kill(pid, SIGINT);
        int status = 0;
        ::waitpid(pid, &status, 0);
        const std::string output = logText(log);
        ASSERT_TRUE(WIFEXITED(status)) << "SIGINT at " << name << " killed it:\n" << output;
        EXPECT_EQ(WEXITSTATUS(status), 130) << output;
        if (afterFrames) {
            ASSERT_TRUE(fs::exists(rec)) << output;
        }
        if (!fs::exists(rec)) continue;
        // A recording was left: it is complete.
        EXPECT_TRUE(matroskaClosed(rec / "main.mkv")) << output;
        SessionReadReport report;
        const Session s = readSession(rec, &report);
        const int rows = rowsOnDisk(rec);
        EXPECT_GE(rows, 1);
        EXPECT_EQ(report.framesListed, rows);
        EXPECT_EQ(report.framesReadable, rows);
        EXPECT_EQ(int(readPosesCsv(rec / "poses.csv").size()), rows);
        auto src = openCameraFrames(s, "main");
        cv::Mat bgr;
        int decoded = 0;
        while (src->read(bgr)) decoded += bgr.empty() ? 0 : 1;
        EXPECT_EQ(decoded, rows);
        if (afterFrames) {
            const CommandResult replay = runMirage(
                {"replay", rec.string(), "--scene", diffuseScene(), "--poses",
                 (rec / "poses.csv").string(), "--frames", "2", "-o", (dir / "replay").string()});
            EXPECT_EQ(replay.exitCode, 0) << replay.output;
        }
    }
}

// --scan: the room first (the virtual objects hidden, every frame the loop takes tracked and
// recorded), the real proxies and the spot rebuilt from it, then live with the rebuilt scene.
TEST(LiveScan, RebuildsTheRoomThenGoesOnLiveWithIt) {
    const fs::path dir = outputDir("live_scan");
    const fs::path out = dir / "live";
    auto r = runMirage({"live", "--camera", sampleSession().string(), "--env-camera",
                        sampleSession().string(), "--camera-loop", "--camera-fps", "30", "--scene",
                        sampleScene(), "--headless", "--frames", "4", "--scan", "3", "-o",
                        out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const fs::path scan = dir / "live.scan";
    // The scan is a session of its own, with the rebuilt scene and its report beside it.
    SessionReadReport report;
    const Session s = readSession(scan, &report);
    EXPECT_TRUE(report.ok());
    EXPECT_GE(s.frames.size(), 8u);
    const Scene rebuilt = loadScene(scan / "scene.gltf");
    bool table = false, sphere = false;
    for (const Node& n : rebuilt.nodes) {
        table |= n.name == "real_table" && n.origin == Origin::Real;
        sphere |= n.name == "glass_sphere" && n.origin == Origin::Virtual;
    }
    EXPECT_TRUE(table);
    EXPECT_TRUE(sphere);
    int realSpots = 0;
    for (const LightInstance& li : rebuilt.lightInstances())
        realSpots +=
            li.origin == Origin::Real && rebuilt.lights[size_t(li.light)].type == Light::Type::Spot;
    EXPECT_EQ(realSpots, 1);  // the sample's backlit spot, none of the hand-made scene's lights
    EXPECT_TRUE(fs::exists(scan / "scene.report.json"));
    // Then live, with the rebuilt scene: its frames and CSV.
    EXPECT_EQ(readLiveCsv(out / "frames.csv").size(), 4u);
    EXPECT_NE(r.output.find("going on live with the rebuilt scene"), std::string::npos) << r.output;
}

// A scan too short to hold the frames a reconstruction needs (the sample at 30 frames/s gives 4-5
// frames in 0.15 s; 8 are needed): what to record instead, a non-zero
// exit, and the scan kept for the user to look at.
TEST(LiveScan, TooShortAScanSaysWhatToRecordAndKeepsIt) {
    const fs::path dir = outputDir("live_scan_short");
    const fs::path scan = dir / "scan";
    auto r =
        runMirage({"live", "--camera", sampleSession().string(), "--camera-fps", "30", "--scene",
                   sampleScene(), "--headless", "--scan", "0.15", "--scan-dir", scan.string()});
    EXPECT_NE(r.exitCode, 0) << r.output;
    const bool refused = r.output.find("record again") != std::string::npos &&
                         r.output.find("the scan is kept in " + scan.string()) != std::string::npos;
    const bool empty = r.output.find("the scan recorded no frame") != std::string::npos;
    EXPECT_TRUE(refused || empty) << r.output;
    if (refused) {
        EXPECT_TRUE(fs::exists(scan / "session.json"));
    }
}

}  // namespace
}  // namespace mirage::test
