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
        d.found = true;
        return d;
    }
    const cv::Size pattern(chessboard_.cols, chessboard_.rows);
    std::vector<cv::Point2f> corners;
    // The classic detector is ~100x faster than the sector-based one (1 ms against 0.4 s at
    // 640x480 here) and, refined with cornerSubPix, as accurate on sharp views
    // (tests/calibration: < 0.1 px RMS on rendered boards). The sector-based detector copes
    // better with blur and uneven light: it is the fallback.
    bool found = cv::findChessboardCorners(
        grey, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
    if (found) {
        // Refinement window: about a third of the smallest corner spacing, so it never reaches
        // the next corner on small or steeply tilted boards.
        double spacing = 1e9;
        for (int r = 0; r < pattern.height; ++r)
            for (int c = 0; c + 1 < pattern.width; ++c)
                spacing =
                    std::min(spacing, double(cv::norm(corners[size_t(r * pattern.width + c)] -
                                                      corners[size_t(r * pattern.width + c + 1)])));
        const int half = std::clamp(int(spacing / 3), 2, 7);
        cv::cornerSubPix(
            grey, corners, {half, half}, {-1, -1},
            cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.001));
    } else {
        found = cv::findChessboardCornersSB(grey, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
    }
    if (!found || corners.size() != size_t(pattern.area())) {
        d.reason = fmt::format(
            "no {}x{} chessboard found (the whole board must be visible, "
            "with its white margin)",
            chessboard_.cols, chessboard_.rows);
        return d;
    }
    d.found = true;
    d.view.imagePoints = corners;
    d.view.boardPoints = allPoints_;
    return d;
}

}  // namespace mirage::calib
