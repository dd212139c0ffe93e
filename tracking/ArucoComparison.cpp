#include "tracking/ArucoComparison.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

#include "core/Error.h"
#include "tracking/BoardImage.h"
#include "tracking/BoardLayout.h"
#include "tracking/SyntheticBoardView.h"
#include "tracking/SyntheticTrials.h"
#include "tracking/Tracker.h"

namespace mirage::tracking {
namespace {

// The benchmark camera: centre off by a few pixels, mild barrel distortion, as a webcam's.
CameraIntrinsics benchCamera(int width) {
    CameraIntrinsics c;
    c.width = width;
    c.height = width == 640 ? 480 : 720;
    c.fx = c.fy = width == 640 ? 600 : 1000;
    c.cx = (c.width - 1) * 0.5 + 3.2;
    c.cy = (c.height - 1) * 0.5 - 2.1;
    c.model = DistortionModel::BrownConrady;
    c.distortion = {-0.12, 0.05, 0.0005, -0.0003, 0.0};
    return c;
}

BoardFrames emptyFrames(int width) {
    if (width != 640 && width != 1280)
        throw Error("tracker comparison: width " + std::to_string(width) + " is not 640 or 1280");
    BoardFrames f;
    f.camera = benchCamera(width);
    f.board = BoardLayout().makeBoard();
    return f;
}

double median(std::vector<double> v) {
    if (v.empty()) return -1;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// Board tags whose 4 corners are inside the image and at least 8 px on a side.
int countVisibleTags(const BoardFrames& f, size_t view) {
    int n = 0;
    const Pose T_camera_world = f.truth[view].inverse();
    for (const auto& t : f.board.tags) {
        bool inside = true;
        std::array<glm::dvec2, 4> px{};
        const auto corners = t.cornersInWorld();
        for (size_t k = 0; k < 4 && inside; ++k) {
            const auto p = f.camera.project(T_camera_world * corners[k]);
            inside = p && p->x > 2 && p->y > 2 && p->x < f.camera.width - 3 &&
                     p->y < f.camera.height - 3;
            if (p) px[k] = *p;
        }
        if (inside && glm::length(px[0] - px[1]) >= 8 && glm::length(px[1] - px[2]) >= 8) ++n;
    }
    return n;
}

// OpenCV's DICT_APRILTAG_36h11 decodes the printed tag mirrored relative to libapriltag's corner
// order (measured on rendered boards): mirage corners 0, 1, 2, 3 are ArUco's 1, 0, 3, 2.
std::array<glm::dvec2, 4> toMirageOrder(const std::vector<cv::Point2f>& c) {
    return {glm::dvec2(c[1].x, c[1].y), glm::dvec2(c[0].x, c[0].y), glm::dvec2(c[3].x, c[3].y),
            glm::dvec2(c[2].x, c[2].y)};
}

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::optional<Pose> okPose(const PoseEstimate& e) {
    return e.state == TrackingState::Ok ? e.pose : std::nullopt;
}

// OpenCV held to one thread while in scope (libapriltag runs with one): CPU time compares like
// with like.
struct OneOpenCvThread {
    int before = cv::getNumThreads();
    OneOpenCvThread() { cv::setNumThreads(1); }
    ~OneOpenCvThread() { cv::setNumThreads(before); }
    OneOpenCvThread(const OneOpenCvThread&) = delete;
    OneOpenCvThread& operator=(const OneOpenCvThread&) = delete;
};

// The hard views' ranges (hardBoardViews).
constexpr double kHardViewMinDistanceM = 0.6, kHardViewMaxDistanceM = 1.1;
constexpr double kHardViewMinTiltDeg = 45, kHardViewMaxTiltDeg = 70;
constexpr double kHardViewMaxBlurPx = 2.5;
constexpr int kHardViewMinJpegQuality = 60;

}  // namespace

BoardFrames singleBoardViews(int width) {
    BoardFrames f = emptyFrames(width);
    const BoardRaster texture = renderBoard(f.board, 8000, false);
    int i = 0;
    for (double distance : {0.3, 0.45, 0.6, 0.8})
        for (double elevationDeg : {88.0, 60.0, 40.0, 25.0}) {
            const double el = glm::radians(elevationDeg), az = glm::radians(-35.0 + 23.0 * (i % 4));
            const glm::dvec3 eye = distance * glm::dvec3(std::cos(el) * std::sin(az), std::sin(el),
                                                         std::cos(el) * std::cos(az));
            // The board's far edge (-Z) up in the image.
            const Pose T = cameraLookingAt(eye, {0.01 * (i % 3), 0, 0}, {0, 0, -1}, 0.15 * (i % 5));
            f.images.push_back(renderSyntheticBoardView(f.board, texture, f.camera, T));
            f.truth.push_back(T);
            ++i;
        }
    return f;
}

BoardFrames orbitBoardVideo(int width) {
    BoardFrames f = emptyFrames(width);
    const BoardRaster texture = renderBoard(f.board, 8000, false);
    const int n = 60;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * glm::pi<double>() * i / n;
        const double r = 0.45 + 0.1 * std::sin(2 * a), h = 0.3 + 0.05 * std::cos(3 * a);
        const glm::dvec3 eye(r * std::sin(a), h, r * std::cos(a));
        const glm::dvec3 target(0.02 * std::sin(3 * a), 0, 0.02 * std::cos(2 * a));
        const Pose T = cameraLookingAt(eye, target, {0, 1, 0}, 0.1 * std::sin(a));
        f.images.push_back(renderSyntheticBoardView(f.board, texture, f.camera, T));
        f.truth.push_back(T);
    }
    return f;
}

BoardFrames hardBoardViews(int width, uint64_t seed, int frames) {
    if (frames < 1) throw Error("hard views: frames must be at least 1");
    BoardFrames f = emptyFrames(width);
    const BoardRaster texture = renderBoard(f.board, 8000, false);
    cv::RNG rng(seed * 2654435761ull + 777);
    const glm::dvec3 centre = boardCentre(f.board);
    for (int i = 0; i < frames; ++i) {
        const double d = rng.uniform(kHardViewMinDistanceM, kHardViewMaxDistanceM);
        const double el =
            glm::radians(rng.uniform(90.0 - kHardViewMaxTiltDeg, 90.0 - kHardViewMinTiltDeg));
        const double az = glm::radians(rng.uniform(-70.0, 70.0));
        const glm::dvec3 eye = centre + d * glm::dvec3(std::cos(el) * std::sin(az), std::sin(el),
                                                       std::cos(el) * std::cos(az));
        const glm::dvec3 target =
            centre + glm::dvec3(rng.uniform(-0.05, 0.05), 0, rng.uniform(-0.04, 0.04));
        const Pose T = cameraLookingAt(eye, target, {0, 1, 0}, rng.uniform(-0.3, 0.3));
        Degradation g;
        g.seed = seed * 1000 + uint64_t(i);
        g.blurPx = rng.uniform(0.0, kHardViewMaxBlurPx);
        g.blurAngleRad = rng.uniform(0.0, M_PI);
        g.jpegQuality = rng.uniform(kHardViewMinJpegQuality, 91);
        g.gain = rng.uniform(0.6, 1.3);
        g.noiseLevels = rng.uniform(0.3, 1.2);
        f.images.push_back(degradeView(renderSyntheticBoardView(f.board, texture, f.camera, T), g));
        f.truth.push_back(T);
    }
    return f;
}

FoundTags foundTags(const std::vector<TagDetection>& detections) {
    FoundTags out;
    for (const auto& t : detections) out.emplace_back(t.id, t.corners);
    return out;
}

void TrackingAccuracy::addFrame(const BoardFrames& f, size_t view, const FoundTags& tags,
                                const std::optional<Pose>& pose) {
    ++frames;
    visibleTags += countVisibleTags(f, view);
    const Pose T_camera_world = f.truth[view].inverse();
    for (const auto& [id, corners] : tags) {
        const BoardTag* t = f.board.find(id);
        if (!t) continue;
        ++foundTags;
        const auto world = t->cornersInWorld();
        for (size_t k = 0; k < 4; ++k)
            if (const auto p = f.camera.project(T_camera_world * world[k]))
                cornerErrPx.push_back(glm::length(*p - corners[k]));
    }
    if (!pose) return;
    const Pose& T = f.truth[view];
    const double rot = glm::degrees(rotationAngleBetween(pose->rotation, T.rotation));
    const double trans =
        glm::length(pose->translation - T.translation) / glm::length(T.translation);
    rotErrDeg.push_back(rot);
    transErrRel.push_back(trans);
    ++poses;
    if (rot > 2.0 || trans > 0.02) ++wrongPoses;
}

double TrackingAccuracy::detectRate() const {
    return visibleTags > 0 ? double(foundTags) / visibleTags : 0.0;
}
double TrackingAccuracy::poseRate() const {
    return frames > 0 ? double(poses) / frames : 0.0;
}
double TrackingAccuracy::medianCornerErrPx() const {
    return median(cornerErrPx);
}
double TrackingAccuracy::medianRotErrDeg() const {
    return median(rotErrDeg);
}
double TrackingAccuracy::medianTransErrPercent() const {
    const double m = median(transErrRel);
    return m < 0 ? m : 100 * m;
}

ArucoBaseline::ArucoBaseline(int cornerRefinement)
    : dictionary_(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11)),
      parameters_(cv::aruco::DetectorParameters::create()) {
    parameters_->cornerRefinementMethod = cornerRefinement;
}

ArucoBaseline::Result ArucoBaseline::process(const BoardFrames& f, const cv::Mat& image) {
    cv::aruco::detectMarkers(image, dictionary_, corners_, ids_, parameters_);
    Result r;
    std::vector<cv::Point3d> object;
    std::vector<cv::Point2d> imagePoints;
    for (size_t i = 0; i < ids_.size(); ++i) {
        const auto c = toMirageOrder(corners_[i]);
        r.tags.emplace_back(ids_[i], c);
        const BoardTag* t = f.board.find(ids_[i]);
        if (!t) continue;
        const auto w = t->cornersInWorld();
        for (size_t k = 0; k < 4; ++k) {
            object.emplace_back(w[k].x, w[k].y, w[k].z);
            imagePoints.emplace_back(c[k].x, c[k].y);
        }
    }
    if (object.size() < 4) return r;
    const CameraIntrinsics& cam = f.camera;
    const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    const cv::Mat distortion(cam.distortion);
    cv::Vec3d rvec, tvec;
    if (!cv::solvePnP(object, imagePoints, K, distortion, rvec, tvec, false,
                      cv::SOLVEPNP_ITERATIVE))
        return r;
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    glm::dmat3 Rg;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) Rg[b][a] = R(a, b);
    // solvePnP gives T_camera_world.
    r.pose = Pose::fromRotationTranslation(Rg, {tvec[0], tvec[1], tvec[2]}).inverse();
    return r;
}

std::vector<TrackerComparisonRow> compareTrackerWithAruco(int width, int repeats) {
    if (repeats < 1) throw Error("tracker comparison: repeats must be at least 1");
    const OneOpenCvThread oneThread;
    std::vector<TrackerComparisonRow> rows;
    auto row = [&](const char* frames, const char* method, const BoardFrames& f) {
        TrackerComparisonRow r;
        r.frames = frames;
        r.method = method;
        r.width = f.camera.width;
        r.height = f.camera.height;
        return r;
    };
    for (const bool video : {true, false}) {
        const BoardFrames f = video ? orbitBoardVideo(width) : singleBoardViews(width);
        const char* kind = video ? "video" : "single";
        // Frame times: 30 fps along the video; 10 s apart for single frames (nothing carries
        // over, every frame is a re-acquisition).
        const double dt = video ? 1.0 / 30.0 : 10.0;
        {
            TrackerComparisonRow r = row(kind, "mirage", f);
            Tracker tracker(f.board, f.camera, TrackerOptions{});
            double t = 0;
            if (video)
                for (const cv::Mat& image : f.images) tracker.process(image, t += dt);
            std::vector<double> ms;
            for (int rep = 0; rep < repeats; ++rep)
                for (size_t v = 0; v < f.images.size(); ++v) {
                    const auto t0 = std::chrono::steady_clock::now();
                    const TrackedFrame tf = tracker.process(f.images[v], t += dt);
                    ms.push_back(msSince(t0));
                    if (rep == 0)
                        r.accuracy.addFrame(f, v, foundTags(tf.detections), okPose(tf.estimate));
                }
            r.medianMs = median(ms);
            rows.push_back(std::move(r));
        }
        {
            TrackerComparisonRow r = row(kind, "ArUco", f);
            ArucoBaseline aruco;
            std::vector<double> ms;
            for (int rep = 0; rep < repeats; ++rep)
                for (size_t v = 0; v < f.images.size(); ++v) {
                    const auto t0 = std::chrono::steady_clock::now();
                    ArucoBaseline::Result a = aruco.process(f, f.images[v]);
                    ms.push_back(msSince(t0));
                    if (rep == 0) r.accuracy.addFrame(f, v, a.tags, a.pose);
                }
            r.medianMs = median(ms);
            rows.push_back(std::move(r));
        }
    }
    return rows;
}

}  // namespace mirage::tracking
