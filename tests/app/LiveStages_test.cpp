// The stages of the live loop (app/live/LiveSession.h) and the tracking stage it shares with
// replay (app/PoseStage.h), each built and run alone: no window, no command line.
#include <chrono>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "app/BoardPlane.h"
#include "app/PoseStage.h"
#include "app/live/LiveCapture.h"
#include "app/live/LiveOutputs.h"
#include "app/live/LiveRecorder.h"
#include "app/live/LiveRenderStage.h"
#include "app/live/PlacementEditor.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/scene/Scene.h"
#include "core/session/FrameSource.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

namespace fs = std::filesystem;
using app::PoseStage;

fs::path sample() {
    return dataDir() / "sessions" / "sample";
}
std::string diffuseScene() {
    return (dataDir() / "scenes" / "tabletop" / "tabletop_diffuse.gltf").string();
}
cv::Mat sampleFrame(int index) {
    const Session s = readSession(sample());
    auto src = openCameraFrames(s, "main");
    cv::Mat bgr;
    for (int i = 0; i <= index; ++i) EXPECT_TRUE(src->read(bgr));
    return bgr.clone();
}
Pose poseAt(double x) {
    Pose p;
    p.translation = {x, 0.2, 0.5};
    return p;
}

// Tracking: a short wobble to `uncertain` keeps the last ok pose for kHoldUncertainS, later
// the frame has no pose; a lost frame is lost with its problem as the reason.
TEST(PoseStage, HoldsTheLastOkPoseOnlyForAShortUncertainty) {
    PoseStage stage(nullptr);
    const cv::Mat frame(4, 4, CV_8UC3, cv::Scalar(1, 2, 3));
    const PoseRow ok = stage.decide(frame, 1.0, "", PoseRow{"ok", "", poseAt(0.1)});
    ASSERT_TRUE(ok.pose);
    const PoseRow held = stage.decide(frame, 1.2, "", PoseRow{"uncertain", "ambiguous", poseAt(9)});
    ASSERT_TRUE(held.pose) << held.reason;
    EXPECT_DOUBLE_EQ(held.pose->translation.x, 0.1);
    EXPECT_NE(held.reason.find("held the last ok pose"), std::string::npos) << held.reason;
    const PoseRow late = stage.decide(frame, 1.3, "", PoseRow{"uncertain", "ambiguous", poseAt(9)});
    EXPECT_FALSE(late.pose) << "an uncertain pose 0.3 s after the last ok one was used";
    EXPECT_EQ(late.state, "uncertain");
    const PoseRow lost = stage.decide(cv::Mat(), 1.4, "checksum mismatch", std::nullopt);
    EXPECT_EQ(lost.state, "lost");
    EXPECT_EQ(lost.reason, "checksum mismatch");
    EXPECT_FALSE(lost.pose);
    stage.restart();
    const PoseRow afterRestart =
        stage.decide(frame, 1.45, "", PoseRow{"uncertain", "ambiguous", poseAt(9)});
    EXPECT_FALSE(afterRestart.pose) << "a held pose survived restart()";
}

// Tracking the sample's first frames on its board gives poses near its ground truth.
TEST(PoseStage, TracksTheSampleOnItsBoard) {
    const Session s = readSession(sample());
    const CameraCalibration cal = loadCalibration(s.path(s.cameras.front().calibration));
    tracking::Tracker tracker(tracking::Board::load(s.path(s.board)), cal.intrinsics);
    PoseStage stage(&tracker);
    auto src = openCameraFrames(s, "main");
    cv::Mat bgr;
    int ok = 0;
    for (int i = 0; i < 4 && src->read(bgr); ++i) {
        const FrameRecord& rec = s.frames[size_t(i)];
        const PoseRow r = stage.decide(bgr, rec.timestamps.front(), "", std::nullopt);
        if (!r.pose) continue;
        ++ok;
        ASSERT_TRUE(rec.groundTruth);
        EXPECT_LT(glm::length(r.pose->translation - rec.groundTruth->translation), 0.02)
            << "frame " << i;
    }
    EXPECT_GE(ok, 3);
}

// Capture: a recorded stand-in paced at its rate delivers its frames in order; with an
// environment camera every main frame comes with the environment frame nearest in time.
TEST(LiveCapture, PairsEachMainFrameWithTheNearestEnvironmentFrame) {
    app::CameraInput cam;
    cam.source = openFrames(sample() / "main.mkv");
    cam.pacing.paceFps = 30;
    app::EnvironmentInput env;
    env.source = openFrames(sample() / "main.mkv");
    env.pacing.paceFps = 30;
    env.fps = 30;
    app::LiveCapture capture(cam, &env);
    ASSERT_TRUE(capture.hasEnvironment());
    int frames = 0;
    int64_t lastSequence = -1;
    app::LiveFrame f;
    while (frames < 8 && capture.next(f, 2.0)) {
        ASSERT_FALSE(f.main.bgr.empty());
        EXPECT_GT(f.main.sequence, lastSequence);
        lastSequence = f.main.sequence;
        ASSERT_FALSE(f.envBgr.empty()) << "frame " << frames << " came without an environment";
        // Within half an environment frame (1/60 s) of the main frame, with slack for the
        // scheduling of two threads on a loaded machine.
        EXPECT_LT(std::abs(f.envSeconds - f.main.captureSeconds), 0.5 / 30 + 0.05)
            << "frame " << frames;
        ++frames;
    }
    EXPECT_EQ(frames, 8);
    EXPECT_EQ(capture.stop(), "");
}

// Placement: every change moves the objects at once; the save (and a rebuild, if a move could
// not be made in place) waits until the keys rest and no drag goes on.
TEST(PlacementEditor, SettlesOnceTheKeysRestAndRebuildsOnlyForAMoveNotInPlace) {
    using Clock = app::PlacementEditor::Clock;
    const auto t0 = Clock::now();
    auto at = [&](double s) {
        return t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
    };
    app::PlacementEditor ed{ScenePlacement{}};
    ScenePlacement p;
    EXPECT_FALSE(ed.change(p, true, at(0))) << "no move is no change";
    p.moveU = 0.01;
    EXPECT_TRUE(ed.change(p, true, at(0)));
    EXPECT_TRUE(ed.pending());
    EXPECT_FALSE(ed.settle(at(0.2), false)) << "settled while the keys were still moving";
    EXPECT_FALSE(ed.settle(at(0.5), true)) << "settled during a drag";
    EXPECT_TRUE(ed.settle(at(0.5), false));
    EXPECT_FALSE(ed.rebuildNeeded());
    EXPECT_FALSE(ed.settle(at(0.9), false)) << "settled twice for one change";
    p.turnDeg = 5;
    EXPECT_TRUE(ed.change(p, false, at(1.0)));  // a translucent object: not in place
    p.turnDeg = 10;
    EXPECT_TRUE(ed.change(p, true, at(1.1)));
    EXPECT_TRUE(ed.settle(at(1.5), false));
    EXPECT_TRUE(ed.rebuildNeeded()) << "a move not made in place was forgotten";
    EXPECT_DOUBLE_EQ(ed.placement().turnDeg, 10);
}

app::CompositedFrame fakeComposite(const cv::Mat& image, bool withPose) {
    app::CompositedFrame cf;
    cf.pose = withPose ? PoseRow{"ok", "", poseAt(0.25)} : PoseRow{"lost", "no tag", {}};
    cf.image = image;
    cf.passMs["gbuffer"] = 1.5;
    return cf;
}

// Outputs: each composite into the video and a row per frame into the CSV, both in place after
// finish(); stopped before the first frame, nothing is left.
TEST(LiveOutputs, WritesEveryCompositeAndARowPerFrameOrNothing) {
    const fs::path dir = outputDirForThisTest("live_outputs");
    const OutputRule rule{{sample()}, false, "test"};
    const cv::Mat image = sampleFrame(0);
    {
        app::LiveOutputs out(dir / "out.mkv", rule);
        out.open(30, 90, {"gbuffer", "composite"});
        for (int i = 0; i < 3; ++i) {
            CapturedFrame f;
            f.captureSeconds = 10 + i / 30.0;
            f.sequence = i;
            out.writeImage(i, image, f.captureSeconds);
            out.writeRow(i, f, std::nan(""), fakeComposite(image, i != 1), 5, 20);
        }
        out.finish();
        EXPECT_EQ(out.imagesWritten(), 3);
    }
    const CsvTable csv = readCsvTable(dir / "out.csv");
    ASSERT_EQ(csv.rows.size(), 3u);
    auto src = openFrames(dir / "out.mkv");
    cv::Mat bgr;
    int n = 0;
    while (src->read(bgr)) n += bgr.empty() ? 0 : 1;
    EXPECT_EQ(n, 3);
    {
        app::LiveOutputs out(dir / "empty.mkv", rule);
        out.open(30, 90, {"gbuffer"});
        out.finish();
    }
    EXPECT_FALSE(fs::exists(dir / "empty.mkv"));
    EXPECT_FALSE(fs::exists(dir / "empty.csv"));
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos)
            << "a temporary file was left: " << e.path();
}

// Record: a recording stopped before its first frame is not left; one with frames is a
// complete session that reads back frame for frame, with a pose per frame.
TEST(LiveRecorder, LeavesNothingOrACompleteSession) {
    const fs::path dir = outputDirForThisTest("live_recorder");
    const Session s = readSession(sample());
    LiveRecording::Options o;
    o.fps = 6;
    const fs::path calib = s.path(s.cameras.front().calibration), board = s.path(s.board);
    {
        app::LiveRecorder r(dir / "empty", calib, board, o, diffuseScene());
        r.start();
        EXPECT_TRUE(fs::exists(dir / "empty" / "session.json"));
        r.stop();
        EXPECT_FALSE(fs::exists(dir / "empty")) << "a recording without footage was left";
    }
    const cv::Mat image = sampleFrame(0);
    {
        app::LiveRecorder r(dir / "three", calib, board, o, diffuseScene());
        r.start();
        for (int i = 0; i < 3; ++i)
            r.append(image, 5 + i / 6.0, PoseRow{"ok", "", poseAt(0.1 * i)}, cv::Mat(), 0);
        EXPECT_EQ(r.frames(), 3);
        // Destroyed without stop(), as when the loop leaves by an exception: closed all the same.
    }
    SessionReadReport report;
    const Session rec = readSession(dir / "three", &report);
    EXPECT_EQ(report.framesListed, 3);
    EXPECT_EQ(report.framesReadable, 3);
    EXPECT_EQ(readPosesCsv(dir / "three" / "poses.csv").size(), 3u);
    auto src = openCameraFrames(rec, "main");
    cv::Mat bgr;
    int n = 0;
    while (src->read(bgr)) {
        ASSERT_FALSE(bgr.empty()) << src->lastProblem();
        EXPECT_GT(psnr(bgr, image, 255), 30.0);  // JPEG quality 92
        ++n;
    }
    EXPECT_EQ(n, 3);
}

// Render and composite: with a pose the virtual objects change the frame, hidden they do not;
// a new quality preset builds the renderer anew and it composites the same frame alike.
TEST(LiveRenderStage, CompositesHidesAndRebuilds) {
    const Session s = readSession(sample());
    const CameraCalibration cal = loadCalibration(s.path(s.cameras.front().calibration));
    gl::ContextOptions co;
    co.width = cal.intrinsics.width;
    co.height = cal.intrinsics.height;
    gl::Context ctx = gl::Context::headless(co);
    const Scene scene = loadScene(diffuseScene());
    const PlacementPlane plane = app::boardPlane(tracking::Board::load(s.path(s.board)));
    app::LiveRenderSettings settings;
    settings.vpls = 32;
    app::LiveRenderStage stage(scene, plane, ScenePlacement{}, cal.intrinsics, settings, nullptr);
    EXPECT_EQ(stage.builds(), 1);
    const cv::Mat frame = sampleFrame(0);
    const PoseRow pose{"ground_truth", "", s.frames.front().groundTruth};
    const app::CompositedFrame shown = stage.composite(frame, pose, true);
    ASSERT_TRUE(shown.report);
    ASSERT_EQ(shown.image.size(), frame.size());
    EXPECT_LT(psnr(shown.image, frame, 255), 40.0) << "the virtual objects changed nothing";
    const app::CompositedFrame hidden = stage.composite(frame, pose, false);
    EXPECT_FALSE(hidden.report);
    EXPECT_GT(psnr(hidden.image, frame, 255), 99.0) << "hidden objects changed the footage";
    stage.settings().preset = 0;
    stage.settings().vpls = 32;
    stage.rebuild();
    EXPECT_EQ(stage.builds(), 2);
    const app::CompositedFrame again = stage.composite(frame, pose, true);
    ASSERT_TRUE(again.report);
    EXPECT_GT(psnr(again.image, shown.image, 255), 30.0);
    EXPECT_FALSE(stage.view(1).empty()) << "the HUD's L_rv view";
}

}  // namespace
}  // namespace mirage::test
