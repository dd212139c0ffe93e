#include "render/reconstruction/ProxyGeometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"

namespace mirage::reconstruction {
namespace {

using open3d::geometry::TriangleMesh;

Eigen::Matrix4d toEigen(const glm::dmat4& m) {
    Eigen::Matrix4d e;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) e(r, c) = m[c][r];
    return e;
}

// Fuses the depth maps; returns the marching-cubes mesh with its small pieces removed.
// Depth of the working volume only: points within maxTableHalfExtentM of the board along the
// plane and between maxDepthBelowM under it and maxHeightM over it. The floor and far walls
// cost the sparse volume most of its blocks and say nothing about the table or its objects
// (where the table ends, nothing in the band agrees with the plane either way).
cv::Mat croppedDepth(const DepthView& v, const BoardPlane& plane, const GeometryOptions& o) {
    cv::Mat d = v.depth.clone();
    for (int y = 0; y < d.rows; ++y)
        for (int x = 0; x < d.cols; ++x) {
            float& z = d.at<float>(y, x);
            if (z <= 0) continue;
            const glm::dvec3 c((x - v.cx) / v.fx * z, (y - v.cy) / v.fy * z, z);
            const glm::dvec3 uvh = plane.toPlane(v.T_world_camera * c);
            if (std::abs(uvh.x) > o.maxTableHalfExtentM ||
                std::abs(uvh.y) > o.maxTableHalfExtentM || uvh.z < -o.maxDepthBelowM ||
                uvh.z > o.maxHeightM)
                z = 0;
        }
    return d;
}

std::shared_ptr<TriangleMesh> fuseDepth(const std::vector<DepthView>& views,
                                        const BoardPlane& plane, const GeometryOptions& o,
                                        FusedGeometry& out) {
    open3d::pipelines::integration::ScalableTSDFVolume volume(
        o.voxelM, o.truncationM, open3d::pipelines::integration::TSDFVolumeColorType::RGB8);
    for (const DepthView& v : views) {
        const int w = v.depth.cols, h = v.depth.rows;
        open3d::geometry::Image colour, depth;
        colour.Prepare(w, h, 3, 1);
        depth.Prepare(w, h, 1, 4);
        cv::Mat rgb(h, w, CV_8UC3, colour.data_.data());
        cv::cvtColor(v.bgr, rgb, cv::COLOR_BGR2RGB);
        cv::Mat d(h, w, CV_32F, depth.data_.data());
        croppedDepth(v, plane, o).copyTo(d);
        auto rgbd = open3d::geometry::RGBDImage::CreateFromColorAndDepth(
            colour, depth, 1.0, 1e6, /*convert_rgb_to_intensity=*/false);
        const open3d::camera::PinholeCameraIntrinsic K(w, h, v.fx, v.fy, v.cx, v.cy);
        volume.Integrate(*rgbd, K, toEigen(v.T_world_camera.inverse().matrix()));
    }
    auto mesh = volume.ExtractTriangleMesh();
    mesh->RemoveDuplicatedVertices();
    if (mesh->triangles_.empty()) return mesh;
    auto [cluster, counts, areas] = mesh->ClusterConnectedTriangles();
    std::vector<bool> drop(mesh->triangles_.size(), false);
    std::vector<bool> small(counts.size(), false);
    for (size_t c = 0; c < counts.size(); ++c) {
        small[c] = int(counts[c]) < o.minComponentTriangles;
        out.droppedComponents += small[c] ? 1 : 0;
    }
    for (size_t t = 0; t < drop.size(); ++t) drop[t] = small[size_t(cluster[t])];
    mesh->RemoveTrianglesByMask(drop);
    mesh->RemoveUnreferencedVertices();
    mesh->ComputeVertexNormals();
    out.fusedVertices = int(mesh->vertices_.size());
    out.fusedTriangles = int(mesh->triangles_.size());
    return mesh;
}

// Linear colour of a fused vertex (Open3D keeps the averaged sRGB bytes / 255).
glm::vec3 linearColour(const Eigen::Vector3d& c, double exposure) {
    return glm::vec3(srgbToLinear(float(c.x())), srgbToLinear(float(c.y())),
                     srgbToLinear(float(c.z()))) /
           float(exposure);
}

// The carving's diffuse colour of the table's cells (PlaneAppearance::diffuseColour: a low
// quantile over the frames that see the table there). The fused surface has colour only where
// the stereo found depth, averaged over the views with their glossy reflections and with
// whatever stood in front in the other views.
void useCarvedTableColour(const PlaneAppearance& a, double exposure, FusedGeometry& out) {
    const TableEstimate& t = out.table;
    for (int y = 0; y < out.tableColour.rows; ++y)
        for (int x = 0; x < out.tableColour.cols; ++x) {
            const double u = t.uMin + (x + 0.5) * out.tableCellM;
            const double v = t.vMin + (y + 0.5) * out.tableCellM;
            const int cx = int(std::floor((u - a.u0) / a.cell));
            const int cy = int(std::floor((v - a.v0) / a.cell));
            if (cx < 0 || cy < 0 || cx >= a.kind.cols || cy >= a.kind.rows ||
                a.kind.at<uchar>(cy, cx) != PlaneAppearance::Table)
                continue;
            out.tableColour.at<cv::Vec3f>(y, x) =
                a.diffuseColour.at<cv::Vec3f>(cy, cx) / float(exposure);
            out.tableObserved.at<uchar>(y, x) = 255;
        }
}

// The carving's table outline (Table and Covered cells, docs/reconstruction.md "Space carving")
// as a rectangle in plane coordinates; false when the carving found no table.
bool carvedTableRect(const CarvedHeights& carved, double& uMin, double& uMax, double& vMin,
                     double& vMax) {
    const PlaneAppearance& a = carved.plane;
    if (a.kind.empty()) return false;
    std::vector<cv::Point> cells;
    cv::findNonZero(a.kind != PlaneAppearance::Unknown, cells);
    if (cells.empty()) return false;
    const cv::Rect r = cv::boundingRect(cells);
    uMin = a.u0 + r.x * a.cell, uMax = a.u0 + (r.x + r.width) * a.cell;
    vMin = a.v0 + r.y * a.cell, vMax = a.v0 + (r.y + r.height) * a.cell;
    return true;
}

// The table's extent: the connected region of 1 cm cells holding fused surface within the plane
// band, from the cell nearest the board's centre; the board itself always belongs to it. With
// the carving, also its table outline: the fused surface has depth only where the table has
// texture or edges, the carving knows every cell the frames see the table's colour in.
void estimateTable(const TriangleMesh& mesh, const Footage& footage, const GeometryOptions& o,
                   const CarvedHeights* carved, FusedGeometry& out) {
    const BoardPlane& plane = footage.board;
    const double cell = 0.01;
    const int n = int(std::ceil(2 * o.maxTableHalfExtentM / cell));
    cv::Mat support(n, n, CV_8U, cv::Scalar(0));
    auto cellOf = [&](double u, double v) {
        return cv::Point(int(std::floor((u + o.maxTableHalfExtentM) / cell)),
                         int(std::floor((v + o.maxTableHalfExtentM) / cell)));
    };
    const cv::Rect all(0, 0, n, n);
    for (const auto& p : mesh.vertices_) {
        const glm::dvec3 uvh = plane.toPlane({p.x(), p.y(), p.z()});
        const cv::Point c = cellOf(uvh.x, uvh.y);
        if (std::abs(uvh.z) < o.planeBandM && all.contains(c)) support.at<uchar>(c) = 255;
    }
    // The board is flat by definition (tags may hide parts of it from the stereo matcher).
    cv::rectangle(support, cellOf(-plane.halfU, -plane.halfV), cellOf(plane.halfU, plane.halfV),
                  cv::Scalar(255), cv::FILLED);
    cv::Mat labels;
    cv::connectedComponents(support, labels, 8, CV_32S);
    const int board = labels.at<int>(cellOf(0, 0));
    double uMin = 1e9, uMax = -1e9, vMin = 1e9, vMax = -1e9;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            if (labels.at<int>(y, x) == board) {
                uMin = std::min(uMin, x * cell - o.maxTableHalfExtentM);
                uMax = std::max(uMax, (x + 1) * cell - o.maxTableHalfExtentM);
                vMin = std::min(vMin, y * cell - o.maxTableHalfExtentM);
                vMax = std::max(vMax, (y + 1) * cell - o.maxTableHalfExtentM);
            }
    int filled = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            if (labels.at<int>(y, x) == board) ++filled;
    if (double cu0, cu1, cv0, cv1; carved && carvedTableRect(*carved, cu0, cu1, cv0, cv1)) {
        uMin = std::min(uMin, cu0), uMax = std::max(uMax, cu1);
        vMin = std::min(vMin, cv0), vMax = std::max(vMax, cv1);
    }
    TableEstimate& t = out.table;
    t.plane = plane;
    t.uMin = uMin, t.uMax = uMax, t.vMin = vMin, t.vMax = vMax;
    const int inCells =
        int(std::lround((uMax - uMin) / cell)) * int(std::lround((vMax - vMin) / cell));
    t.filledFraction = inCells > 0 ? std::min(1.0, double(filled) / inCells) : 0.0;

    // Colour of the table per cell (for its albedo texture) and the plane fit residual.
    out.tableCellM = o.cellM;
    const int cols = std::max(1, int(std::ceil((uMax - uMin) / o.cellM)));
    const int rows = std::max(1, int(std::ceil((vMax - vMin) / o.cellM)));
    cv::Mat sum(rows, cols, CV_32FC3, cv::Scalar::all(0)), count(rows, cols, CV_32F, 0.0f);
    double sumH2 = 0;
    for (size_t i = 0; i < mesh.vertices_.size(); ++i) {
        const auto& p = mesh.vertices_[i];
        const glm::dvec3 uvh = plane.toPlane({p.x(), p.y(), p.z()});
        if (std::abs(uvh.z) >= o.planeBandM) continue;
        const int x = int((uvh.x - uMin) / o.cellM), y = int((uvh.y - vMin) / o.cellM);
        if (x < 0 || y < 0 || x >= cols || y >= rows) continue;
        const glm::vec3 c = linearColour(mesh.vertex_colors_[i], footage.exposure);
        sum.at<cv::Vec3f>(y, x) += cv::Vec3f(c.r, c.g, c.b);
        count.at<float>(y, x) += 1.0f;
        sumH2 += uvh.z * uvh.z;
        ++t.supportPoints;
    }
    t.rmsHeightM = t.supportPoints > 0 ? std::sqrt(sumH2 / t.supportPoints) : 0.0;
    out.tableColour = cv::Mat(rows, cols, CV_32FC3, cv::Scalar::all(0));
    out.tableObserved = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
    for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x)
            if (count.at<float>(y, x) > 0) {
                out.tableColour.at<cv::Vec3f>(y, x) =
                    sum.at<cv::Vec3f>(y, x) / count.at<float>(y, x);
                out.tableObserved.at<uchar>(y, x) = 255;
            }
    if (carved) {
        useCarvedTableColour(carved->plane, footage.exposure, out);
        t.filledFraction = double(cv::countNonZero(out.tableObserved)) / double(rows * cols);
    }
}

struct HeightField {
    cv::Mat height;    // CV_32F metres above the plane, 0 = empty
    cv::Mat observed;  // CV_8U: cells with fused surface
    double u0 = 0, v0 = 0, cell = 0.004;
};

// The fused surface more than planeBandM above the plane, as the highest point per cell.
HeightField objectHeights(const TriangleMesh& mesh, const TableEstimate& t,
                          const GeometryOptions& o) {
    HeightField f;
    f.cell = o.cellM;
    f.u0 = t.uMin, f.v0 = t.vMin;
    const int cols = std::max(1, int(std::ceil((t.uMax - t.uMin) / f.cell)));
    const int rows = std::max(1, int(std::ceil((t.vMax - t.vMin) / f.cell)));
    f.height = cv::Mat(rows, cols, CV_32F, 0.0f);
    for (const auto& p : mesh.vertices_) {
        const glm::dvec3 uvh = t.plane.toPlane({p.x(), p.y(), p.z()});
        if (uvh.z < o.planeBandM) continue;
        const int x = int((uvh.x - f.u0) / f.cell), y = int((uvh.y - f.v0) / f.cell);
        if (x < 0 || y < 0 || x >= cols || y >= rows) continue;
        float& h = f.height.at<float>(y, x);
        h = std::max(h, float(uvh.z));
    }
    f.observed = f.height > 0;
    return f;
}

// The carved columns' heights (SpaceCarving.h) as the objects' height field.
HeightField carvedHeights(const CarvedHeights& c) {
    HeightField f;
    f.cell = c.cell;
    f.u0 = c.u0, f.v0 = c.v0;
    f.height = c.height.clone();
    f.observed = f.height > 0;
    return f;
}

// Silhouettes leave the space over a plain top that every frame sees the top through (a wedge
// rising towards the cameras, docs/reconstruction.md); the fused stereo surface has depth where
// the footage has edges, such as a top's rims. Each carved object is cut at the 95th percentile
// of the fused surface's heights over its footprint (plus a cell), where the fusion has at least
// minFusedSamples points there.
void capByFusedSurface(HeightField& f, const TriangleMesh& mesh, const BoardPlane& plane,
                       const GeometryOptions& o) {
    cv::Mat labels;
    const int count = cv::connectedComponents(f.height > 0, labels, 8, CV_32S);
    std::vector<std::vector<float>> heights{size_t(count)};
    for (const auto& p : mesh.vertices_) {
        const glm::dvec3 uvh = plane.toPlane({p.x(), p.y(), p.z()});
        const int x = int(std::floor((uvh.x - f.u0) / f.cell));
        const int y = int(std::floor((uvh.y - f.v0) / f.cell));
        if (uvh.z < o.planeBandM || x < 0 || y < 0 || x >= labels.cols || y >= labels.rows)
            continue;
        heights[size_t(labels.at<int>(y, x))].push_back(float(uvh.z));
    }
    std::vector<float> cap(size_t(count), std::numeric_limits<float>::infinity());
    for (int l = 1; l < count; ++l) {
        auto& h = heights[size_t(l)];
        if (int(h.size()) < o.minFusedSamples) continue;
        auto at = h.begin() + long(0.95 * double(h.size() - 1));
        std::nth_element(h.begin(), at, h.end());
        cap[size_t(l)] = *at + float(f.cell);
    }
    for (int y = 0; y < labels.rows; ++y)
        for (int x = 0; x < labels.cols; ++x) {
            float& h = f.height.at<float>(y, x);
            h = std::min(h, cap[size_t(labels.at<int>(y, x))]);
        }
}

void closeHeightField(HeightField& f) {
    const int rows = f.height.rows, cols = f.height.cols;
    // Close one-cell gaps between fused samples, then the holes inside each footprint (the
    // unseen underside of an overhang, a face the matcher left empty): the object stands there.
    cv::Mat occupied;
    cv::morphologyEx(f.observed, occupied, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
    cv::Mat outside = occupied.clone();
    cv::copyMakeBorder(outside, outside, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::floodFill(outside, cv::Point(0, 0), cv::Scalar(255));
    cv::Mat holes = outside(cv::Rect(1, 1, cols, rows)) == 0;
    occupied |= holes;
    // Heights of the filled cells: grown from their neighbours.
    for (int pass = 0; pass < 64; ++pass) {
        cv::Mat grown;
        cv::dilate(f.height, grown, cv::Mat());
        int missing = 0;
        for (int y = 0; y < rows; ++y)
            for (int x = 0; x < cols; ++x)
                if (occupied.at<uchar>(y, x) && f.height.at<float>(y, x) <= 0) {
                    f.height.at<float>(y, x) = grown.at<float>(y, x);
                    missing += grown.at<float>(y, x) <= 0 ? 1 : 0;
                }
        if (missing == 0) break;
    }
    f.height.setTo(0.0f, occupied == 0);
    cv::Mat smoothed;
    cv::medianBlur(f.height, smoothed, 3);
    smoothed.copyTo(f.height, occupied);
}

// A closed solid from the cells labelled `label`: a top quad per cell, walls down to the lower
// neighbour (or the plane), a bottom on the plane. Counter-clockwise seen from outside.
void buildColumns(const HeightField& f, const cv::Mat& labels, int label, const BoardPlane& plane,
                  ProxyObject& obj) {
    auto vertex = [&](double u, double v, double h) {
        obj.positions.push_back(glm::vec3(plane.toWorld({u, v, h})));
        return uint32_t(obj.positions.size() - 1);
    };
    auto quad = [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                    const glm::dvec3& d) {
        const uint32_t i0 = vertex(a.x, a.y, a.z), i1 = vertex(b.x, b.y, b.z),
                       i2 = vertex(c.x, c.y, c.z), i3 = vertex(d.x, d.y, d.z);
        obj.indices.insert(obj.indices.end(), {i0, i1, i2, i0, i2, i3});
    };
    auto heightAt = [&](int y, int x) -> double {
        if (y < 0 || x < 0 || y >= labels.rows || x >= labels.cols) return 0.0;
        return labels.at<int>(y, x) == label ? f.height.at<float>(y, x) : 0.0;
    };
    for (int y = 0; y < labels.rows; ++y)
        for (int x = 0; x < labels.cols; ++x) {
            if (labels.at<int>(y, x) != label) continue;
            const double h = f.height.at<float>(y, x);
            const double u0 = f.u0 + x * f.cell, u1 = u0 + f.cell;
            const double v0 = f.v0 + y * f.cell, v1 = v0 + f.cell;
            quad({u0, v0, h}, {u1, v0, h}, {u1, v1, h}, {u0, v1, h});  // top, facing +h
            quad({u0, v1, 0}, {u1, v1, 0}, {u1, v0, 0}, {u0, v0, 0});  // bottom, facing -h
            if (const double hn = heightAt(y, x + 1); hn < h)          // facing +u
                quad({u1, v0, hn}, {u1, v1, hn}, {u1, v1, h}, {u1, v0, h});
            if (const double hn = heightAt(y, x - 1); hn < h)  // facing -u
                quad({u0, v0, h}, {u0, v1, h}, {u0, v1, hn}, {u0, v0, hn});
            if (const double hn = heightAt(y + 1, x); hn < h)  // facing +v
                quad({u0, v1, hn}, {u0, v1, h}, {u1, v1, h}, {u1, v1, hn});
            if (const double hn = heightAt(y - 1, x); hn < h)  // facing -v
                quad({u1, v0, hn}, {u1, v0, h}, {u0, v0, h}, {u0, v0, hn});
        }
}

void simplify(ProxyObject& obj, int budget) {
    TriangleMesh m;
    for (const auto& p : obj.positions) m.vertices_.emplace_back(p.x, p.y, p.z);
    for (size_t i = 0; i + 2 < obj.indices.size(); i += 3)
        m.triangles_.emplace_back(int(obj.indices[i]), int(obj.indices[i + 1]),
                                  int(obj.indices[i + 2]));
    m.RemoveDuplicatedVertices();
    std::shared_ptr<TriangleMesh> s = std::make_shared<TriangleMesh>(m);
    if (int(m.triangles_.size()) > budget)
        s = m.SimplifyQuadricDecimation(budget, std::numeric_limits<double>::infinity(), 1.0);
    s->RemoveDegenerateTriangles();
    s->RemoveUnreferencedVertices();
    obj.positions.clear();
    obj.indices.clear();
    for (const auto& v : s->vertices_) obj.positions.emplace_back(v.x(), v.y(), v.z());
    for (const auto& t : s->triangles_)
        obj.indices.insert(obj.indices.end(), {uint32_t(t.x()), uint32_t(t.y()), uint32_t(t.z())});
}

void splitObjects(const TriangleMesh& mesh, const Footage& footage, const GeometryOptions& o,
                  const CarvedHeights* carved, FusedGeometry& out) {
    HeightField f = carved ? carvedHeights(*carved) : objectHeights(mesh, out.table, o);
    if (carved) capByFusedSurface(f, mesh, footage.board, o);
    closeHeightField(f);
    cv::Mat labels, stats, centroids;
    const int count =
        cv::connectedComponentsWithStats(f.height > 0, labels, stats, centroids, 8, CV_32S);
    const double cellArea = f.cell * f.cell;
    for (int label = 1; label < count; ++label) {
        // Small pieces first, by their area alone (the carved raster holds many specks).
        if (stats.at<int>(label, cv::CC_STAT_AREA) * cellArea < o.minObjectAreaM2) continue;
        const int x0 = stats.at<int>(label, cv::CC_STAT_LEFT),
                  y0 = stats.at<int>(label, cv::CC_STAT_TOP);
        const int x1 = x0 + stats.at<int>(label, cv::CC_STAT_WIDTH);
        const int y1 = y0 + stats.at<int>(label, cv::CC_STAT_HEIGHT);
        double top = 0;
        int observed = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x)
                if (labels.at<int>(y, x) == label) {
                    top = std::max(top, double(f.height.at<float>(y, x)));
                    observed += f.observed.at<uchar>(y, x) ? 1 : 0;
                }
        const double area = stats.at<int>(label, cv::CC_STAT_AREA) * cellArea;
        if (area < o.minObjectAreaM2 || top < o.minObjectHeightM) continue;
        ProxyObject obj;
        obj.heightM = top;
        obj.footprintM2 = area;
        obj.observedCells = observed;
        obj.sizeU = stats.at<int>(label, cv::CC_STAT_WIDTH) * f.cell;
        obj.sizeV = stats.at<int>(label, cv::CC_STAT_HEIGHT) * f.cell;
        obj.centre =
            footage.board.toWorld({f.u0 + (centroids.at<double>(label, 0) + 0.5) * f.cell,
                                   f.v0 + (centroids.at<double>(label, 1) + 0.5) * f.cell, 0.0});
        buildColumns(f, labels, label, footage.board, obj);
        simplify(obj, o.triangleBudgetPerObject);
        // The fused surface samples that belong to it (for the material and light steps).
        for (size_t i = 0; i < mesh.vertices_.size(); ++i) {
            const auto& p = mesh.vertices_[i];
            const glm::dvec3 uvh = footage.board.toPlane({p.x(), p.y(), p.z()});
            const int x = int((uvh.x - f.u0) / f.cell), y = int((uvh.y - f.v0) / f.cell);
            if (uvh.z < o.planeBandM || x < 0 || y < 0 || x >= labels.cols || y >= labels.rows ||
                labels.at<int>(y, x) != label)
                continue;
            obj.samplePoints.emplace_back(p.x(), p.y(), p.z());
            obj.sampleColours.push_back(linearColour(mesh.vertex_colors_[i], footage.exposure));
            const auto& n = mesh.vertex_normals_[i];
            obj.sampleNormals.emplace_back(n.x(), n.y(), n.z());
        }
        out.objects.push_back(std::move(obj));
    }
    // Largest first; names in that order.
    std::sort(out.objects.begin(), out.objects.end(),
              [](const ProxyObject& a, const ProxyObject& b) {
                  return a.footprintM2 * a.heightM > b.footprintM2 * b.heightM;
              });
    if (int(out.objects.size()) > o.maxObjects) out.objects.resize(size_t(o.maxObjects));
    for (size_t i = 0; i < out.objects.size(); ++i)
        out.objects[i].name = fmt::format("real_object_{}", i + 1);
}

}  // namespace

FusedGeometry reconstructGeometry(const Footage& footage, const std::vector<DepthView>& views,
                                  const GeometryOptions& o, const CarvedHeights* carved) {
    FusedGeometry out;
    const auto mesh = fuseDepth(views, footage.board, o, out);
    estimateTable(*mesh, footage, o, carved, out);
    splitObjects(*mesh, footage, o, carved, out);
    return out;
}

}  // namespace mirage::reconstruction
