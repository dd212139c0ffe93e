#include "core/camera/CalibrationFile.h"

#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <sstream>

#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/Log.h"
#include "core/Timestamp.h"
#include "core/session/AtomicFile.h"

namespace mirage {

namespace {

// Key spellings accepted on reading, first = the one mirage writes (OpenCV's calibration sample).
const std::vector<std::string> kCameraMatrixKeys = {"camera_matrix", "cameraMatrix", "K"};
const std::vector<std::string> kDistortionKeys = {"distortion_coefficients", "dist_coeffs",
                                                  "distCoeffs", "D"};
const std::vector<std::string> kWidthKeys = {"image_width", "imageWidth"};
const std::vector<std::string> kHeightKeys = {"image_height", "imageHeight"};

struct Reader {
    std::string file;
    cv::FileNode root;

    [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
        throw FileError(file, "key '" + key + "': " + problem);
    }

    // The first key present among `keys`; empty node (and `found` empty) if none is.
    cv::FileNode find(const std::vector<std::string>& keys, std::string& found) const {
        for (const auto& k : keys) {
            cv::FileNode n = root[k];
            if (!n.empty() && !n.isNone()) {
                found = k;
                return n;
            }
        }
        found.clear();
        return {};
    }

    static std::string alternatives(const std::vector<std::string>& keys) {
        std::string s;
        for (size_t i = 0; i < keys.size(); ++i) s += (i ? " or '" : "'") + keys[i] + "'";
        return s;
    }

    double number(const cv::FileNode& n, const std::string& key) const {
        if (!n.isInt() && !n.isReal()) fail(key, "expected a number");
        const double v = n.real();
        if (!std::isfinite(v)) fail(key, "not a finite number");
        return v;
    }

    int integer(const cv::FileNode& n, const std::string& key) const {
        const double v = number(n, key);
        if (v != std::floor(v) || std::abs(v) > 1e9) fail(key, "expected an integer");
        return int(v);
    }

    // A matrix as an OpenCV "!!opencv-matrix" map (rows, cols, dt, data), a ROS camera_info
    // style map (rows, cols, data), or a flat sequence of numbers (then rows x cols is
    // `expectRows` x n/expectRows when expectRows > 0, else a column). Values read as doubles.
    cv::Mat matrix(const cv::FileNode& n, const std::string& key, int expectRows) const {
        std::vector<double> data;
        int rows = -1, cols = -1;
        cv::FileNode seq;
        if (n.isMap()) {
            seq = n["data"];
            if (seq.empty() || !seq.isSeq()) fail(key, "matrix has no 'data' sequence");
            if (!n["rows"].empty()) rows = integer(n["rows"], key + ".rows");
            if (!n["cols"].empty()) cols = integer(n["cols"], key + ".cols");
        } else if (n.isSeq()) {
            seq = n;
        } else {
            fail(key, "expected a matrix (rows, cols, data) or a sequence of numbers");
        }
        for (auto it = seq.begin(); it != seq.end(); ++it) data.push_back(number(*it, key));
        const int count = int(data.size());
        if (rows < 0 && cols < 0) {
            rows = expectRows > 0 ? expectRows : count;
            cols = rows > 0 ? count / rows : 0;
        } else if (rows < 0) {
            rows = cols > 0 ? count / cols : 0;
        } else if (cols < 0) {
            cols = rows > 0 ? count / rows : 0;
        }
        if (rows <= 0 || cols <= 0 || rows * cols != count)
            fail(key, "matrix has " + std::to_string(count) + " values, which does not fit " +
                          std::to_string(rows) + "x" + std::to_string(cols));
        return cv::Mat(data, true).reshape(1, rows);
    }
};

// The file's text as an OpenCV FileStorage.
cv::FileStorage openCalibrationYaml(const std::filesystem::path& path) {
    const std::string file = path.string();
    // Reading through memory keeps FileStorage from guessing the format from the extension
    // (ROS camera_info files are often *.yml or *.yaml without the %YAML directive).
    std::string text = readFileBytes(path);
    if (text.rfind("%YAML", 0) != 0) text = "%YAML:1.0\n---\n" + text;
    cv::FileStorage fs;
    try {
        fs.open(text,
                cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    } catch (const cv::Exception& e) {
        throw FileError(file, std::string("not a valid OpenCV YAML file: ") + e.err);
    } catch (const std::exception& e) {
        // OpenCV's YAML parser throws std::length_error on some damaged files (found by
        // calibration_fuzz); still bad input, not a bug of mirage.
        throw FileError(file, std::string("not a valid OpenCV YAML file (the parser failed: ") +
                                  e.what() + ")");
    }
    if (!fs.isOpened()) throw FileError(file, "not a valid OpenCV YAML file");
    return fs;
}

// Image size and camera matrix.
void readSizeAndCameraMatrix(const Reader& r, CameraIntrinsics& in) {
    std::string key;
    cv::FileNode n = r.find(kWidthKeys, key);
    if (n.empty()) r.fail("image_width", "missing (the calibrated image size is required)");
    in.width = r.integer(n, key);
    n = r.find(kHeightKeys, key);
    if (n.empty()) r.fail("image_height", "missing (the calibrated image size is required)");
    in.height = r.integer(n, key);
    if (in.width <= 0 || in.height <= 0)
        r.fail("image_width", "image size must be positive, got " + std::to_string(in.width) + "x" +
                                  std::to_string(in.height));

    n = r.find(kCameraMatrixKeys, key);
    if (n.empty())
        r.fail("camera_matrix",
               "missing (also accepted: " + Reader::alternatives(kCameraMatrixKeys) + ")");
    const cv::Mat k = r.matrix(n, key, 3);
    if (k.rows != 3 || k.cols != 3) r.fail(key, "camera matrix must be 3x3");
    in.fx = k.at<double>(0, 0);
    in.fy = k.at<double>(1, 1);
    in.cx = k.at<double>(0, 2);
    in.cy = k.at<double>(1, 2);
    if (!(in.fx > 0 && in.fy > 0))
        r.fail(key, "focal lengths must be positive (fx=" + std::to_string(in.fx) +
                        ", fy=" + std::to_string(in.fy) + ")");
    if (std::abs(k.at<double>(2, 2) - 1.0) > 1e-9 || k.at<double>(1, 0) != 0 ||
        k.at<double>(2, 0) != 0 || k.at<double>(2, 1) != 0)
        r.fail(key, "not an upper-triangular camera matrix with K[2][2] = 1");
    if (std::abs(k.at<double>(0, 1)) > 1e-9 * in.fx)
        r.fail(key, "non-zero skew K[0][1] is not supported by mirage's camera models");
}

// Distortion model and coefficients.
void readDistortion(const Reader& r, CameraIntrinsics& in) {
    std::string key;
    cv::FileNode n;
    // Model: mirage's distortion_model key, else the tutorial's fisheye_model flag, else pinhole.
    in.model = DistortionModel::BrownConrady;
    if (cv::FileNode m = r.root["distortion_model"]; !m.empty()) {
        if (!m.isString()) r.fail("distortion_model", "expected a string (plumb_bob or fisheye)");
        try {
            in.model = distortionModelFromName(m.string());
        } catch (const Error& e) {
            r.fail("distortion_model", e.what());
        }
    } else if (cv::FileNode f = r.root["fisheye_model"]; !f.empty()) {
        in.model = r.integer(f, "fisheye_model") != 0 ? DistortionModel::KannalaBrandt
                                                      : DistortionModel::BrownConrady;
    }

    n = r.find(kDistortionKeys, key);
    if (n.empty())
        r.fail("distortion_coefficients",
               "missing (also accepted: " + Reader::alternatives(kDistortionKeys) +
                   "; write an empty list for a distortion-free camera)");
    if (n.isSeq() && n.size() == 0) {
        in.distortion.clear();
    } else {
        const cv::Mat d = r.matrix(n, key, 0);
        if (d.rows != 1 && d.cols != 1) r.fail(key, "expected a row or column of coefficients");
        in.distortion.assign(d.begin<double>(), d.end<double>());
    }
    const size_t supported = in.model == DistortionModel::KannalaBrandt ? 4 : 5;
    if (in.model == DistortionModel::KannalaBrandt && !in.distortion.empty() &&
        in.distortion.size() != 4)
        r.fail(key, "the fisheye model takes exactly 4 coefficients k1..k4, got " +
                        std::to_string(in.distortion.size()));
    for (size_t i = supported; i < in.distortion.size(); ++i)
        if (in.distortion[i] != 0.0)
            r.fail(key, "coefficient " + std::to_string(i + 1) +
                            " is non-zero: mirage supports k1,k2,p1,p2,k3 only (recalibrate "
                            "without the rational / thin-prism / tilted models)");
    if (in.distortion.size() > supported) in.distortion.resize(supported);
}

// Residuals, view count, reach and reliability: what the calibration says about itself.
void readQuality(const Reader& r, CameraCalibration& c) {
    if (cv::FileNode e = r.root["avg_reprojection_error"]; !e.empty())
        c.avgReprojectionError = r.number(e, "avg_reprojection_error");
    if (cv::FileNode e = r.root["per_view_reprojection_errors"]; !e.empty()) {
        const cv::Mat v = r.matrix(e, "per_view_reprojection_errors", 0);
        c.perViewErrors.assign(v.begin<double>(), v.end<double>());
    }
    if (cv::FileNode e = r.root["std_deviations_intrinsics"]; !e.empty()) {
        const cv::Mat v = r.matrix(e, "std_deviations_intrinsics", 0);
        c.stdDeviations.assign(v.begin<double>(), v.end<double>());
    }
    if (cv::FileNode e = r.root["nr_of_frames"]; !e.empty())
        c.viewCount = r.integer(e, "nr_of_frames");
    else if (cv::FileNode e2 = r.root["nframes"]; !e2.empty())
        c.viewCount = r.integer(e2, "nframes");
    else
        c.viewCount = int(c.perViewErrors.size());

    // The reach (optional: files written before it, or by other tools, have none).
    if (cv::FileNode e = r.root["reach_off_axis_deg"]; !e.empty()) {
        c.reachDeg = r.number(e, "reach_off_axis_deg");
        if (!(c.reachDeg > 0 && c.reachDeg <= 180))
            r.fail("reach_off_axis_deg", "must be an angle in (0, 180] degrees");
    }
    if (cv::FileNode e = r.root["reach_radius_px"]; !e.empty()) {
        c.reachRadiusPx = r.number(e, "reach_radius_px");
        if (!(c.reachRadiusPx > 0)) r.fail("reach_radius_px", "must be a positive radius");
    }
    if (cv::FileNode e = r.root["reliable"]; !e.empty()) c.reliable = r.integer(e, "reliable") != 0;
    if (cv::FileNode e = r.root["unreliable_reason"]; !e.empty()) {
        if (!e.isString()) r.fail("unreliable_reason", "expected a string");
        c.unreliableReason = e.string();
    }
}

// The optional extrinsic: T_parent_camera with its parent.
void readExtrinsic(const Reader& r, CameraCalibration& c) {
    cv::FileNode t = r.root["T_parent_camera"];
    cv::FileNode parent = r.root["extrinsic_parent"];
    if (!t.empty()) {
        if (parent.empty() || !parent.isString())
            r.fail("extrinsic_parent",
                   "missing: T_parent_camera needs its parent ('main' or 'world')");
        c.extrinsicParent = parent.string();
        if (c.extrinsicParent != "main" && c.extrinsicParent != "world")
            r.fail("extrinsic_parent",
                   "must be 'main' or 'world', got '" + c.extrinsicParent + "'");
        const cv::Mat m = r.matrix(t, "T_parent_camera", 4);
        if (m.rows != 4 || m.cols != 4) r.fail("T_parent_camera", "must be a 4x4 matrix");
        if (m.at<double>(3, 0) != 0 || m.at<double>(3, 1) != 0 || m.at<double>(3, 2) != 0 ||
            m.at<double>(3, 3) != 1)
            r.fail("T_parent_camera", "last row must be 0 0 0 1");
        glm::dmat3 rot;
        glm::dvec3 trans;
        for (int row = 0; row < 3; ++row) {
            for (int col = 0; col < 3; ++col) rot[col][row] = m.at<double>(row, col);
            trans[row] = m.at<double>(row, 3);
        }
        // A calibration result is orthonormal to many digits; a loose bound only catches typos
        // and scaled matrices, which Pose::fromRotationTranslation would otherwise hide.
        const glm::dmat3 rtr = glm::transpose(rot) * rot;
        double worst = std::abs(glm::determinant(rot) - 1.0);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) worst = std::max(worst, std::abs(rtr[a][b] - (a == b)));
        if (worst > 1e-4)
            r.fail("T_parent_camera", "rotation part is not a rotation (R^T R != I or det != 1)");
        c.T_parent_camera = Pose::fromRotationTranslation(rot, trans);
    } else if (!parent.empty()) {
        r.fail("T_parent_camera", "missing although extrinsic_parent is set");
    }
}

}  // namespace

CameraCalibration loadCalibration(const std::filesystem::path& path) {
    const std::string file = path.string();
    if (!std::filesystem::is_regular_file(path))
        throw FileError(file, "calibration file not found (run `mirage calibrate` to make one)");
    cv::FileStorage fs = openCalibrationYaml(path);
    Reader r{file, fs.root()};
    if (!r.root.isMap())
        throw FileError(file, "expected a YAML map of calibration keys at the top");
    CameraCalibration c;
    readSizeAndCameraMatrix(r, c.intrinsics);
    readDistortion(r, c.intrinsics);
    readQuality(r, c);
    readExtrinsic(r, c);
    if (!c.intrinsics.isValid()) throw FileError(file, "intrinsics are not finite/positive");
    // Used all the same (the numbers may still serve), but never silently.
    if (!c.reliable)
        spdlog::warn(
            "{}: the calibration is marked unreliable (reliable: 0){}; results that "
            "depend on it may be off. Recalibrate (docs/calibration.md)",
            file, c.unreliableReason.empty() ? "" : ": " + c.unreliableReason);
    return c;
}

namespace {

cv::Mat column(const std::vector<double>& v) {
    return cv::Mat(v, true);
}

}  // namespace

void saveCalibration(const std::filesystem::path& path, const CameraCalibration& c) {
    const CameraIntrinsics& in = c.intrinsics;
    if (!in.isValid())
        throw FileError(path.string(),
                        "refusing to write invalid intrinsics (size or focal length)");
    cv::FileStorage fs(
        ".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    // Key names and layout of OpenCV's camera calibration sample, so that OpenCV tools read it.
    fs << "calibration_time" << utcTimestamp();
    fs << "nr_of_frames" << c.viewCount;
    fs << "image_width" << in.width;
    fs << "image_height" << in.height;
    fs << "fisheye_model" << int(in.model == DistortionModel::KannalaBrandt);
    const cv::Mat k = (cv::Mat_<double>(3, 3) << in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
    fs << "camera_matrix" << k;
    // No coefficients means no distortion: write the model's full set of zeros, because an empty
    // matrix is written as a 0x1 node that readers (ours included) reject.
    std::vector<double> dist = in.distortion;
    if (dist.empty()) dist.assign(in.model == DistortionModel::KannalaBrandt ? 4 : 5, 0.0);
    fs << "distortion_coefficients" << column(dist);
    if (c.avgReprojectionError >= 0) fs << "avg_reprojection_error" << c.avgReprojectionError;
    if (!c.perViewErrors.empty()) fs << "per_view_reprojection_errors" << column(c.perViewErrors);
    // mirage's additions (docs/formats.md).
    fs << "distortion_model" << distortionModelName(in.model);
    if (!c.stdDeviations.empty()) fs << "std_deviations_intrinsics" << column(c.stdDeviations);
    if (c.reachDeg > 0) fs << "reach_off_axis_deg" << c.reachDeg;
    if (c.reachRadiusPx > 0) fs << "reach_radius_px" << c.reachRadiusPx;
    fs << "reliable" << int(c.reliable);
    if (!c.unreliableReason.empty()) fs << "unreliable_reason" << c.unreliableReason;
    if (c.T_parent_camera) {
        if (c.extrinsicParent != "main" && c.extrinsicParent != "world")
            throw FileError(path.string(), "extrinsic parent must be 'main' or 'world', got '" +
                                               c.extrinsicParent + "'");
        fs << "extrinsic_parent" << c.extrinsicParent;
        const glm::dmat4 m = c.T_parent_camera->matrix();
        cv::Mat t(4, 4, CV_64F);
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) t.at<double>(row, col) = m[col][row];
        fs << "T_parent_camera" << t;
    }
    writeFileAtomically(path, fs.releaseAndGetString());
}

void saveRosCameraInfo(const std::filesystem::path& path, const CameraCalibration& c,
                       const std::string& cameraName) {
    const CameraIntrinsics& in = c.intrinsics;
    if (!in.isValid())
        throw FileError(path.string(),
                        "refusing to write invalid intrinsics (size or focal length)");
    std::ostringstream s;
    s << std::setprecision(17);
    auto mat = [&s](const char* name, int rows, int cols, const std::vector<double>& data) {
        s << name << ":\n  rows: " << rows << "\n  cols: " << cols << "\n  data: [";
        for (size_t i = 0; i < data.size(); ++i) s << (i ? ", " : "") << data[i];
        s << "]\n";
    };
    // camera_calibration_parsers' format. ROS names the fish-eye model "equidistant".
    s << "image_width: " << in.width << "\nimage_height: " << in.height << "\n";
    s << "camera_name: " << cameraName << "\n";
    mat("camera_matrix", 3, 3, {in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1});
    const bool fisheye = in.model == DistortionModel::KannalaBrandt;
    s << "distortion_model: " << (fisheye ? "equidistant" : "plumb_bob") << "\n";
    std::vector<double> d = in.distortion;
    d.resize(fisheye ? 4 : 5, 0.0);
    mat("distortion_coefficients", 1, int(d.size()), d);
    mat("rectification_matrix", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1});
    mat("projection_matrix", 3, 4, {in.fx, 0, in.cx, 0, 0, in.fy, in.cy, 0, 0, 0, 1, 0});
    writeFileAtomically(path, s.str());
}

}  // namespace mirage
