#include "calibration/BatchCalibration.h"

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Log.h"

namespace mirage::calib {

BatchResult runBatchCalibration(const std::vector<std::string>& inputs,
                                const CalibrationTarget& target, const BatchOptions& options) {
    auto source = openFrameList(inputs, options.source);
    BatchResult r;
    r.targetDescription = target.description();
    std::vector<CalibrationView> views;
    std::string firstName;
    cv::Mat bgr;
    while (source->read(bgr)) {
        ++r.framesRead;
        const std::string name = source->lastName();
        if (bgr.empty()) {
            r.skipped.push_back({name, "frame lost: " + source->lastProblem()});
            continue;
        }
        const cv::Size size = bgr.size();
        if (firstName.empty()) {
            r.imageSize = size;
            firstName = name;
        } else if (size != r.imageSize) {
            throw Error(fmt::format(
                "mixed image sizes: {} is {}x{} but {} is {}x{}; all inputs must come from the "
                "same camera at the same resolution",
                firstName, r.imageSize.width, r.imageSize.height, name, size.width, size.height));
        }
        auto d = target.detect(bgr, name);
        // Video input can take minutes: say how far it got.
        if (r.framesRead % 5 == 0)
            spdlog::info("calibrate: {} frame(s) read, the board found in {} (last: {})",
                         r.framesRead, views.size() + (d.found ? 1 : 0), name);
        if (d.found) {
            spdlog::debug("{}: {} corners", name, d.view.imagePoints.size());
            views.push_back(std::move(d.view));
        } else {
            spdlog::debug("{}: {}", name, d.reason);
            r.skipped.push_back({name, d.reason});
        }
    }
    if (r.framesRead == 0) throw Error("the inputs hold no frames");
    if (views.empty())
        throw Error(fmt::format(
            "the {} was found in none of the {} frames (first: {}); check --board (a "
            "chessboard is given by its INNER corners: 10x7 squares = chessboard:9x6:SIZE) and "
            "that the whole board is visible",
            r.targetDescription, r.framesRead, firstName));
    r.calibration = calibrate(views, r.imageSize, options.calibration);
    return r;
}

std::string formatCalibrationResult(const CalibrationResult& r) {
    const auto& c = r.calibration;
    const auto& in = c.intrinsics;
    std::string s;
    s += fmt::format("model: {} ({})\n", distortionModelName(in.model),
                     in.model == DistortionModel::KannalaBrandt
                         ? "OpenCV fisheye, Kannala-Brandt k1..k4"
                         : "pinhole + Brown-Conrady k1 k2 p1 p2 k3");
    s += fmt::format("image size: {}x{}\n", in.width, in.height);
    s += fmt::format("views used: {} of {}\n", r.usedViewCount(), r.views.size());
    s += fmt::format("RMS reprojection error: {:.4f} px\n", c.avgReprojectionError);
    s += "parameters (value +- 1-sigma standard deviation):\n";
    for (size_t i = 0; i < r.parameterNames.size(); ++i) {
        const double value = i == 0   ? in.fx
                             : i == 1 ? in.fy
                             : i == 2 ? in.cx
                             : i == 3 ? in.cy
                                      : in.coeff(i - 4);
        const double sd = i < c.stdDeviations.size() ? c.stdDeviations[i] : -1;
        const std::string unit = i < 4 ? " px" : "";
        if (sd == 0)
            s += fmt::format("  {:<3} {:>14.6f}{} (fixed)\n", r.parameterNames[i], value, unit);
        else
            s += fmt::format("  {:<3} {:>14.6f} +- {:.6f}{}\n", r.parameterNames[i], value, sd,
                             unit);
    }
    const bool fisheye = in.model == DistortionModel::KannalaBrandt;
    s += fmt::format(
        "views (RMS px, noise px per coordinate, weight, tilt deg {}, max off-axis deg, "
        "detector):\n",
        fisheye ? "to the line of sight" : "to the optical axis");
    for (const auto& v : r.views) {
        if (v.rejected) {
            s += fmt::format("  {:<28} REJECTED: {}\n", v.name, v.rejectReason);
            continue;
        }
        s += fmt::format("  {:<28} {:7.4f}  {:6.3f}  {:4.2f}  {:5.1f}  {:5.1f}  {}  ({} points",
                         v.name, v.rmsPx, v.noisePx, v.weight, v.tiltDeg, v.maxOffAxisDeg,
                         v.detector.empty() ? "-" : v.detector, v.pointCount);
        if (v.unrefinedCorners > 0)
            s += fmt::format(", {} corners not refined (left out)", v.unrefinedCorners);
        if (!v.droppedCorners.empty()) s += fmt::format(", {} dropped", v.droppedCorners.size());
        s += ")\n";
        for (const auto& d : v.droppedCorners)
            s += fmt::format(
                "      dropped corner at ({:.1f}, {:.1f}) px, board ({:.4f}, {:.4f}) m: residual "
                "{:.2f} px\n",
                d.imagePoint.x, d.imagePoint.y, d.boardPoint.x, d.boardPoint.y, d.residualPx);
    }
    s += fmt::format("outlier corners dropped: {}\n", r.droppedCornerCount);
    s += fmt::format("largest board tilt: {:.1f} deg\n", r.maxTiltDeg);
    s += fmt::format(
        "reach: corners up to {:.1f} deg off the optical axis, {:.1f} px from the principal "
        "point (beyond: extrapolated)\n",
        c.reachDeg, c.reachRadiusPx);
    for (const auto& w : r.warnings) s += "warning: " + w + "\n";
    s += c.reliable ? std::string("verdict: reliable\n")
                    : "verdict: UNRELIABLE: " + c.unreliableReason + "\n";
    return s;
}

std::string formatReport(const BatchResult& r) {
    std::string s = "mirage calibrate report\n";
    s += fmt::format("target: {}\n", r.targetDescription);
    s += fmt::format("frames read: {}, board found in {}, not found in {}\n", r.framesRead,
                     r.framesRead - int(r.skipped.size()), r.skipped.size());
    s += formatCalibrationResult(r.calibration);
    if (!r.skipped.empty()) {
        s += "frames without a detection:\n";
        for (const auto& f : r.skipped) s += fmt::format("  {:<28} {}\n", f.name, f.reason);
    }
    return s;
}

}  // namespace mirage::calib
