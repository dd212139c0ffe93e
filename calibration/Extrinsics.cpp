#include "calibration/Extrinsics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calibration/FrameSource.h"
#include "core/Error.h"

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

// Joint refinement of T_camera_main and every pair's board pose T_main_board_i, minimising the
// reprojection errors (pixels) of both cameras' corners with the intrinsics fixed. Parameters:
// x = [rvec, tvec of T_camera_main | rvec, tvec of T_main_board_i ...]. Levenberg-Marquardt on
// central-difference Jacobians (the problem is small: 6 + 6 per pair). Returns the 1-sigma
// deviations of the first 6 parameters, (J^T J)^-1 sigma^2 as for the intrinsics.
struct StereoProblem {
    const CameraIntrinsics* main;
    const CameraIntrinsics* camera;
    std::vector<const CalibrationView*> mainViews, cameraViews;
    std::vector<double> x;

    int pairs() const { return int(mainViews.size()); }
    // Residuals of pair i (main corners, then camera corners), appended to r.
    void pairResiduals(int i, const std::vector<double>& p, std::vector<double>& r) const {
        const cv::Vec3d rC(p[0], p[1], p[2]), tC(p[3], p[4], p[5]);
        const size_t o = 6 + 6 * size_t(i);
        const cv::Vec3d rB(p[o], p[o + 1], p[o + 2]), tB(p[o + 3], p[o + 4], p[o + 5]);
        const auto& mv = *mainViews[size_t(i)];
        const auto pm = projectBoardPoints(mv.boardPoints, *main, rB, tB);
        for (size_t k = 0; k < pm.size(); ++k) {
            r.push_back(double(pm[k].x) - mv.imagePoints[k].x);
            r.push_back(double(pm[k].y) - mv.imagePoints[k].y);
        }
        cv::Vec3d r3, t3;  // T_camera_board = T_camera_main * T_main_board
        cv::composeRT(rB, tB, rC, tC, r3, t3);
        const auto& cvw = *cameraViews[size_t(i)];
        const auto pc = projectBoardPoints(cvw.boardPoints, *camera, r3, t3);
        for (size_t k = 0; k < pc.size(); ++k) {
            r.push_back(double(pc[k].x) - cvw.imagePoints[k].x);
            r.push_back(double(pc[k].y) - cvw.imagePoints[k].y);
        }
    }
    double cost(const std::vector<double>& p) const {
        std::vector<double> r;
        for (int i = 0; i < pairs(); ++i) pairResiduals(i, p, r);
        double s = 0;
        for (double v : r) s += v * v;
        return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
    }
    // Normal equations A = J^T J, g = J^T r at p; also the residual count.
    void normal(const std::vector<double>& p, cv::Mat& A, cv::Mat& g, int& residuals) const {
        const int P = int(p.size());
        A = cv::Mat::zeros(P, P, CV_64F);
        g = cv::Mat::zeros(P, 1, CV_64F);
        residuals = 0;
        const double h = 1e-6;
        for (int i = 0; i < pairs(); ++i) {
            std::vector<double> r0;
            pairResiduals(i, p, r0);
            const int n = int(r0.size());
            residuals += n;
            // Columns that touch this pair: the shared 6 and its own 6.
            std::vector<int> cols = {0, 1, 2, 3, 4, 5};
            for (int c = 0; c < 6; ++c) cols.push_back(6 + 6 * i + c);
            cv::Mat J(n, 12, CV_64F);
            for (int c = 0; c < 12; ++c) {
                auto pp = p, pm = p;
                pp[size_t(cols[size_t(c)])] += h;
                pm[size_t(cols[size_t(c)])] -= h;
                std::vector<double> rp, rm;
                pairResiduals(i, pp, rp);
                pairResiduals(i, pm, rm);
                for (int k = 0; k < n; ++k)
                    J.at<double>(k, c) = (rp[size_t(k)] - rm[size_t(k)]) / (2 * h);
            }
            const cv::Mat r(n, 1, CV_64F, r0.data());
            const cv::Mat JtJ = J.t() * J, Jtr = J.t() * r;
            for (int a = 0; a < 12; ++a) {
                g.at<double>(cols[size_t(a)]) += Jtr.at<double>(a);
                for (int b = 0; b < 12; ++b)
                    A.at<double>(cols[size_t(a)], cols[size_t(b)]) += JtJ.at<double>(a, b);
            }
        }
    }
    void refine(int maxIterations) {
        double c = cost(x), lambda = 1e-3;
        for (int it = 0; it < maxIterations; ++it) {
            cv::Mat A, g;
            int n = 0;
            normal(x, A, g, n);
            bool accepted = false;
            double newCost = c;
            while (lambda < 1e12) {
                cv::Mat Ad = A.clone();
                for (int i = 0; i < Ad.rows; ++i) Ad.at<double>(i, i) *= 1 + lambda;
                cv::Mat d;
                if (!cv::solve(Ad, -g, d, cv::DECOMP_CHOLESKY)) {
                    lambda *= 10;
                    continue;
                }
                auto trial = x;
                for (size_t k = 0; k < trial.size(); ++k) trial[k] += d.at<double>(int(k));
                newCost = cost(trial);
                if (newCost < c) {
                    x = trial;
                    accepted = true;
                    lambda = std::max(lambda / 10, 1e-9);
                    break;
                }
                lambda *= 10;
            }
            if (!accepted || (c - newCost) < 1e-12 * c) break;
            c = newCost;
        }
    }
    // 1-sigma of the shared 6 parameters; +inf if singular.
    std::array<double, 6> sharedStd() const {
        std::array<double, 6> sd;
        sd.fill(std::numeric_limits<double>::infinity());
        cv::Mat A, g;
        int n = 0;
        normal(x, A, g, n);
        const int dof = n - A.rows;
        cv::Mat inv;
        if (dof <= 0 || cv::invert(A, inv, cv::DECOMP_SVD) == 0) return sd;
        const double sigma2 = cost(x) / dof;
        for (int i = 0; i < 6; ++i)
            sd[size_t(i)] = std::sqrt(std::max(0.0, inv.at<double>(i, i) * sigma2));
        return sd;
    }
};

}  // namespace

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
    // Joint refinement from the mean and the main camera's per-pair board poses.
    StereoProblem prob;
    prob.main = &main;
    prob.camera = &camera;
    cv::Vec3d rC, tC;
    toCv(mean.inverse(), rC, tC);
    prob.x = {rC[0], rC[1], rC[2], tC[0], tC[1], tC[2]};
    for (const auto& p : kept) {
        prob.mainViews.push_back(&mainViews[p.index]);
        prob.cameraViews.push_back(&cameraViews[p.index]);
        cv::Vec3d rB, tB;
        toCv(mainBoard[p.index], rB, tB);
        prob.x.insert(prob.x.end(), {rB[0], rB[1], rB[2], tB[0], tB[1], tB[2]});
    }
    prob.refine(50);
    const auto sd = prob.sharedStd();
    e.rotationStdDeg = std::sqrt(sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]) * kRadToDeg;
    e.translationStdM = std::sqrt(sd[3] * sd[3] + sd[4] * sd[4] + sd[5] * sd[5]);
    mean = poseFromCv(cv::Vec3d(prob.x[0], prob.x[1], prob.x[2]),
                      cv::Vec3d(prob.x[3], prob.x[4], prob.x[5]))
               .inverse();
    for (size_t k = 0; k < kept.size(); ++k)
        mainBoard[kept[k].index] =
            poseFromCv(cv::Vec3d(prob.x[6 + 6 * k], prob.x[7 + 6 * k], prob.x[8 + 6 * k]),
                       cv::Vec3d(prob.x[9 + 6 * k], prob.x[10 + 6 * k], prob.x[11 + 6 * k]));
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
    FrameSourceOptions so;
    so.allVideoFrames = true;  // pairing by order needs every frame of both
    auto mainSource = openFrameSource(mainInputs, so);
    auto camSource = openFrameSource(cameraInputs, so);
    std::vector<CalibrationView> mv, cv_;
    InputFrame a, b;
    while (true) {
        const bool ga = mainSource->next(a), gb = camSource->next(b);
        if (ga != gb)
            throw Error(
                "extrinsics: --main-input and INPUT hold different numbers of frames; "
                "they must be taken in pairs");
        if (!ga) break;
        auto da = target.detect(a.bgr, a.name), db = target.detect(b.bgr, b.name);
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
    const cv::Mat img = cv::imread(imagePath, cv::IMREAD_COLOR);
    if (img.empty()) throw FileError(imagePath, "cannot be read as an image");
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
