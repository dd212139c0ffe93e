// The stages of the replay loop (app/replay/ReplaySession.h) built and run alone, and what the
// replay says it wrote against what its video holds.
#include <filesystem>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>

#include "app/replay/ReplayOutputs.h"
#include "app/replay/ReplayPoses.h"
#include "core/camera/CalibrationFile.h"
#include "core/session/FrameSource.h"
#include "core/session/PosesCsv.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

fs::path sample() {
    return dataDir() / "sessions" / "sample";
}
std::string sampleScene() {
    return (dataDir() / "scenes" / "tabletop" / "tabletop_backlit.gltf").string();
}
int framesIn(const fs::path& video) {
    auto src = openFrames(video);
    cv::Mat bgr;
    int n = 0;
    while (src->read(bgr)) n += bgr.empty() ? 0 : 1;
    return n;
}

// Poses: a poses file's ok row is used, an uncertain one is not, a missing one is lost; without
// a file the ground truth (--ground-truth) or tracking (the session's board) decides.
TEST(ReplayPoses, FileRowsGroundTruthOrTracking) {
    const fs::path dir = outputDirForThisTest("replay_poses");
    const Session s = readSession(sample());
    const CameraCalibration cal = loadCalibration(s.path(s.cameras.front().calibration));
    Pose p;
    p.translation = {0.1, 0.2, 0.3};
    {
        std::ofstream f(dir / "poses.csv");
        f << posesCsvHeader() << posesCsvRow(0, 0.0, PoseRow{"ok", "", p})
          << posesCsvRow(1, 0.1, PoseRow{"uncertain", "ambiguous", p});
    }
    const cv::Mat image(8, 8, CV_8UC3, cv::Scalar::all(128));
    const app::ReplayPoses file(s, cal.intrinsics, (dir / "poses.csv").string(), false);
    EXPECT_EQ(file.tracker(), nullptr);
    const auto r0 = file.given(s.frames[0], image), r1 = file.given(s.frames[1], image),
               r2 = file.given(s.frames[2], image);
    ASSERT_TRUE(r0 && r1 && r2);
    ASSERT_TRUE(r0->pose);
    EXPECT_DOUBLE_EQ(r0->pose->translation.z, 0.3);
    EXPECT_EQ(r1->state, "uncertain");
    EXPECT_FALSE(r1->pose);
    EXPECT_EQ(r2->state, "lost");
    EXPECT_EQ(r2->reason, "no row in the poses file");
    EXPECT_FALSE(file.given(s.frames[0], cv::Mat())) << "a lost frame is decided by tracking";

    const app::ReplayPoses truth(s, cal.intrinsics, "", true);
    const auto g = truth.given(s.frames[3], image);
    ASSERT_TRUE(g && g->pose);
    EXPECT_EQ(g->state, "ground_truth");
    EXPECT_EQ(g->pose->translation, s.frames[3].groundTruth->translation);

    const app::ReplayPoses tracked(s, cal.intrinsics, "", false);
    EXPECT_NE(tracked.tracker(), nullptr) << "the sample has a board: it is tracked";
    EXPECT_FALSE(tracked.given(s.frames[0], image));
}

// Outputs: a lost frame has a row and no image; the counts are what the files hold.
TEST(ReplayOutputs, CountsImagesAndRowsApart) {
    const fs::path dir = outputDirForThisTest("replay_outputs");
    const OutputRule rule{{sample()}, false, "test"};
    const cv::Mat image(48, 64, CV_8UC3, cv::Scalar(30, 90, 200));
    app::ReplayOutputs out(dir / "out.mkv", true, dir / "out.csv", rule);
    out.open(12, 90, {"gbuffer"});
    for (int i = 0; i < 5; ++i) {
        app::CompositedFrame cf;
        const bool lost = i % 2 == 1;
        cf.pose = lost ? PoseRow{"lost", "checksum, mismatch", {}} : PoseRow{"ok", "", Pose{}};
        if (!lost) cf.image = image;
        EXPECT_EQ(out.writeImage(i, cf.image, i / 12.0), !lost);
        out.writeRow(i, i / 12.0, cf, {}, "static");
    }
    out.finish();
    EXPECT_EQ(out.rowsWritten(), 5);
    EXPECT_EQ(out.imagesWritten(), 3);
    EXPECT_EQ(framesIn(dir / "out.mkv"), 3);
    const CsvTable csv = readCsvTable(dir / "out.csv");
    ASSERT_EQ(csv.rows.size(), 5u);
    EXPECT_EQ(csv.field(1, "reason"), "checksum; mismatch");
    EXPECT_EQ(csv.field(4, "environment"), "static");
}

// The summary counts what the video holds: a copy of the sample with 12 of its first 14 frames
// damaged (their clusters fail their checksums, so they are lost) replays 14 rows and 2 images,
// and says 2 frames were written.
TEST(ReplaySummary, SaysHowManyFramesTheVideoHolds) {
    const fs::path dir = outputDirForThisTest("replay_summary");
    const fs::path copy = dir / "damaged";
    fs::remove_all(copy);
    fs::copy(sample(), copy);
    {
        std::ifstream in(copy / "main.mkv", std::ios::binary);
        std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        in.close();
        std::vector<size_t> clusters;
        for (size_t at = b.find("\x1F\x43\xB6\x75"); at != std::string::npos;
             at = b.find("\x1F\x43\xB6\x75", at + 4))
            clusters.push_back(at);
        ASSERT_GE(clusters.size(), 14u);
        for (size_t k = 2; k < 14; ++k) b[clusters[k] + 400] ^= 0x5A;  // inside the JPEG
        std::ofstream(copy / "main.mkv", std::ios::binary) << b;
    }
    const fs::path out = dir / "out.mkv";
    fs::remove(out);
    fs::remove(dir / "out.csv");
    const CommandResult r =
        runMirage({"replay", copy.string(), "--scene", sampleScene(), "--ground-truth", "--frames",
                   "14", "--vpls", "32", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const int held = framesIn(out);
    EXPECT_EQ(held, 2);
    EXPECT_EQ(readCsvTable(dir / "out.csv").rows.size(), 14u);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.output, m, std::regex("replay: (\\d+) frames? written to")))
        << r.output;
    EXPECT_EQ(std::stoi(m[1]), held) << r.output;
    EXPECT_NE(r.output.find("12 of the 14 frames replayed were lost"), std::string::npos)
        << r.output;
}

}  // namespace
}  // namespace mirage::test
