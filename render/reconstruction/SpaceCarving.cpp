#include "render/reconstruction/SpaceCarving.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"

namespace mirage::reconstruction {
namespace {

enum PixelClass : uint8_t { SaysNothing = 0, SeesTable = 1, SeesAbove = 2 };

// One frame as the carving reads it: undistorted pinhole, linear RGB, blurred.
struct CarvingView {
    cv::Mat rgb;         // CV_32FC3 linear
    cv::Mat pixelClass;  // CV_8U PixelClass, filled in step 2
    glm::dmat3 R_camera_world{1.0};
    glm::dvec3 centre{0.0};  // camera centre, world
    double fx = 0, fy = 0, cx = 0, cy = 0;

    // Pixel (x right, y down) of a world point; false behind the camera or outside the image.
    bool project(const glm::dvec3& world, double& x, double& y) const {
        const glm::dvec3 p = R_camera_world * (world - centre);
        if (p.z <= 1e-6) return false;
        x = fx * p.x / p.z + cx, y = fy * p.y / p.z + cy;
        return x >= 0 && y >= 0 && x <= rgb.cols - 1 && y <= rgb.rows - 1;
    }
};

std::vector<CarvingView> prepareViews(const Footage& f, const CarvingOptions& o) {
    const CameraIntrinsics& K = f.camera;
    const cv::Matx33d camera(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
    bool distorted = false;
    for (double d : K.distortion) distorted |= d != 0.0;
    cv::Mat mapX, mapY;
    if (distorted)  // the same pinhole without the Brown-Conrady distortion
        cv::initUndistortRectifyMap(camera, K.distortion, cv::noArray(), camera,
                                    cv::Size(K.width, K.height), CV_32FC1, mapX, mapY);
    cv::Mat lut(1, 256, CV_32F);
    for (int i = 0; i < 256; ++i) lut.at<float>(i) = srgbToLinear(i / 255.0f);
    const size_t step = std::max<size_t>(
        1, (f.frames.size() + size_t(o.maxFrames) - 1) / size_t(std::max(1, o.maxFrames)));
    std::vector<CarvingView> views;
    for (size_t i = 0; i < f.frames.size(); i += step) {
        const PosedFrame& frame = f.frames[i];
        CarvingView v;
        cv::Mat bgr = frame.bgr;
        if (distorted) cv::remap(frame.bgr, bgr, mapX, mapY, cv::INTER_LINEAR);
        cv::Mat rgb8, rgbF;
        cv::cvtColor(bgr, rgb8, cv::COLOR_BGR2RGB);
        rgb8.convertTo(rgbF, CV_32FC3);
        rgbF.forEach<cv::Vec3f>([&](cv::Vec3f& c, const int*) {
            for (int ch = 0; ch < 3; ++ch) c[ch] = lut.at<float>(int(c[ch]));
        });
        const double sigma = o.blurPixels * K.width / 320.0;
        if (sigma > 0) cv::GaussianBlur(rgbF, rgbF, cv::Size(), sigma);
        v.rgb = rgbF;
        v.R_camera_world = glm::transpose(frame.T_world_camera.rotationMatrix());
        v.centre = frame.T_world_camera.translation;
        v.fx = K.fx, v.fy = K.fy, v.cx = K.cx, v.cy = K.cy;
        views.push_back(std::move(v));
    }
    return views;
}

cv::Vec3f sampleBilinear(const cv::Mat& rgb, double x, double y) {
    const int x0 = std::min(int(x), rgb.cols - 2), y0 = std::min(int(y), rgb.rows - 2);
    const float ax = float(x - x0), ay = float(y - y0);
    const cv::Vec3f* r0 = rgb.ptr<cv::Vec3f>(y0);
    const cv::Vec3f* r1 = rgb.ptr<cv::Vec3f>(y0 + 1);
    return (r0[x0] * (1 - ax) + r0[x0 + 1] * ax) * (1 - ay) +
           (r1[x0] * (1 - ax) + r1[x0 + 1] * ax) * ay;
}

cv::Vec2f chromaOf(const cv::Vec3f& c) {
    const float s = c[0] + c[1] + c[2];
    return s > 1e-6f ? cv::Vec2f(c[0] / s, c[1] / s) : cv::Vec2f(1 / 3.f, 1 / 3.f);
}

float median(std::vector<float>& v) {
    auto mid = v.begin() + long(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

// The q-quantile (0..1, nearest rank below) of a non-empty v; reorders v.
float quantile(std::vector<float>& v, double q) {
    auto at = v.begin() + long(std::clamp(q, 0.0, 1.0) * double(v.size() - 1));
    std::nth_element(v.begin(), at, v.end());
    return *at;
}

// What the table and the board look like: the chromaticity (r, g over r+g+b) and brightness
// (r+g+b, linear) of the board's paper and of the table in a ring 2-20 cm around the board.
struct PlaneReference {
    cv::Vec2f tableChroma{0, 0}, boardChroma{0, 0};
    float tableBright = 0, boardBright = 0;
    bool valid = false;
};

bool onBoard(const BoardPlane& plane, double u, double v, double grow) {
    return std::abs(u) <= plane.halfU + grow && std::abs(v) <= plane.halfV + grow;
}

// Is a colour seen at plane point (u, v) the table's (or the board's) there?
bool looksLikeTable(const cv::Vec3f& c, bool board, const PlaneReference& r,
                    const CarvingOptions& o) {
    const float s = c[0] + c[1] + c[2];
    const cv::Vec2f k = chromaOf(c);
    if (board) return cv::norm(k - r.boardChroma) <= o.boardChroma || s < 0.5f * r.boardBright;
    return cv::norm(k - r.tableChroma) <= o.tableChroma &&
           s >= float(o.minTableBrightness) * r.tableBright;
}

// Step 1a: each cell's colour over the frames that see it (CV_32FC3), how many see it, and how
// many of those see the table's colour there. Without a reference: the median of all; with
// one: the median of the table-coloured samples (a cell behind an object is hidden in most
// frames, but the few that see it see the table).
void planeColour(const std::vector<CarvingView>& views, const BoardPlane& plane,
                 const PlaneReference* ref, const CarvingOptions& o, PlaneAppearance& a,
                 cv::Mat& seenBy, cv::Mat& tableSeenBy) {
    const int n = a.colour.rows;
    seenBy = cv::Mat(n, n, CV_32S, cv::Scalar(0));
    tableSeenBy = cv::Mat(n, n, CV_32S, cv::Scalar(0));
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& rows) {
        std::vector<float> ch[3];
        for (int y = rows.start; y < rows.end; ++y)
            for (int x = 0; x < n; ++x) {
                const double u = a.u0 + (x + 0.5) * a.cell, v = a.v0 + (y + 0.5) * a.cell;
                const bool board = onBoard(plane, u, v, 0.0);
                const glm::dvec3 w = plane.toWorld({u, v, 0.0});
                for (auto& c : ch) c.clear();
                int seen = 0;
                for (const CarvingView& view : views) {
                    double px, py;
                    if (!view.project(w, px, py)) continue;
                    ++seen;
                    const cv::Vec3f c = sampleBilinear(view.rgb, px, py);
                    if (ref && !looksLikeTable(c, board, *ref, o)) continue;
                    for (int k = 0; k < 3; ++k) ch[k].push_back(c[k]);
                }
                seenBy.at<int>(y, x) = seen;
                tableSeenBy.at<int>(y, x) = int(ch[0].size());
                if (ch[0].empty()) continue;
                a.colour.at<cv::Vec3f>(y, x) =
                    cv::Vec3f(median(ch[0]), median(ch[1]), median(ch[2]));
                if (ref)
                    a.diffuseColour.at<cv::Vec3f>(y, x) = cv::Vec3f(
                        quantile(ch[0], o.diffuseQuantile), quantile(ch[1], o.diffuseQuantile),
                        quantile(ch[2], o.diffuseQuantile));
            }
    });
}

// Step 1b: the references, from the plain medians.
PlaneReference planeReference(const BoardPlane& plane, const cv::Mat& seenBy,
                              const CarvingOptions& o, const PlaneAppearance& a) {
    const int n = a.colour.rows;
    std::vector<float> tr, tg, tb, br, bg, bb;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            if (seenBy.at<int>(y, x) < o.minFramesPerCell) continue;
            const double u = a.u0 + (x + 0.5) * a.cell, v = a.v0 + (y + 0.5) * a.cell;
            const cv::Vec3f c = a.colour.at<cv::Vec3f>(y, x);
            const cv::Vec2f k = chromaOf(c);
            const float s = c[0] + c[1] + c[2];
            if (onBoard(plane, u, v, 0.0))
                br.push_back(k[0]), bg.push_back(k[1]), bb.push_back(s);
            else if (onBoard(plane, u, v, 0.2) && !onBoard(plane, u, v, 0.02))
                tr.push_back(k[0]), tg.push_back(k[1]), tb.push_back(s);
        }
    PlaneReference r;
    if (tr.empty() || br.empty()) return r;
    r.tableChroma = {median(tr), median(tg)};
    r.boardChroma = {median(br), median(bg)};
    r.tableBright = median(tb), r.boardBright = median(bb);
    r.valid = true;
    return r;
}

// Step 1c: which cells are the table (or the board), which are covered, which are off it.
void classifyCells(const BoardPlane& plane, const cv::Mat& seenBy, const cv::Mat& tableSeenBy,
                   const CarvingOptions& o, PlaneAppearance& a) {
    const int n = a.colour.rows;
    a.kind = cv::Mat(n, n, CV_8U, cv::Scalar(PlaneAppearance::Unknown));
    cv::Mat tableLike(n, n, CV_8U, cv::Scalar(0));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const int seen = seenBy.at<int>(y, x), table = tableSeenBy.at<int>(y, x);
            if (seen < o.minFramesPerCell) continue;
            a.kind.at<uchar>(y, x) = PlaneAppearance::Covered;
            tableLike.at<uchar>(y, x) =
                table >= o.minPlaneVotes && table >= o.minTableShare * seen ? 255 : 0;
        }
    // The table: the table-coloured region that holds most of the board.
    cv::Mat labels;
    const int count = cv::connectedComponents(tableLike, labels, 8, CV_32S);
    std::vector<int> boardCells(size_t(count), 0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            if (onBoard(plane, a.u0 + (x + 0.5) * a.cell, a.v0 + (y + 0.5) * a.cell, 0.0))
                ++boardCells[size_t(labels.at<int>(y, x))];
    int table = 0;
    for (int l = 1; l < count; ++l)
        if (boardCells[size_t(l)] > boardCells[size_t(table)]) table = l;
    if (table == 0) {
        a.kind.setTo(PlaneAppearance::Unknown);
        return;
    }
    // The table's outline: the convex hull of that region. Inside it, a cell of another colour
    // is covered (a footprint, or the table hidden behind an object in most views: objects at
    // the table's edge hide the table up to the edge); outside it lies the floor or a wall.
    std::vector<cv::Point> points, hull;
    cv::findNonZero(labels == table, points);
    cv::convexHull(points, hull);
    cv::Mat inside(n, n, CV_8U, cv::Scalar(0));
    cv::fillConvexPoly(inside, hull, cv::Scalar(255));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            uchar& k = a.kind.at<uchar>(y, x);
            if (!inside.at<uchar>(y, x) || k == PlaneAppearance::Unknown)
                k = PlaneAppearance::Unknown;
            else
                k = tableLike.at<uchar>(y, x) ? PlaneAppearance::Table : PlaneAppearance::Covered;
        }
}

// Step 2: per pixel, does its ray show the table where it meets the plane?
void classifyPixels(const BoardPlane& plane, const PlaneAppearance& a, const CarvingOptions& o,
                    CarvingView& v) {
    PlaneReference ref;
    ref.tableChroma = a.tableChroma, ref.boardChroma = a.boardChroma;
    ref.tableBright = a.tableBrightness, ref.boardBright = a.boardBrightness;
    const glm::dmat3 R_world_camera = glm::transpose(v.R_camera_world);
    const double hC = glm::dot(v.centre - plane.point, plane.normal);
    v.pixelClass = cv::Mat(v.rgb.size(), CV_8U, cv::Scalar(SaysNothing));
    const int n = a.colour.rows;
    cv::parallel_for_(cv::Range(0, v.rgb.rows), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y)
            for (int x = 0; x < v.rgb.cols; ++x) {
                const glm::dvec3 d =
                    R_world_camera * glm::dvec3((x - v.cx) / v.fx, (y - v.cy) / v.fy, 1.0);
                const double dn = glm::dot(d, plane.normal);
                if (dn >= -1e-9 || hC <= 0) continue;  // the ray never meets the plane
                const glm::dvec3 uvh = plane.toPlane(v.centre - (hC / dn) * d);
                const double gx = (uvh.x - a.u0) / a.cell - 0.5, gy = (uvh.y - a.v0) / a.cell - 0.5;
                const int cx = int(std::lround(gx)), cy = int(std::lround(gy));
                if (cx < 0 || cy < 0 || cx >= n || cy >= n) continue;
                const uchar kind = a.kind.at<uchar>(cy, cx);
                const cv::Vec3f c = v.rgb.at<cv::Vec3f>(y, x);
                if (kind == PlaneAppearance::Unknown) {
                    // Off the table: a pixel that shows what most frames see through that cell
                    // of the plane (the floor, a wall) sees past everything on the table; any
                    // other colour says nothing (a textured floor differs from view to view).
                    const cv::Vec3f far = a.colour.at<cv::Vec3f>(cy, cx);
                    if (a.seenBy.at<int>(cy, cx) >= o.minFramesPerCell &&
                        cv::norm(c - far) <= o.colourFloor + o.colourTolerance * cv::norm(far))
                        v.pixelClass.at<uchar>(y, x) = SeesTable;
                    continue;
                }
                if (kind == PlaneAppearance::Covered) {
                    v.pixelClass.at<uchar>(y, x) =
                        looksLikeTable(c, onBoard(plane, uvh.x, uvh.y, 0.0), ref, o) ? SeesTable
                                                                                     : SeesAbove;
                    continue;
                }
                // The table's colour there: bilinear where all four cells are the table's.
                cv::Vec3f bg = a.colour.at<cv::Vec3f>(cy, cx);
                const int x0 = int(std::floor(gx)), y0 = int(std::floor(gy));
                if (x0 >= 0 && y0 >= 0 && x0 + 1 < n && y0 + 1 < n &&
                    a.kind.at<uchar>(y0, x0) == PlaneAppearance::Table &&
                    a.kind.at<uchar>(y0, x0 + 1) == PlaneAppearance::Table &&
                    a.kind.at<uchar>(y0 + 1, x0) == PlaneAppearance::Table &&
                    a.kind.at<uchar>(y0 + 1, x0 + 1) == PlaneAppearance::Table)
                    bg = sampleBilinear(a.colour, gx, gy);
                const bool table =
                    cv::norm(c - bg) <= o.colourFloor + o.colourTolerance * cv::norm(bg);
                v.pixelClass.at<uchar>(y, x) = table ? SeesTable : SeesAbove;
            }
    });
}

// Step 3: each column's occupied run from the table up.
void carveColumns(const std::vector<CarvingView>& views, const BoardPlane& plane,
                  const CarvingOptions& o, CarvedHeights& out) {
    const PlaneAppearance& a = out.plane;
    const int n = a.kind.rows;
    out.height = cv::Mat(n, n, CV_32F, 0.0f);
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y)
            for (int x = 0; x < n; ++x) {
                if (a.kind.at<uchar>(y, x) == PlaneAppearance::Unknown) continue;
                const double u = a.u0 + (x + 0.5) * a.cell, v = a.v0 + (y + 0.5) * a.cell;
                float top = 0.0f;
                for (double h = o.startHeightM; h < o.maxHeightM; h += o.voxelM) {
                    const glm::dvec3 w = plane.toWorld({u, v, h});
                    int table = 0, above = 0;
                    for (const CarvingView& view : views) {
                        double px, py;
                        if (!view.project(w, px, py)) continue;
                        const uchar c =
                            view.pixelClass.at<uchar>(int(std::lround(py)), int(std::lround(px)));
                        table += c == SeesTable ? 1 : 0;
                        above += c == SeesAbove ? 1 : 0;
                        if (table >= o.minPlaneVotes) break;
                    }
                    const bool occupied = table < o.minPlaneVotes && above >= o.minObjectVotes &&
                                          above >= o.minObjectShare * (above + table);
                    if (!occupied) break;
                    top = float(h + 0.5 * o.voxelM);
                }
                out.height.at<float>(y, x) = top;
            }
    });
    out.occupiedColumns = cv::countNonZero(out.height > 0);
}

// Step 4: the hull's columns whose top no minObjectVotes frames see (the ray from the top to the
// camera passes under another column's top) are cut. Behind an object, seen from one side only,
// the hull runs on as a slope along the rays that graze the object's far edge: no frame sees
// that slope's top, only the object in front of it. Objects keep the tops the frames see; their
// unseen back is closed straight down (ProxyGeometry.h).
void cutUnseenTops(const std::vector<CarvingView>& views, const BoardPlane& plane,
                   const CarvingOptions& o, CarvedHeights& out) {
    const int n = out.height.rows;
    const cv::Mat height = out.height.clone();
    auto heightAt = [&](double u, double v) {
        const int x = int(std::floor((u - out.u0) / out.cell));
        const int y = int(std::floor((v - out.v0) / out.cell));
        return x < 0 || y < 0 || x >= n || y >= n ? 0.0f : height.at<float>(y, x);
    };
    std::vector<glm::dvec3> cameras;
    for (const CarvingView& v : views) cameras.push_back(plane.toPlane(v.centre));
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y)
            for (int x = 0; x < n; ++x) {
                const float top = height.at<float>(y, x);
                if (top <= 0) continue;
                const glm::dvec3 p(out.u0 + (x + 0.5) * out.cell, out.v0 + (y + 0.5) * out.cell,
                                   top);
                int seen = 0;
                for (size_t k = 0; k < views.size() && seen < o.minObjectVotes; ++k) {
                    double px, py;
                    if (!views[k].project(plane.toWorld(p), px, py)) continue;
                    const glm::dvec3 d = cameras[k] - p;
                    const double reach = std::hypot(d.x, d.y);
                    bool clear = true;
                    for (double s = 0.75 * out.cell; s < reach && clear; s += 0.5 * out.cell) {
                        const glm::dvec3 q = p + d * (s / reach);
                        if (q.z > o.maxHeightM) break;
                        clear = heightAt(q.x, q.y) <= q.z + o.voxelM;  // a step of the raster
                    }
                    seen += clear ? 1 : 0;
                }
                if (seen < o.minObjectVotes) out.height.at<float>(y, x) = 0.0f;
            }
    });
    out.occupiedColumns = cv::countNonZero(out.height > 0);
}

}  // namespace

CarvedHeights carveAbovePlane(const Footage& footage, const CarvingOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    CarvedHeights out;
    std::vector<CarvingView> views = prepareViews(footage, o);
    out.framesUsed = int(views.size());
    PlaneAppearance& a = out.plane;
    const int n = int(std::ceil(2 * o.regionHalfM / o.voxelM));
    a.cell = out.cell = o.voxelM;
    a.u0 = a.v0 = out.u0 = out.v0 = -0.5 * n * o.voxelM;
    a.colour = cv::Mat(n, n, CV_32FC3, cv::Scalar::all(0));
    a.diffuseColour = cv::Mat(n, n, CV_32FC3, cv::Scalar::all(0));
    cv::Mat& seenBy = a.seenBy;
    cv::Mat tableSeenBy;
    planeColour(views, footage.board, nullptr, o, a, seenBy, tableSeenBy);
    const PlaneReference ref = planeReference(footage.board, seenBy, o, a);
    if (ref.valid) {
        a.tableChroma = ref.tableChroma, a.boardChroma = ref.boardChroma;
        a.tableBrightness = ref.tableBright, a.boardBrightness = ref.boardBright;
        const cv::Mat allColours = a.colour.clone();
        planeColour(views, footage.board, &ref, o, a, seenBy, tableSeenBy);
        classifyCells(footage.board, seenBy, tableSeenBy, o, a);
        allColours.copyTo(a.colour, a.kind == PlaneAppearance::Unknown);
    } else {
        a.kind = cv::Mat(n, n, CV_8U, cv::Scalar(PlaneAppearance::Unknown));
    }
    for (CarvingView& v : views) classifyPixels(footage.board, a, o, v);
    carveColumns(views, footage.board, o, out);
    cutUnseenTops(views, footage.board, o, out);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

}  // namespace mirage::reconstruction
