// `mirage live` without a webcam: the bundled sample session stands in for a camera, paced at a
// frame rate the renderer cannot keep up with on llvmpipe (so frames are dropped, as a camera's
// are), headless. Checked against `mirage replay` of exactly the frames live processed, with
// the poses live tracked: the same per-frame code must give the same images.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/Csv.h"
#include "core/session/PosesCsv.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

fs::path sampleSession() {
    return dataDir() / "sessions" / "sample";
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
    // 6 frames/s: faster than llvmpipe renders this scene at 640x480 (about 2-4 frames/s on
    // the 2-core test machine), so the stand-in drops frames like a camera.
    auto live = runMirage({"live", "--camera", sampleSession().string(), "--scene", diffuseScene(),
                           "--headless", "--camera-fps", "6", "--frames", "4", "-o",
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
        o.fps = 6;
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
    int caught = 0;
    for (size_t k = 0; k < rows.size(); ++k) {
        const Diff d =
            compareFrame(frameFile(dir / "live", int(k)), frameFile(dir / "replay_3mm", int(k)));
        caught += d.psnrDb <= kSameImageDb;
    }
    EXPECT_EQ(caught, int(rows.size()));
}

}  // namespace
}  // namespace mirage::test
