#include "calibration/Extrinsics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calibration/JointRefinement.h"
#include "core/Error.h"
#include "core/image/StrictJpeg.h"
#include "core/session/FrameSource.h"

namespace mirage::calib {
namespace {
constexpr double kRadToDeg = 57.29577951308232;

struct PairPose {
    Pose T_main_camera;
    size_t index;
};

Pose meanPose(const std::vector<PairPose>& poses) {
    glm::dquat sum(0, 0, 0, 0);
    glm::dvec3 t(0.0);
    const glm::dquat ref = poses.front().T_main_camera.rotation;
    for (const auto& p : poses) {
        glm::dquat q = p.T_main_camera.rotation;
        if (glm::dot(q, ref) < 0) q = -q;  // q and -q are the same rotation
        sum += q;
        t += p.T_main_camera.translation;
    }
    Pose m;
    m.rotation = glm::normalize(sum);
    m.translation = t / double(poses.size());
    return m;
}

double rmsPixels(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const cv::Point2f d = a[i] - b[i];
        s += double(d.x) * d.x + double(d.y) * d.y;
    }
    return std::sqrt(s / double(std::max<size_t>(1, a.size())));
}

void toCv(const Pose& p, cv::Vec3d& rvec, cv::Vec3d& tvec) {
    const glm::dmat3 m = p.rotationMatrix();
    cv::Matx33d R;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R(r, c) = m[c][r];
    cv::Rodrigues(R, rvec);
    tvec = cv::Vec3d(p.translation.x, p.translation.y, p.translation.z);
}

cv::Vec3d vec3At(const std::vector<double>& x, size_t o) {
    return {x[o], x[o + 1], x[o + 2]};
}

// The 3x3 block of a composeRT derivative (CV_64F).
cv::Mat block3(const cv::Mat& d) {
    return d.reshape(1, 3);
}

}  // namespace

lm::Problem stereoLeastSquares(const CameraIntrinsics& main, const CameraIntrinsics& camera,
                               const std::vector<const CalibrationView*>& mainViews,
                               const std::vector<const CalibrationView*>& cameraViews) {
    lm::Problem p;
    p.parameters = int(6 + 6 * mainViews.size());
    // Residuals of pair i, main view then camera view; optionally the Jacobian block with columns
    // (T_camera_main's 6, T_main_board_i's 6).
    auto pair = [&main, &camera, &mainViews, &cameraViews](const std::vector<double>& x, size_t i,
                                                           std::vector<double>& r, cv::Mat* J) {
        const cv::Vec3d rC = vec3At(x, 0), tC = vec3At(x, 3);
        const cv::Vec3d rB = vec3At(x, 6 + 6 * i), tB = vec3At(x, 9 + 6 * i);
        std::vector<double> rm, rc;
        cv::Mat Jm, Jc;
        boardResiduals(*mainViews[i], main, rB, tB, rm, nullptr, J ? &Jm : nullptr);
        // T_camera_board = T_camera_main * T_main_board.
        cv::Vec3d r3, t3;
        cv::Mat dr3dr1, dr3dt1, dr3dr2, dr3dt2, dt3dr1, dt3dt1, dt3dr2, dt3dt2;
        cv::composeRT(rB, tB, rC, tC, r3, t3, dr3dr1, dr3dt1, dr3dr2, dr3dt2, dt3dr1, dt3dt1,
                      dt3dr2, dt3dt2);
        boardResiduals(*cameraViews[i], camera, r3, t3, rc, nullptr, J ? &Jc : nullptr);
        r = rm;
        r.insert(r.end(), rc.begin(), rc.end());
        if (!J) return;
        const int nm = int(rm.size()), nc = int(rc.size());
        *J = cv::Mat::zeros(nm + nc, 12, CV_64F);
        Jm.copyTo(J->rowRange(0, nm).colRange(6, 12));
        // Chain rule through the composition: d(r3, t3) / d(rC, tC) and / d(rB, tB).
        const cv::Mat Jr = Jc.colRange(0, 3), Jt = Jc.colRange(3, 6);
        cv::Mat out = J->rowRange(nm, nm + nc);
        cv::Mat(Jr * block3(dr3dr2) + Jt * block3(dt3dr2)).copyTo(out.colRange(0, 3));
        cv::Mat(Jr * block3(dr3dt2) + Jt * block3(dt3dt2)).copyTo(out.colRange(3, 6));
        cv::Mat(Jr * block3(dr3dr1) + Jt * block3(dt3dr1)).copyTo(out.colRange(6, 9));
        cv::Mat(Jr * block3(dr3dt1) + Jt * block3(dt3dt1)).copyTo(out.colRange(9, 12));
    };
    const size_t pairs = mainViews.size();
    p.residuals = [pair, pairs](const std::vector<double>& x, std::vector<double>& r) {
        r.clear();
        std::vector<double> ri;
        for (size_t i = 0; i < pairs; ++i) {
            pair(x, i, ri, nullptr);
            r.insert(r.end(), ri.begin(), ri.end());
        }
        return true;
    };
    p.jacobian = [pair, pairs](const std::vector<double>& x, lm::JacobianSink& sink) {
        std::vector<double> ri;
        size_t row = 0;
        for (size_t i = 0; i < pairs; ++i) {
            cv::Mat J;
            pair(x, i, ri, &J);
            std::vector<int> columns = {0, 1, 2, 3, 4, 5};
            for (int c = 0; c < 6; ++c) columns.push_back(int(6 + 6 * i) + c);
            const cv::Mat Jc = J.isContinuous() ? J : J.clone();
            sink.add(row, ri.size(), columns, Jc.ptr<double>());
            row += ri.size();
        }
    };
    return p;
}

Pose poseFromCv(const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    glm::dmat3 m;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m[c][r] = R(r, c);
    return Pose::fromRotationTranslation(m, {tvec[0], tvec[1], tvec[2]});
}

StereoExtrinsics estimateStereoExtrinsics(const CameraIntrinsics& main,
                                          const std::vector<CalibrationView>& mainViews,
                                          const CameraIntrinsics& camera,
                                          const std::vector<CalibrationView>& cameraViews) {
    if (mainViews.size() != cameraViews.size())
        throw Error(
            fmt::format("extrinsics: {} main-camera views but {} views of the other "
                        "camera; they must be taken in pairs",
                        mainViews.size(), cameraViews.size()));
    StereoExtrinsics e;
    std::vector<PairPose> pairs;
    std::vector<Pose> mainBoard(mainViews.size());
    for (size_t i = 0; i < mainViews.size(); ++i) {
        cv::Vec3d rm, tm, rc, tc;
        if (!estimateBoardPose(mainViews[i], main, rm, tm)) {
            e.skipped.push_back(mainViews[i].name + ": no board pose in the main camera");
            continue;
        }
        if (!estimateBoardPose(cameraViews[i], camera, rc, tc)) {
            e.skipped.push_back(cameraViews[i].name + ": no board pose in this camera");
            continue;
        }
        mainBoard[i] = poseFromCv(rm, tm);
        pairs.push_back({mainBoard[i] * poseFromCv(rc, tc).inverse(), i});
    }
    if (pairs.empty()) throw Error("extrinsics: no view pair shows the board in both cameras");
    Pose mean = meanPose(pairs);
    // Drop pairs far from the first mean (a mis-detection or a frame out of sync), then re-mean.
    // Single-view PnP depth is noisy for small or steep boards, so the limits are relative to
    // the median deviation, with floors of 1 degree and 10 mm.
    std::vector<double> dt, da;
    for (const auto& p : pairs) {
        dt.push_back(glm::length(p.T_main_camera.translation - mean.translation));
        da.push_back(rotationAngleBetween(p.T_main_camera.rotation, mean.rotation) * kRadToDeg);
    }
    auto medianOf = [](std::vector<double> v) {
        std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    const double limitT = std::max(3 * medianOf(dt), 0.010);
    const double limitA = std::max(3 * medianOf(da), 1.0);
    std::vector<PairPose> kept;
    for (size_t k = 0; k < pairs.size(); ++k) {
        if (pairs.size() >= 3 && (da[k] > limitA || dt[k] > limitT))
            e.skipped.push_back(
                fmt::format("{}: outlier pair ({:.2f} deg, {:.1f} mm from the mean)",
                            cameraViews[pairs[k].index].name, da[k], 1000 * dt[k]));
        else
            kept.push_back(pairs[k]);
    }
    mean = meanPose(kept);
    // Joint refinement of T_camera_main and every pair's board pose T_main_board_i over both
    // cameras' reprojection errors (pixels), intrinsics fixed, from the mean and the main camera's
    // per-pair board poses. State: rvec, tvec of T_camera_main, then of each T_main_board_i.
    std::vector<const CalibrationView*> keptMain, keptCamera;
    cv::Vec3d rC, tC;
    toCv(mean.inverse(), rC, tC);
    std::vector<double> x = {rC[0], rC[1], rC[2], tC[0], tC[1], tC[2]};
    for (const auto& p : kept) {
        keptMain.push_back(&mainViews[p.index]);
        keptCamera.push_back(&cameraViews[p.index]);
        cv::Vec3d rB, tB;
        toCv(mainBoard[p.index], rB, tB);
        x.insert(x.end(), {rB[0], rB[1], rB[2], tB[0], tB[1], tB[2]});
    }
    const lm::Problem problem = stereoLeastSquares(main, camera, keptMain, keptCamera);
    lm::Options o;
    o.maxIterations = 50;
    lm::solve(problem, x, o);
    // 1-sigma of T_camera_main's 6 parameters; +inf if singular.
    const lm::Covariance cov = lm::covariance(problem, x);
    std::array<double, 6> sd;
    for (int i = 0; i < 6; ++i)
        sd[size_t(i)] = cov.ok ? std::sqrt(std::max(0.0, cov.at(i, i)))
                               : std::numeric_limits<double>::infinity();
    e.rotationStdDeg = std::sqrt(sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]) * kRadToDeg;
    e.translationStdM = std::sqrt(sd[3] * sd[3] + sd[4] * sd[4] + sd[5] * sd[5]);
    mean = poseFromCv(vec3At(x, 0), vec3At(x, 3)).inverse();
    for (size_t k = 0; k < kept.size(); ++k)
        mainBoard[kept[k].index] = poseFromCv(vec3At(x, 6 + 6 * k), vec3At(x, 9 + 6 * k));
    e.T_main_camera = mean;
    e.pairCount = int(kept.size());
    double rot2 = 0, tr2 = 0, transfer2 = 0;
    size_t transferN = 0;
    const Pose T_camera_main = mean.inverse();
    for (const auto& p : kept) {
        const double a = rotationAngleBetween(p.T_main_camera.rotation, mean.rotation) * kRadToDeg;
        rot2 += a * a;
        const double d = glm::length(p.T_main_camera.translation - mean.translation);
        tr2 += d * d;
        cv::Vec3d rvec, tvec;
        toCv(T_camera_main * mainBoard[p.index], rvec, tvec);
        const auto& v = cameraViews[p.index];
        const auto projected = projectBoardPoints(v.boardPoints, camera, rvec, tvec);
        const double r = rmsPixels(projected, v.imagePoints);
        transfer2 += r * r * double(v.imagePoints.size());
        transferN += v.imagePoints.size();
    }
    e.rotationSpreadDeg = std::sqrt(rot2 / double(kept.size()));
    e.translationSpreadM = std::sqrt(tr2 / double(kept.size()));
    e.transferRmsPx = std::sqrt(transfer2 / double(std::max<size_t>(1, transferN)));
    return e;
}

StereoExtrinsics extrinsicsFromPairedInputs(const CameraIntrinsics& main,
                                            const std::vector<std::string>& mainInputs,
                                            const CameraIntrinsics& camera,
                                            const std::vector<std::string>& cameraInputs,
                                            const CalibrationTarget& target) {
    FrameListOptions so;
    so.allVideoFrames = true;  // pairing by order needs every frame of both
    auto mainSource = openFrameList(mainInputs, so);
    auto camSource = openFrameList(cameraInputs, so);
    std::vector<CalibrationView> mv, cv_;
    cv::Mat a, b;
    while (true) {
        const bool ga = mainSource->read(a), gb = camSource->read(b);
        if (ga != gb)
            throw Error(
                "extrinsics: --main-input and INPUT hold different numbers of frames; "
                "they must be taken in pairs");
        if (!ga) break;
        if (a.empty() || b.empty()) continue;  // a lost frame (damaged recording): no pair
        auto da = target.detect(a, mainSource->lastName()),
             db = target.detect(b, camSource->lastName());
        if (da.found && db.found) {
            mv.push_back(std::move(da.view));
            cv_.push_back(std::move(db.view));
        }
    }
    if (mv.empty()) throw Error("extrinsics: no frame pair shows the board in both cameras");
    return estimateStereoExtrinsics(main, mv, camera, cv_);
}

WorldPose poseFromWorldBoard(const CameraIntrinsics& camera, const std::string& imagePath,
                             const CalibrationTarget& target) {
    // Strict decoding, the size screened from the header first (core/image/StrictJpeg.h).
    std::string why;
    const cv::Mat img = readImageStrict(imagePath, &why);
    if (img.empty()) throw FileError(imagePath, "cannot be read as an image: " + why);
    if (img.cols != camera.width || img.rows != camera.height)
        throw FileError(imagePath, fmt::format("is {}x{} but the calibration is for {}x{}",
                                               img.cols, img.rows, camera.width, camera.height));
    const auto d = target.detect(img, imagePath);
    if (!d.found) throw FileError(imagePath, d.reason);
    cv::Vec3d rvec, tvec;
    if (!estimateBoardPose(d.view, camera, rvec, tvec))
        throw FileError(imagePath, "board pose could not be estimated");
    WorldPose w;
    // T_world_camera = T_world_board * T_board_camera.
    w.T_world_camera = target.worldFromBoard() * poseFromCv(rvec, tvec).inverse();
    w.rmsPx =
        rmsPixels(projectBoardPoints(d.view.boardPoints, camera, rvec, tvec), d.view.imagePoints);
    return w;
}

std::string formatExtrinsics(const StereoExtrinsics& e) {
    const auto& t = e.T_main_camera.translation;
    const auto& q = e.T_main_camera.rotation;
    std::string s = "extrinsics relative to the main camera (T_main_camera):\n";
    s += fmt::format("  translation (m): {:.5f} {:.5f} {:.5f}\n", t.x, t.y, t.z);
    s += fmt::format("  rotation (qw qx qy qz): {:.6f} {:.6f} {:.6f} {:.6f}\n", q.w, q.x, q.y, q.z);
    s += fmt::format("  1-sigma: rotation {:.3f} deg, translation {:.2f} mm\n", e.rotationStdDeg,
                     1000 * e.translationStdM);
    s += fmt::format(
        "  pairs used: {}; per-pair spread: {:.3f} deg, {:.2f} mm; transfer RMS "
        "{:.3f} px\n",
        e.pairCount, e.rotationSpreadDeg, 1000 * e.translationSpreadM, e.transferRmsPx);
    for (const auto& k : e.skipped) s += "  skipped " + k + "\n";
    return s;
}

}  // namespace mirage::calib
