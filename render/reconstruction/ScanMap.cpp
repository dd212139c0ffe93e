#include "render/reconstruction/ScanMap.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "core/plot/SvgPlot.h"

namespace mirage::reconstruction {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Plane (u, v) metres to SVG pixels: u to the right, v upwards (the cameras' side, small v for
// the default board, at the bottom).
struct MapFrame {
    double u0 = 0, v1 = 0, scale = 1;
    double x(double u) const { return (u - u0) * scale; }
    double y(double v) const { return (v1 - v) * scale; }
};

struct Bounds {
    double uMin = 1e9, uMax = -1e9, vMin = 1e9, vMax = -1e9;
    void add(double u, double v) {
        uMin = std::min(uMin, u), uMax = std::max(uMax, u);
        vMin = std::min(vMin, v), vMax = std::max(vMax, v);
    }
};

std::string polygon(const std::vector<cv::Point2d>& uv, const MapFrame& m, const char* style) {
    std::string points;
    for (const auto& p : uv) points += fmt::format("{:.1f},{:.1f} ", m.x(p.x), m.y(p.y));
    return fmt::format("<polygon points=\"{}\" {}/>\n", points, style);
}

// The footprint of an object seen from above: the convex hull of its vertices on the plane.
std::vector<cv::Point2d> footprint(const ProxyObject& o, const BoardPlane& plane) {
    std::vector<cv::Point2f> uv, hull;
    for (const glm::vec3& p : o.positions) {
        const glm::dvec3 q = plane.toPlane(glm::dvec3(p));
        uv.emplace_back(float(q.x), float(q.y));
    }
    if (uv.size() < 3) return {};
    cv::convexHull(uv, hull);
    return {hull.begin(), hull.end()};
}

}  // namespace

std::string scanMapSvg(const Footage& footage, const Reconstruction& r) {
    const BoardPlane& plane = footage.board;
    const TableEstimate& t = r.geometry.table;
    Bounds b;
    b.add(t.uMin, t.vMin), b.add(t.uMax, t.vMax);
    b.add(-plane.halfU, -plane.halfV), b.add(plane.halfU, plane.halfV);
    struct Camera {
        glm::dvec3 c;     // centre, plane coordinates
        glm::dvec2 look;  // where the optical axis meets the plane (or a point along it)
        double downDeg = 0;
    };
    std::vector<Camera> cameras;
    for (const PosedFrame& f : footage.frames) {
        Camera cam;
        cam.c = plane.toPlane(f.T_world_camera.translation);
        const glm::dvec3 axis = f.T_world_camera.rotation * glm::dvec3(0, 0, 1);
        const double along = glm::dot(axis, plane.normal);
        const glm::dvec3 a(glm::dot(axis, plane.axisU), glm::dot(axis, plane.axisV()), along);
        const double s = along < -1e-3 ? std::min(cam.c.z / -along, 3.0) : 0.3;
        cam.look = glm::dvec2(cam.c.x + s * a.x, cam.c.y + s * a.y);
        cam.downDeg = glm::degrees(std::asin(std::clamp(-along, -1.0, 1.0)));
        b.add(cam.c.x, cam.c.y);
        cameras.push_back(cam);
    }
    std::optional<glm::dvec3> spot;
    glm::dvec2 spotHit(0.0);
    if (r.lighting.spot) {
        const FittedSpotLight& l = *r.lighting.spot;
        spot = plane.toPlane(l.position);
        const double along = glm::dot(l.direction, plane.normal);
        const double s = along < -1e-3 ? spot->z / -along : 0.0;
        const glm::dvec3 hit = plane.toPlane(l.position + s * l.direction);
        spotHit = glm::dvec2(hit.x, hit.y);
        b.add(spot->x, spot->y);
    }
    const double margin = 0.08;
    const int width = 640;
    MapFrame m;
    m.u0 = b.uMin - margin;
    m.v1 = b.vMax + margin;
    m.scale = width / (b.uMax - b.uMin + 2 * margin);
    const int mapHeight = int(std::ceil((b.vMax - b.vMin + 2 * margin) * m.scale));
    const int height = mapHeight + 70;

    std::string svg = fmt::format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} "
        "{}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
        "fill=\"white\"/>\n",
        width, height, width, height);
    svg += polygon({{t.uMin, t.vMin}, {t.uMax, t.vMin}, {t.uMax, t.vMax}, {t.uMin, t.vMax}}, m,
                   "class=\"table\" fill=\"#e8d3b0\" stroke=\"#8a6a3a\"");
    svg += fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" fill=\"#8a6a3a\">table {:.2f} x {:.2f} m</text>\n",
        m.x(t.uMin) + 4, m.y(t.vMax) + 14, t.uMax - t.uMin, t.vMax - t.vMin);
    svg += polygon({{-plane.halfU, -plane.halfV},
                    {plane.halfU, -plane.halfV},
                    {plane.halfU, plane.halfV},
                    {-plane.halfU, plane.halfV}},
                   m, "class=\"board\" fill=\"white\" stroke=\"black\"");
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">board</text>\n",
                       m.x(0), m.y(0) + 4);
    for (const ProxyObject& o : r.geometry.objects) {
        const auto hull = footprint(o, plane);
        if (hull.empty()) continue;
        svg += polygon(hull, m, "class=\"object\" fill=\"#7a8fb8\" fill-opacity=\"0.7\"");
        const glm::dvec3 c = plane.toPlane(o.centre);
        svg += fmt::format(
            "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{} ({:.1f} cm tall)</text>\n",
            m.x(c.x), m.y(c.y) + 4, plot::xmlEscape(o.name), 100 * o.heightM);
    }
    for (const Camera& c : cameras) {
        svg += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#2a6\" "
            "stroke-opacity=\"0.35\"/>\n",
            m.x(c.c.x), m.y(c.c.y), m.x(c.look.x), m.y(c.look.y));
        svg += fmt::format(
            "<circle class=\"camera\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"#2a6\"/>\n",
            m.x(c.c.x), m.y(c.c.y));
    }
    if (spot) {
        svg += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#d90\" "
            "stroke-dasharray=\"4 3\"/>\n",
            m.x(spot->x), m.y(spot->y), m.x(spotHit.x), m.y(spotHit.y));
        // The label on the side of the dot towards the map's middle (it stays on the canvas).
        const bool right = m.x(spot->x) > 0.5 * width;
        svg += fmt::format(
            "<circle class=\"spot\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"7\" fill=\"#fc0\" "
            "stroke=\"#d90\"/>\n<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"{}\">spot light, "
            "{:.2f} m up</text>\n",
            m.x(spot->x), m.y(spot->y), m.x(spot->x) + (right ? -10 : 10), m.y(spot->y) + 4,
            right ? "end" : "start", spot->z);
    }
    // The caption: how the scan was made, against what docs/live.md asks of one.
    double arcDeg = 0, downMin = 90, downMax = 0;
    std::vector<double> azimuth;
    for (const Camera& c : cameras) {
        azimuth.push_back(std::atan2(c.c.y, c.c.x));
        downMin = std::min(downMin, c.downDeg), downMax = std::max(downMax, c.downDeg);
    }
    if (azimuth.size() > 1) {
        // The arc: the full turn less the largest gap between neighbouring azimuths.
        std::sort(azimuth.begin(), azimuth.end());
        double gap = 2 * kPi - (azimuth.back() - azimuth.front());
        for (size_t i = 1; i < azimuth.size(); ++i)
            gap = std::max(gap, azimuth[i] - azimuth[i - 1]);
        arcDeg = glm::degrees(2 * kPi - gap);
    }
    svg += fmt::format(
        "<text x=\"8\" y=\"{}\">{} frames (green: camera positions and where they looked), an arc "
        "of {:.0f} degrees around the board,</text>\n<text x=\"8\" y=\"{}\">looking {:.0f}-{:.0f} "
        "degrees down; parallax {:.1f} degrees. Seen from above, the cameras' side at the "
        "bottom.</text>\n",
        mapHeight + 22, cameras.size(), arcDeg, mapHeight + 40, downMin, downMax,
        r.check.parallaxDeg);
    svg += "</svg>\n";
    return svg;
}

}  // namespace mirage::reconstruction
