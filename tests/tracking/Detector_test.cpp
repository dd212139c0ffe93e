#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>

#include <opencv2/imgcodecs.hpp>

#include "core/Error.h"
#include "tests/support/TestSupport.h"
#include "tracking/BoardLayout.h"
#include "tracking/Detector.h"
#include "tracking/SyntheticBoardView.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {
namespace {

struct Expected {
    int id;
    std::array<glm::dvec2, 4> corners;
};

std::vector<Expected> readExpected(const std::filesystem::path& path) {
    std::ifstream in(path);
    EXPECT_TRUE(in.good()) << path;
    std::vector<Expected> out;
    std::string line;
    const std::regex re(
        R"(^\s*(\d+),\s*\(([-\d.]+) ([-\d.]+)\),\s*\(([-\d.]+) ([-\d.]+)\),\s*\(([-\d.]+) ([-\d.]+)\),\s*\(([-\d.]+) ([-\d.]+)\))");
    while (std::getline(in, line)) {
        std::smatch m;
        if (!std::regex_search(line, m, re)) continue;
        Expected e;
        e.id = std::stoi(m[1]);
        for (int k = 0; k < 4; ++k)
            e.corners[size_t(k)] = {std::stod(m[2 + 2 * k]), std::stod(m[3 + 2 * k])};
        out.push_back(e);
    }
    return out;
}

// libapriltag's own regression data (data/peer/apriltag/README.md): with quad_decimate = 1 and
// refine_edges = 0 every tag must be found and every corner within 0.25 px of the golden file.
// The golden corners use libapriltag's pixel convention (pixel centres at +0.5), mirage reports
// OpenCV's (centres at integers), so 0.5 is added back before comparing.
void checkPeerImage(const std::string& stem) {
    const auto dir = test::dataDir() / "peer" / "apriltag";
    const cv::Mat img = cv::imread((dir / (stem + ".jpg")).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << stem;
    const auto expected = readExpected(dir / (stem + ".txt"));
    ASSERT_FALSE(expected.empty());
    DetectorOptions opt;
    opt.decimate = 1.0f;
    opt.refineEdges = false;
    opt.maxHammingCorrected = 2;  // libapriltag's default, as in its test harness
    opt.minDecisionMargin = 0.0f;
    opt.refineCorners = false;  // the golden corners are libapriltag's own
    Detector det(opt);
    auto found = det.detect(img);
    EXPECT_EQ(found.size(), expected.size()) << stem;
    std::vector<bool> used(found.size(), false);
    double worst = 0;
    for (const auto& e : expected) {
        double best = 1e9;
        size_t bestIdx = 0;
        for (size_t i = 0; i < found.size(); ++i) {
            if (used[i] || found[i].id != e.id) continue;
            double d = 0;
            for (int k = 0; k < 4; ++k)
                d = std::max(d, glm::length(found[i].corners[size_t(k)] + glm::dvec2(0.5) -
                                            e.corners[size_t(k)]));
            if (d < best) {
                best = d;
                bestIdx = i;
            }
        }
        ASSERT_LT(best, 1e9) << stem << ": tag id " << e.id << " not found";
        used[bestIdx] = true;
        EXPECT_LE(best, 0.25) << stem << ": tag at " << e.corners[0].x << "," << e.corners[0].y;
        worst = std::max(worst, best);
    }
    ::testing::Test::RecordProperty("worst_corner_error_px", std::to_string(worst));
}

TEST(DetectorPeerData, Image33369213973) {
    checkPeerImage("33369213973_9d9bb4cc96_c");
}
TEST(DetectorPeerData, Image34085369442) {
    checkPeerImage("34085369442_304b6bafd9_c");
}
TEST(DetectorPeerData, Image34139872896) {
    checkPeerImage("34139872896_defdb2f8d9_c");
}

TEST(Detector, RejectsBadInput) {
    DetectorOptions o;
    o.decimate = 0.5f;
    EXPECT_THROW(Detector{o}, Error);
    Detector d;
    EXPECT_THROW(d.detect(cv::Mat(10, 10, CV_32F)), Error);
    EXPECT_TRUE(d.detect(cv::Mat()).empty());
}

TEST(Detector, NoiseFrameGivesNoTags) {
    cv::Mat noise(480, 640, CV_8UC1);
    cv::randu(noise, 0, 256);
    Detector d;
    EXPECT_TRUE(d.detect(noise).empty());
}

// A rendered board at a known pose: the camera 0.35 m above the board, looking down and slightly
// forward (-Z), tilted by 25 deg and rolled by 0.3 rad so that no edge is aligned with the pixel
// grid.
struct TiltedBoardView {
    Board board = BoardLayout().makeBoard();
    CameraIntrinsics cam;
    Pose T_world_camera;
    cv::Mat image;
    TiltedBoardView() {
        const BoardRaster tex = renderBoard(board, 12000, false);
        cam.width = 640;
        cam.height = 480;
        cam.fx = cam.fy = 600;
        cam.cx = 319.5;
        cam.cy = 239.5;
        const double tilt = glm::radians(25.0);
        const glm::dvec3 eye(0.02, 0.32, 0.15);
        const glm::dvec3 fwd = glm::normalize(glm::dvec3(0, -std::cos(tilt), -std::sin(tilt)));
        const double roll = 0.3;
        const glm::dvec3 right0(1, 0, 0);
        const glm::dvec3 right = std::cos(roll) * right0 + std::sin(roll) * glm::cross(fwd, right0);
        const glm::dvec3 down = glm::cross(fwd, right);
        T_world_camera = Pose::fromRotationTranslation(glm::dmat3(right, down, fwd), eye);
        image = renderSyntheticBoardView(board, tex, cam, T_world_camera);
    }
};

// Every tag found, corners in the documented order and at the projected board corners (OpenCV
// pixel convention) to a small fraction of a pixel.
TEST(Detector, CornersMatchBoardGeometryAndOrder) {
    const TiltedBoardView view;
    const Board& board = view.board;
    const CameraIntrinsics& cam = view.cam;
    const Pose& T_world_camera = view.T_world_camera;
    const cv::Mat& img = view.image;
    cv::imwrite((test::outputDir("detector_synthetic") / "view.png").string(), img);
    for (float decimate : {1.0f, 2.0f}) {
        DetectorOptions opt;
        opt.decimate = decimate;
        Detector det(opt);
        auto found = det.detect(img);
        EXPECT_EQ(found.size(), board.tags.size()) << "decimate " << decimate;
        const Pose T_camera_world = T_world_camera.inverse();
        double worst = 0, sum = 0;
        int n = 0;
        for (const auto& d : found) {
            const BoardTag* tag = board.find(d.id);
            ASSERT_NE(tag, nullptr);
            auto cw = tag->cornersInWorld();
            for (int k = 0; k < 4; ++k) {
                auto p = cam.project(T_camera_world * cw[size_t(k)]);
                ASSERT_TRUE(p.has_value());
                const double e = glm::length(*p - d.corners[size_t(k)]);
                worst = std::max(worst, e);
                sum += e;
                ++n;
            }
        }
        // Sub-pixel: mean < 0.05 px, worst < 0.12 px (libapriltag alone: ~0.2 px mean, 0.35 worst).
        EXPECT_LT(sum / n, 0.05) << "decimate " << decimate;
        EXPECT_LT(worst, 0.12) << "decimate " << decimate;
    }
}

// The coarse search's corners: libapriltag at decimation 4 without its edge refinement (as the
// tracker's coarse search runs it) leaves corners pixels off. mirage's refinement from that
// error (refineQuadCorners: a first pass that may move a corner by the decimation, a second when
// it moved) keeps nearly every tag at the accuracy of the full-resolution search (measured: 22 of
// 23, worst corner 0.09 px); the single pass for corners libapriltag refined (a move of at most
// 1.5 px) drops a quarter of them (17 kept): the must-fail.
TEST(Detector, QuadCornersFromAnUnrefinedDecimatedSearch) {
    const TiltedBoardView view;
    DetectorOptions opt;
    opt.decimate = 4.0f;
    opt.refineEdges = false;
    opt.refineCorners = false;
    Detector det(opt);
    const std::vector<TagDetection> found = det.detect(view.image);
    ASSERT_GE(found.size(), 8u);
    const TagFamily family(opt.family);
    const Pose T_camera_world = view.T_world_camera.inverse();
    auto worstError = [&](const TagDetection& d, const std::array<glm::dvec2, 4>& corners) {
        const auto cw = view.board.find(d.id)->cornersInWorld();
        double worst = 0;
        for (size_t k = 0; k < 4; ++k)
            worst = std::max(worst,
                             glm::length(*view.cam.project(T_camera_world * cw[k]) - corners[k]));
        return worst;
    };
    int keptQuad = 0, keptSinglePass = 0;
    double unrefinedWorst = 0, refinedWorst = 0;
    for (const auto& d : found) {
        unrefinedWorst = std::max(unrefinedWorst, worstError(d, d.corners));
        std::array<glm::dvec2, 4> quad = d.corners, single = d.corners;
        if (Detector::refineQuadCorners(view.image, family.widthAtBorder(), quad, 4.0)) {
            ++keptQuad;
            refinedWorst = std::max(refinedWorst, worstError(d, quad));
        }
        keptSinglePass += Detector::refineCorners(view.image, family.widthAtBorder(), single);
    }
    std::printf(
        "decimate 4, %zu tags: unrefined worst %.2f px; refineQuadCorners kept %d (worst "
        "%.3f px), one pass of at most 1.5 px kept %d\n",
        found.size(), unrefinedWorst, keptQuad, refinedWorst, keptSinglePass);
    EXPECT_GT(unrefinedWorst, 1.0);
    EXPECT_GE(keptQuad, int(0.8 * double(found.size())));
    EXPECT_LT(refinedWorst, 0.12);
    EXPECT_LT(keptSinglePass, keptQuad);

    // The detector itself without libapriltag's refinement refines its tags the same way: as many
    // tags marked refined as refineQuadCorners kept, at the same accuracy.
    DetectorOptions refining = opt;
    refining.refineCorners = true;
    Detector refiningDetector(refining);
    int refined = 0;
    double detectorWorst = 0;
    for (const auto& d : refiningDetector.detect(view.image)) {
        if (!d.refined) continue;
        ++refined;
        detectorWorst = std::max(detectorWorst, worstError(d, d.corners));
    }
    EXPECT_EQ(refined, keptQuad);
    EXPECT_LT(detectorWorst, 0.12);
}

}  // namespace
}  // namespace mirage::tracking
