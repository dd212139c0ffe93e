#include "calibration/CalibrationTarget.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <regex>

#include <fmt/format.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "tracking/Detector.h"

namespace mirage::calib {

struct CalibrationTarget::TagState {
    tracking::Board board;
    // Full resolution quad search: calibration wants every tag, small ones included, and the
    // corners as exact as the detector's edge refinement makes them.
    std::unique_ptr<tracking::Detector> detector;
    // Per tag id: its 4 detection corners in the board plane frame (metres, z = 0), in
    // libapriltag's corner order.
    std::map<int, std::array<cv::Point3f, 4>> cornersInBoard;
};

struct CalibrationTarget::CharucoState {
    cv::Ptr<cv::aruco::Dictionary> dictionary;
    cv::Ptr<cv::aruco::CharucoBoard> board;
    cv::Ptr<cv::aruco::DetectorParameters> parameters;
};

namespace {

// cv::aruco's predefined dictionaries by name (the names of cv::aruco::PREDEFINED_DICTIONARY_NAME).
const std::map<std::string, cv::aruco::PREDEFINED_DICTIONARY_NAME>& arucoDictionaries() {
    using namespace cv::aruco;
    static const std::map<std::string, PREDEFINED_DICTIONARY_NAME> names = {
        {"DICT_4X4_50", DICT_4X4_50},
        {"DICT_4X4_100", DICT_4X4_100},
        {"DICT_4X4_250", DICT_4X4_250},
        {"DICT_4X4_1000", DICT_4X4_1000},
        {"DICT_5X5_50", DICT_5X5_50},
        {"DICT_5X5_100", DICT_5X5_100},
        {"DICT_5X5_250", DICT_5X5_250},
        {"DICT_5X5_1000", DICT_5X5_1000},
        {"DICT_6X6_50", DICT_6X6_50},
        {"DICT_6X6_100", DICT_6X6_100},
        {"DICT_6X6_250", DICT_6X6_250},
        {"DICT_6X6_1000", DICT_6X6_1000},
        {"DICT_7X7_50", DICT_7X7_50},
        {"DICT_7X7_100", DICT_7X7_100},
        {"DICT_7X7_250", DICT_7X7_250},
        {"DICT_7X7_1000", DICT_7X7_1000},
        {"DICT_ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL},
        {"DICT_APRILTAG_16h5", DICT_APRILTAG_16h5},
        {"DICT_APRILTAG_25h9", DICT_APRILTAG_25h9},
        {"DICT_APRILTAG_36h10", DICT_APRILTAG_36h10},
        {"DICT_APRILTAG_36h11", DICT_APRILTAG_36h11},
    };
    return names;
}

// ChArUco corners needed in one view: fewer than this (or all on one line) constrain a homography
// poorly, and OpenCV's own ChArUco calibration asks for at least 4 per view.
constexpr size_t kMinCharucoCorners = 6;

// Chessboard corners refined to sub-pixel saddle points, each with its own window.
struct CornerRefinement {
    std::vector<cv::Point2f> corners;  // all corners, refined where it converged
    std::vector<size_t> kept;          // indices whose refinement converged
};

// The image in linear light (sRGB-decoded, 0..255 as float). Corners are refined there: a camera
// sums light linearly over a pixel and then encodes it, so an edge's encoded profile is
// asymmetric and cornerSubPix's gradient condition shifts toward one side; decoded, the profile
// is symmetric again (rendered fish-eye views at 70 degrees off-axis: 0.16 -> 0.11 px RMS from
// the true corners).
cv::Mat linearLight(const cv::Mat& grey) {
    cv::Mat lut(1, 256, CV_32F);
    for (int i = 0; i < 256; ++i) lut.at<float>(i) = 255.0f * srgbToLinear(float(i) / 255.0f);
    cv::Mat out;
    cv::LUT(grey, lut, out);
    return out;
}

CornerRefinement refineChessboardCorners(const cv::Mat& grey, cv::Size pattern,
                                         const std::vector<cv::Point2f>& detected) {
    CornerRefinement out;
    out.corners = detected;
    const cv::Mat linear = linearLight(grey);
    const cv::TermCriteria criteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 0.001);
    for (int r = 0; r < pattern.height; ++r)
        for (int c = 0; c < pattern.width; ++c) {
            const size_t i = size_t(r * pattern.width + c);
            // Local spacing: the nearest of the 8 grid neighbours (rows, columns and diagonals),
            // in the square window's own (Chebyshev) metric, so the window never reaches a
            // neighbouring corner whichever way the board is turned or the lens squeezes it.
            double spacing = 1e9;
            for (int dr = -1; dr <= 1; ++dr)
                for (int dc = -1; dc <= 1; ++dc) {
                    const int rr = r + dr, cc = c + dc;
                    if ((dr == 0 && dc == 0) || rr < 0 || cc < 0 || rr >= pattern.height ||
                        cc >= pattern.width)
                        continue;
                    const cv::Point2f d = detected[size_t(rr * pattern.width + cc)] - detected[i];
                    spacing = std::min(spacing, double(std::max(std::abs(d.x), std::abs(d.y))));
                }
            // 0.3 x the spacing: large enough to average pixel noise, small enough that edges
            // curved by a fish-eye stay nearly straight inside it (measured on rendered
            // 180-degree views: best at 0.5 x spacing 50 degrees off-axis, 0.3 x at 70 degrees),
            // and inside the image.
            const cv::Point2f& q = detected[i];
            const double border =
                std::min({double(q.x), double(q.y), grey.cols - 1.0 - q.x, grey.rows - 1.0 - q.y});
            const int half = std::clamp(std::min(int(0.3 * spacing), int(border) - 2), 2, 6);
            std::vector<cv::Point2f> p{detected[i]};
            cv::cornerSubPix(linear, p, {half, half}, {-1, -1}, criteria);
            // Converged: a second run from the result stays put, and the result is still this
            // corner (it did not slide toward a neighbour's saddle or off the board).
            std::vector<cv::Point2f> again = p;
            cv::cornerSubPix(linear, again, {half, half}, {-1, -1}, criteria);
            const double settle = cv::norm(again[0] - p[0]);
            const double moved = cv::norm(p[0] - detected[i]);
            if (!(settle < 0.05) || !(moved < 0.5 * spacing)) continue;
            out.corners[i] = p[0];
            out.kept.push_back(i);
        }
    return out;
}

// Why no whole chessboard was found: a smaller part of the pattern that a detector does find
// means a board is there, but partly outside the image or too distorted for the detectors.
std::string whyNoChessboard(const cv::Mat& grey, cv::Size pattern) {
    std::vector<cv::Point2f> corners;
    cv::Size part;
    bool partFound = false;
    for (const cv::Size p : {cv::Size(pattern.width - 2, pattern.height - 2), cv::Size(4, 3)}) {
        if (p.width < 3 || p.height < 3 || p.width == p.height || partFound) continue;
        part = p;
        partFound = cv::findChessboardCorners(
            grey, p, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
    }
    if (!partFound && pattern.width > 4 && pattern.height > 3) {
        part = {4, 3};
        partFound = cv::findChessboardCornersSB(grey, part, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
    }
    if (!partFound)
        return fmt::format(
            "no {}x{} chessboard found (the whole board must be visible, with its white "
            "margin)",
            pattern.width, pattern.height);
    // The part's corner spacing, and its distance from the image border.
    double spacing = 1e9, border = 1e9;
    for (size_t i = 0; i < corners.size(); ++i) {
        const auto& p = corners[i];
        border = std::min(
            {border, double(p.x), double(p.y), grey.cols - 1.0 - p.x, grey.rows - 1.0 - p.y});
        if ((i + 1) % size_t(part.width) != 0)
            spacing = std::min(spacing, double(cv::norm(corners[i + 1] - p)));
    }
    if (border < 2.5 * spacing)
        return fmt::format(
            "a chessboard is visible, but not all of its {}x{} inner corners: part of it (or of "
            "its white margin) is outside the image; move it inward",
            pattern.width, pattern.height);
    return fmt::format(
        "a chessboard is visible ({}x{} of its corners found), but the detectors cannot follow "
        "the whole {}x{} pattern: it is too distorted (near a fish-eye's rim), too steeply "
        "tilted or too small; bring it closer, turn it to face the camera, or use a board with "
        "fewer, larger squares",
        part.width, part.height, pattern.width, pattern.height);
}

}  // namespace

CalibrationTarget::CalibrationTarget(CalibrationTarget&&) noexcept = default;
CalibrationTarget& CalibrationTarget::operator=(CalibrationTarget&&) noexcept = default;
CalibrationTarget::~CalibrationTarget() = default;

CalibrationTarget CalibrationTarget::chessboard(const ChessboardGeometry& g) {
    if (g.cols < 2 || g.rows < 2 || !(g.squareMetres > 0) || !std::isfinite(g.squareMetres))
        throw Error(
            fmt::format("chessboard {}x{} with {} m squares: need at least 2x2 inner "
                        "corners and a positive square size",
                        g.cols, g.rows, g.squareMetres));
    if (g.cols == g.rows)
        throw Error(fmt::format(
            "chessboard {}x{}: a square board's orientation is ambiguous (OpenCV may number its "
            "corners rotated by 90 degrees between views); use a board with different counts",
            g.cols, g.rows));
    CalibrationTarget t;
    t.kind_ = Kind::Chessboard;
    t.chessboard_ = g;
    t.allPoints_ = g.corners();
    return t;
}

CalibrationTarget CalibrationTarget::tagBoard(const tracking::Board& board) {
    if (board.tags.empty()) throw Error("tag board has no tags");
    if (!board.isPlanar())
        throw Error(
            "calibration needs a planar board (all tags in one plane); this board's tags "
            "lie on several planes");
    CalibrationTarget t;
    t.kind_ = Kind::TagBoard;
    // The board plane frame: the printed sheet's frame when there is one (the page, z = 0),
    // else the first tag's frame (same plane, since the board is planar).
    t.T_world_board_ = board.sheet ? board.sheet->T_world_sheet : board.tags.front().T_world_tag;
    const Pose T_board_world = t.T_world_board_.inverse();
    t.tags_ = std::make_unique<TagState>();
    t.tags_->board = board;
    tracking::DetectorOptions opts;
    opts.family = board.family;
    opts.decimate = 1.0f;
    t.tags_->detector = std::make_unique<tracking::Detector>(opts);
    for (const auto& tag : board.tags) {
        std::array<cv::Point3f, 4> corners;
        const auto world = tag.cornersInWorld();
        for (int c = 0; c < 4; ++c) {
            const glm::dvec3 p = T_board_world * world[size_t(c)];
            MR_CHECK(std::abs(p.z) < 1e-5, "planar board corner off its plane");
            corners[size_t(c)] = cv::Point3f(float(p.x), float(p.y), 0.f);
            t.allPoints_.push_back(corners[size_t(c)]);
        }
        t.tags_->cornersInBoard[tag.id] = corners;
    }
    return t;
}

CalibrationTarget CalibrationTarget::charuco(const CharucoGeometry& g) {
    const auto& dicts = arucoDictionaries();
    const auto dict = dicts.find(g.dictionary);
    if (dict == dicts.end()) {
        std::string known;
        for (const auto& [name, id] : dicts) known += (known.empty() ? "" : ", ") + name;
        throw Error(
            fmt::format("ChArUco board: unknown dictionary '{}' (known: {})", g.dictionary, known));
    }
    if (g.squaresX < 3 || g.squaresY < 3)
        throw Error(
            fmt::format("ChArUco board {}x{}: need at least 3x3 squares", g.squaresX, g.squaresY));
    if (!(g.squareMetres > 0) || !std::isfinite(g.squareMetres) || !(g.markerMetres > 0) ||
        !(g.markerMetres < g.squareMetres))
        throw Error(fmt::format(
            "ChArUco board: square {} m and marker {} m: both must be positive and the marker "
            "smaller than the square (e.g. charuco:5x7:0.04:0.02)",
            g.squareMetres, g.markerMetres));
    CalibrationTarget t;
    t.kind_ = Kind::Charuco;
    t.charucoGeometry_ = g;
    t.charuco_ = std::make_unique<CharucoState>();
    t.charuco_->dictionary = cv::aruco::getPredefinedDictionary(dict->second);
    const int markers = (g.squaresX * g.squaresY) / 2;
    if (markers > t.charuco_->dictionary->bytesList.rows)
        throw Error(fmt::format("ChArUco board {}x{} needs {} markers; {} has only {}", g.squaresX,
                                g.squaresY, markers, g.dictionary,
                                t.charuco_->dictionary->bytesList.rows));
    t.charuco_->board =
        cv::aruco::CharucoBoard::create(g.squaresX, g.squaresY, float(g.squareMetres),
                                        float(g.markerMetres), t.charuco_->dictionary);
    t.charuco_->parameters = cv::aruco::DetectorParameters::create();
    // Marker corners only seed the ChArUco corners, which interpolateCornersCharuco refines on
    // the chessboard's saddle points: refining the markers' own corners too adds nothing.
    t.charuco_->parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
    for (const cv::Point3f& p : t.charuco_->board->chessboardCorners) t.allPoints_.push_back(p);
    return t;
}

cv::Mat CalibrationTarget::drawCharuco(int pixelsPerSquare, int marginPx) const {
    if (kind_ != Kind::Charuco) throw Error("drawCharuco: this target is not a ChArUco board");
    const auto& g = charucoGeometry_;
    cv::Mat image;
    charuco_->board->draw(
        {g.squaresX * pixelsPerSquare + 2 * marginPx, g.squaresY * pixelsPerSquare + 2 * marginPx},
        image, marginPx, 1);
    return image;
}

CalibrationTarget CalibrationTarget::parse(const std::string& spec) {
    static const std::regex chess(R"(chessboard:(\d+)x(\d+):([0-9]*\.?[0-9]+(?:[eE][-+]?\d+)?))");
    std::smatch m;
    if (std::regex_match(spec, m, chess))
        return chessboard({std::stoi(m[1]), std::stoi(m[2]), std::stod(m[3])});
    static const std::regex charucoSpec(
        R"(charuco:(\d+)x(\d+):([0-9]*\.?[0-9]+(?:[eE][-+]?\d+)?):([0-9]*\.?[0-9]+(?:[eE][-+]?\d+)?)(?::(\w+))?)");
    if (std::regex_match(spec, m, charucoSpec)) {
        CharucoGeometry g{std::stoi(m[1]), std::stoi(m[2]), std::stod(m[3]), std::stod(m[4])};
        if (m[5].matched) g.dictionary = m[5];
        return charuco(g);
    }
    if (spec.rfind("charuco", 0) == 0)
        throw Error(fmt::format(
            "--board '{}': expected charuco:SQUARESXxSQUARESY:SQUARE_METRES:MARKER_METRES[:DICT] "
            "counting SQUARES, e.g. charuco:5x7:0.04:0.02:DICT_6X6_250",
            spec));
    if (spec.rfind("chessboard", 0) == 0)
        throw Error(
            fmt::format("--board '{}': expected chessboard:COLSxROWS:SQUARE_METRES with "
                        "the INNER corner counts, e.g. chessboard:9x6:0.025",
                        spec));
    return tagBoard(tracking::Board::load(spec));
}

std::string CalibrationTarget::description() const {
    if (kind_ == Kind::Chessboard)
        return fmt::format("chessboard {}x{} inner corners, {:.1f} mm squares", chessboard_.cols,
                           chessboard_.rows, 1000 * chessboard_.squareMetres);
    if (kind_ == Kind::Charuco)
        return fmt::format("ChArUco {}x{} squares, {:.1f} mm squares, {:.1f} mm {} markers",
                           charucoGeometry_.squaresX, charucoGeometry_.squaresY,
                           1000 * charucoGeometry_.squareMetres,
                           1000 * charucoGeometry_.markerMetres, charucoGeometry_.dictionary);
    return fmt::format("{} board with {} tags", tags_->board.family, tags_->board.tags.size());
}

bool CalibrationTarget::quickCheck(const cv::Mat& grey) const {
    if (kind_ != Kind::Chessboard) return true;
    cv::Mat small = grey;
    const double scale = std::min(1.0, 640.0 / std::max(grey.cols, grey.rows));
    if (scale < 1.0) cv::resize(grey, small, cv::Size(), scale, scale, cv::INTER_AREA);
    std::vector<cv::Point2f> corners;
    return cv::findChessboardCorners(
        small, {chessboard_.cols, chessboard_.rows}, corners,
        cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
}

TargetDetection CalibrationTarget::detect(const cv::Mat& image, const std::string& name) const {
    if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
        throw Error(fmt::format("{}: expected an 8-bit grey or BGR image", name));
    cv::Mat grey = image;
    if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    TargetDetection d;
    d.view.name = name;
    if (kind_ == Kind::Charuco) {
        // Markers first, then the chessboard corners between them: interpolated through the
        // markers' homographies and refined to sub-pixel saddle points. Partial views are fine.
        std::vector<std::vector<cv::Point2f>> markerCorners, rejected;
        std::vector<int> markerIds;
        cv::aruco::detectMarkers(grey, charuco_->dictionary, markerCorners, markerIds,
                                 charuco_->parameters, rejected);
        if (markerIds.empty()) {
            d.reason = "no ChArUco markers found";
            return d;
        }
        // Markers the detector missed, looked for again where the board says they must be.
        cv::aruco::refineDetectedMarkers(grey, charuco_->board, markerCorners, markerIds, rejected);
        std::vector<cv::Point2f> corners;
        std::vector<int> ids;
        cv::aruco::interpolateCornersCharuco(markerCorners, markerIds, grey, charuco_->board,
                                             corners, ids);
        if (ids.size() < kMinCharucoCorners) {
            d.reason = fmt::format("{} ChArUco corners found (at least {} needed)", ids.size(),
                                   kMinCharucoCorners);
            return d;
        }
        // OpenCV 4.6's ChArUco refinement returns corners in a pixel-CORNER convention (it calls
        // cornerSubPix on p - 0.5 and adds 0.5 back), half a pixel off the pixel-CENTRE
        // convention of everything else here (cv::calibrateCamera, cv::projectPoints,
        // docs/conventions.md). Measured on rendered boards: +0.50 px in x and y in every view
        // (tests/calibration/Charuco_test.cpp), which would bias the principal point.
        const cv::Point2f toPixelCentres(0.5f, 0.5f);
        for (size_t i = 0; i < ids.size(); ++i) {
            d.view.imagePoints.push_back(corners[i] - toPixelCentres);
            d.view.boardPoints.push_back(charuco_->board->chessboardCorners[size_t(ids[i])]);
        }
        d.view.detector = "charuco";
        d.found = true;
        return d;
    }
    if (kind_ == Kind::TagBoard) {
        // Tags of this board only (ids it lists); each gives its 4 corners. Partial views are
        // fine, unlike a chessboard: the board may leave the image.
        for (const auto& det : tags_->detector->detect(grey)) {
            const auto it = tags_->cornersInBoard.find(det.id);
            if (it == tags_->cornersInBoard.end()) continue;
            for (size_t c = 0; c < 4; ++c) {
                d.view.imagePoints.emplace_back(float(det.corners[c].x), float(det.corners[c].y));
                d.view.boardPoints.push_back(it->second[c]);
            }
        }
        const size_t tags = d.view.imagePoints.size() / 4;
        if (tags < 2) {
            d.reason = fmt::format("{} of the board's tags detected (at least 2 needed)", tags);
            d.view.imagePoints.clear();
            d.view.boardPoints.clear();
            return d;
        }
        d.view.detector = "tags";
        d.found = true;
        return d;
    }
    const cv::Size pattern(chessboard_.cols, chessboard_.rows);
    std::vector<cv::Point2f> corners;
    // The classic detector is ~100x faster than the sector-based one (1 ms against 0.4 s at
    // 640x480 here). The sector-based detector copes better with blur, uneven light and strong
    // fish-eye distortion: it is the fallback. Both detectors' corners are refined the same way
    // (refineChessboardCorners): the sector-based one's own corners are 0.2-0.45 px off on
    // rendered fish-eye views, 0.06-0.12 px once refined.
    std::string detector = "classic";
    bool found = cv::findChessboardCorners(
        grey, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
    if (!found) {
        detector = "sector-based";
        found = cv::findChessboardCornersSB(grey, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
    }
    if (!found || corners.size() != size_t(pattern.area())) {
        d.reason = whyNoChessboard(grey, pattern);
        return d;
    }
    const CornerRefinement refined = refineChessboardCorners(grey, pattern, corners);
    if (refined.kept.size() < 4) {
        d.reason = fmt::format(
            "{}x{} chessboard found, but the sub-pixel refinement of only {} of its corners "
            "converged (the board is too blurred or too small in the image)",
            chessboard_.cols, chessboard_.rows, refined.kept.size());
        return d;
    }
    d.found = true;
    d.view.detector = detector;
    d.view.unrefinedCorners = int(corners.size() - refined.kept.size());
    for (size_t i : refined.kept) {
        d.view.imagePoints.push_back(refined.corners[i]);
        d.view.boardPoints.push_back(allPoints_[i]);
    }
    return d;
}

}  // namespace mirage::calib
