// The sample synthetic session (data/sessions/sample, made by `mirage synth`, data/README.md):
// its ground-truth poses must put the board's tag corners where the rendered tags are.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/camera/CalibrationFile.h"
#include "core/session/Session.h"
#include "render/raytrace/SyntheticFootage.h"
#include "tests/support/TestSupport.h"
#include "tracking/Board.h"
#include "tracking/Detector.h"

namespace mirage {
namespace {

std::filesystem::path sampleDir() {
    return test::dataDir() / "sessions/sample";
}

struct CornerErrors {
    std::vector<double> errors;  // pixels, one per detected corner
    int frames = 0;
};

// Detects tags in every main-camera frame and measures how far each detected corner is from the
// projection of the board's corner by the frame's ground-truth pose (optionally perturbed).
CornerErrors measure(const Pose& perturbation) {
    Session s = readSession(sampleDir());
    CameraCalibration cal = loadCalibration(s.path(s.camera("main")->calibration));
    tracking::Board board = tracking::Board::load(s.path(s.board));
    tracking::DetectorOptions opts;
    opts.decimate = 1.0f;  // small tags: full-resolution quad search
    tracking::Detector detector(opts);
    auto frames = openCameraFrames(s, "main");
    CornerErrors out;
    cv::Mat bgr;
    for (const FrameRecord& rec : s.frames) {
        if (!frames->read(bgr)) break;
        if (!rec.groundTruth) continue;
        Pose T_camera_world = (*rec.groundTruth * perturbation).inverse();
        ++out.frames;
        for (const auto& det : detector.detect(bgr)) {
            const tracking::BoardTag* tag = board.find(det.id);
            if (!tag) continue;
            auto world = tag->cornersInWorld();
            for (int k = 0; k < 4; ++k) {
                auto px = cal.intrinsics.project(T_camera_world * world[size_t(k)]);
                if (!px) continue;
                out.errors.push_back(glm::length(*px - det.corners[size_t(k)]));
            }
        }
    }
    return out;
}

double quantile(std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}

TEST(SynthSession, GroundTruthProjectsTagCornersOntoRenderedTags) {
    ASSERT_TRUE(std::filesystem::exists(sampleDir() / "session.json")) << "sample session missing";
    CornerErrors e = measure(Pose::identity());
    ASSERT_GT(e.frames, 10);
    ASSERT_GT(e.errors.size(), size_t(e.frames) * 40) << "too few tag corners detected";
    double median = quantile(e.errors, 0.5), p95 = quantile(e.errors, 0.95);
    RecordProperty("median_px", std::to_string(median));
    RecordProperty("p95_px", std::to_string(p95));
    EXPECT_LT(median, 0.25);
    EXPECT_LT(p95, 0.5);
    // The check can fail: a 2 mm error in the ground-truth position moves corners by > 0.5 px.
    Pose shifted = Pose::fromRotationTranslation(glm::dmat3(1.0), glm::dvec3(0.002, 0.0, 0.0));
    CornerErrors wrong = measure(shifted);
    EXPECT_GT(quantile(wrong.errors, 0.5), 0.5);
}

TEST(SynthSession, CameraPathIsContinuousAndCoversItsSegments) {
    raytrace::CameraPathOptions o;
    o.duration = 3.0;
    EXPECT_EQ(raytrace::cameraPathSegment(o, 0.1), "orbit");
    EXPECT_EQ(raytrace::cameraPathSegment(o, 2.0), "shake");
    EXPECT_EQ(raytrace::cameraPathSegment(o, 2.9), "pan");
    double maxStep = 0.0;
    for (double t = 0.0; t < 3.0; t += 0.001) {
        Pose a = raytrace::cameraPathPose(o, t), b = raytrace::cameraPathPose(o, t + 0.001);
        maxStep = std::max(maxStep, glm::length(a.translation - b.translation));
        EXPECT_LT(rotationAngleBetween(a.rotation, b.rotation), 0.01);  // < 10 rad/s
    }
    EXPECT_LT(maxStep, 0.002);  // < 2 m/s, no jumps between segments
    // The orbit looks at the target: it projects near the image centre.
    auto k = raytrace::pinholeFromHorizontalFov(640, 480, 60.0);
    auto px = k.project(raytrace::cameraPathPose(o, 0.3).inverse() * o.target);
    ASSERT_TRUE(px.has_value());
    EXPECT_LT(glm::length(*px - glm::dvec2(319.5, 239.5)), 1.0);
}

}  // namespace
}  // namespace mirage
