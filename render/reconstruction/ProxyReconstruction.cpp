#include "render/reconstruction/ProxyReconstruction.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

namespace mirage::reconstruction {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

nlohmann::json vec(const glm::dvec3& v) {
    return {v.x, v.y, v.z};
}

// The cameras' median cosine to the table's normal, seen from the board's centre.
double medianViewCosine(const Footage& footage) {
    std::vector<double> c;
    for (const PosedFrame& f : footage.frames)
        c.push_back(glm::dot(glm::normalize(f.T_world_camera.translation - footage.board.point),
                             footage.board.normal));
    if (c.empty()) return 0.0;
    auto mid = c.begin() + long(c.size() / 2);
    std::nth_element(c.begin(), mid, c.end());
    return std::max(0.0, *mid);
}

}  // namespace

Reconstruction reconstruct(const Footage& footage, const std::optional<glm::dvec3>& environment,
                           const ReconstructionOptions& o, const ReconstructionProgress& progress) {
    Reconstruction r;
    r.check = checkFootage(footage, o.check);
    if (!r.check.ok)
        throw FootageRefused("mirage proxies: the footage cannot be reconstructed: " +
                             r.check.problem);
    auto t0 = Clock::now();
    const std::vector<DepthView> views =
        computeDepthViews(footage, o.stereo, [&](int done, int total) {
            if (progress) progress("stereo", done, total);
        });
    r.depthMaps = int(views.size());
    for (const auto& v : views) r.meanValidFraction += v.validFraction / double(views.size());
    if (views.empty())
        throw FootageRefused(
            "mirage proxies: no two tracked frames form a stereo pair (a sideways move of "
            "3.5-14 cm between them, optical axes within 25 degrees); record again walking the "
            "camera slowly around the table, keeping the board in view");
    r.stereoSeconds = secondsSince(t0);
    if (o.carving.enabled) {
        t0 = Clock::now();
        if (progress) progress("carving", 0, 1);
        r.carving = carveAbovePlane(footage, o.carving);
        if (progress) progress("carving", 1, 1);
        r.carvingSeconds = secondsSince(t0);
    }
    t0 = Clock::now();
    if (progress) progress("fusion", 0, 1);
    r.geometry =
        reconstructGeometry(footage, views, o.geometry, o.carving.enabled ? &r.carving : nullptr);
    if (progress) progress("fusion", 1, 1);
    r.fusionSeconds = secondsSince(t0);
    t0 = Clock::now();
    if (progress) progress("lights", 0, 1);
    LightFitOptions light = o.light;
    if (light.viewCosine <= 0) light.viewCosine = medianViewCosine(footage);
    r.lighting = estimateLighting(r.geometry, environment, light);
    if (progress) progress("lights", 1, 1);
    r.lightSeconds = secondsSince(t0);
    return r;
}

nlohmann::json reconstructionReport(const Reconstruction& r) {
    using nlohmann::json;
    const TableEstimate& t = r.geometry.table;
    json j;
    j["footage"] = {{"tracked_frames", r.check.frames},
                    {"parallax_deg", r.check.parallaxDeg},
                    {"max_baseline_m", r.check.maxBaselineM},
                    {"median_distance_m", r.check.medianDistanceM},
                    {"depth_maps", r.depthMaps},
                    {"depth_valid_fraction", r.meanValidFraction}};
    if (!r.carving.height.empty()) {
        const PlaneAppearance& a = r.carving.plane;
        j["carving"] = {{"frames", r.carving.framesUsed},
                        {"occupied_columns", r.carving.occupiedColumns},
                        {"table_cells", cv::countNonZero(a.kind == PlaneAppearance::Table)},
                        {"covered_cells", cv::countNonZero(a.kind == PlaneAppearance::Covered)},
                        {"cell_m", a.cell},
                        {"table_chromaticity", {a.tableChroma[0], a.tableChroma[1]}},
                        {"board_chromaticity", {a.boardChroma[0], a.boardChroma[1]}}};
    } else {
        j["carving"] = nullptr;
    }
    j["fusion"] = {{"vertices", r.geometry.fusedVertices},
                   {"triangles", r.geometry.fusedTriangles},
                   {"dropped_components", r.geometry.droppedComponents}};
    j["table"] = {{"plane_point", vec(t.plane.point)},
                  {"plane_normal", vec(t.plane.normal)},
                  {"extent_u_m", {t.uMin, t.uMax}},
                  {"extent_v_m", {t.vMin, t.vMax}},
                  {"size_m", {t.uMax - t.uMin, t.vMax - t.vMin}},
                  {"support_points", t.supportPoints},
                  {"rms_height_m", t.rmsHeightM},
                  {"filled_fraction", t.filledFraction},
                  {"albedo", vec(r.lighting.tableAlbedo)}};
    j["objects"] = json::array();
    for (size_t i = 0; i < r.geometry.objects.size(); ++i) {
        const ProxyObject& o = r.geometry.objects[i];
        const int cells = int(std::lround(o.footprintM2 / (0.004 * 0.004)));
        j["objects"].push_back(
            {{"name", o.name},
             {"centre", vec(o.centre)},
             {"height_m", o.heightM},
             {"footprint_m2", o.footprintM2},
             {"size_m", {o.sizeU, o.sizeV}},
             {"triangles", o.indices.size() / 3},
             {"observed_fraction", cells > 0 ? double(o.observedCells) / cells : 0.0},
             {"albedo",
              i < r.lighting.objectAlbedo.size() ? vec(r.lighting.objectAlbedo[i]) : json()}});
    }
    j["environment"] = {{"measured", r.lighting.environmentMeasured},
                        {"irradiance", vec(r.lighting.environmentIrradiance)},
                        {"specular_share", r.lighting.specularShare}};
    if (r.lighting.spot) {
        const FittedSpotLight& s = *r.lighting.spot;
        j["spot"] = {{"position", vec(s.position)},
                     {"direction", vec(s.direction)},
                     {"inner_cone_rad", s.innerConeRad},
                     {"outer_cone_rad", s.outerConeRad},
                     {"intensity_cd", vec(s.intensity)},
                     {"rms_residual", s.rmsResidual},
                     {"cells_used", s.cellsUsed},
                     {"cells_trimmed", s.cellsTrimmed},
                     {"contrast", s.contrast}};
    } else {
        j["spot"] = nullptr;
    }
    j["notes"] = r.lighting.notes;
    j["seconds"] = {{"stereo", r.stereoSeconds},
                    {"carving", r.carvingSeconds},
                    {"fusion", r.fusionSeconds},
                    {"lights", r.lightSeconds}};
    return j;
}

std::string reconstructionSummary(const Reconstruction& r) {
    const TableEstimate& t = r.geometry.table;
    std::string s = fmt::format(
        "footage: {} tracked frames, parallax {:.1f} deg, {} depth maps ({:.0f} % of pixels with "
        "depth)\n",
        r.check.frames, r.check.parallaxDeg, r.depthMaps, 100 * r.meanValidFraction);
    if (!r.carving.height.empty())
        s += fmt::format("carving: {} frames, {} columns of {:.0f} mm occupied above the table\n",
                         r.carving.framesUsed, r.carving.occupiedColumns, 1000 * r.carving.cell);
    s += fmt::format(
        "table: {:.2f} x {:.2f} m seen flat ({:.0f} % of it observed), plane RMS {:.1f} mm, "
        "albedo {:.2f} {:.2f} {:.2f}\n",
        t.uMax - t.uMin, t.vMax - t.vMin, 100 * t.filledFraction, 1000 * t.rmsHeightM,
        r.lighting.tableAlbedo.x, r.lighting.tableAlbedo.y, r.lighting.tableAlbedo.z);
    for (size_t i = 0; i < r.geometry.objects.size(); ++i) {
        const ProxyObject& o = r.geometry.objects[i];
        const glm::dvec3 a =
            i < r.lighting.objectAlbedo.size() ? r.lighting.objectAlbedo[i] : glm::dvec3(0);
        s += fmt::format(
            "{}: at {:.3f} {:.3f} {:.3f}, {:.1f} x {:.1f} cm, {:.1f} cm tall, {} triangles, "
            "albedo {:.2f} {:.2f} {:.2f}\n",
            o.name, o.centre.x, o.centre.y, o.centre.z, 100 * o.sizeU, 100 * o.sizeV,
            100 * o.heightM, o.indices.size() / 3, a.x, a.y, a.z);
    }
    if (r.lighting.spot) {
        const FittedSpotLight& l = *r.lighting.spot;
        s += fmt::format(
            "spot light: at {:.3f} {:.3f} {:.3f}, shining {:.3f} {:.3f} {:.3f}, cone {:.1f}/{:.1f} "
            "deg, {:.3g} {:.3g} {:.3g} cd, residual {:.4f} ({} cells, {} trimmed)\n",
            l.position.x, l.position.y, l.position.z, l.direction.x, l.direction.y, l.direction.z,
            glm::degrees(l.innerConeRad), glm::degrees(l.outerConeRad), l.intensity.x,
            l.intensity.y, l.intensity.z, l.rmsResidual, l.cellsUsed, l.cellsTrimmed);
    } else {
        s += "spot light: none found\n";
    }
    for (const auto& n : r.lighting.notes) s += "note: " + n + "\n";
    return s;
}

}  // namespace mirage::reconstruction
