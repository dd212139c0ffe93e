#include "render/CameraProjection.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"

namespace mirage::render {

CameraProjection CameraProjection::make(const CameraIntrinsics& cam, double maxGrowth) {
    if (!cam.isValid())
        throw Error(
            "camera intrinsics are invalid (need positive finite fx, fy and image size); "
            "check the calibration file");
    CameraProjection p;
    p.camera = cam;
    for (double c : cam.distortion) p.hasDistortion = p.hasDistortion || c != 0.0;
    if (cam.model == DistortionModel::KannalaBrandt) p.hasDistortion = true;
    const int W = cam.width, H = cam.height;
    p.remap.assign(size_t(W) * size_t(H), glm::vec2(-1e4f));
    if (!p.hasDistortion) {
        p.canvasWidth = W;
        p.canvasHeight = H;
        p.canvasCx = cam.cx;
        p.canvasCy = cam.cy;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) p.remap[size_t(y) * W + x] = glm::vec2(x, y);
        return p;
    }
    // Ideal (undistorted) pixel of every output pixel's ray, relative to the ideal principal
    // point; then the canvas is the bounding box, capped.
    std::vector<glm::dvec2> ideal(size_t(W) * size_t(H), glm::dvec2(1e30));
    double minX = -0.5 - cam.cx, maxX = W - 0.5 - cam.cx;  // at least the image itself
    double minY = -0.5 - cam.cy, maxY = H - 0.5 - cam.cy;
    const double capX = maxGrowth * W, capY = maxGrowth * H;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            auto ray = cam.unproject(glm::dvec2(x, y));
            if (!ray || ray->z <= 1e-6) continue;
            glm::dvec2 q(cam.fx * ray->x / ray->z, cam.fy * ray->y / ray->z);
            if (std::abs(q.x) > capX || std::abs(q.y) > capY) continue;
            ideal[size_t(y) * W + x] = q;
            minX = std::min(minX, q.x - 1.0);
            maxX = std::max(maxX, q.x + 1.0);
            minY = std::min(minY, q.y - 1.0);
            maxY = std::max(maxY, q.y + 1.0);
        }
    }
    // Canvas pixel u spans [-0.5, cw-0.5]; put the principal point so that minX lands at -0.5.
    p.canvasCx = -0.5 - std::floor(minX);
    p.canvasCy = -0.5 - std::floor(minY);
    p.canvasWidth = int(std::ceil(maxX + p.canvasCx + 0.5));
    p.canvasHeight = int(std::ceil(maxY + p.canvasCy + 0.5));
    for (size_t i = 0; i < ideal.size(); ++i)
        if (ideal[i].x < 1e29)
            p.remap[i] = glm::vec2(float(ideal[i].x + p.canvasCx), float(ideal[i].y + p.canvasCy));
    return p;
}

glm::mat4 CameraProjection::projectionMatrix(float n, float f) const {
    // x_ndc = 2 (u + 0.5) / W - 1 with u = fx x/z + cx; same for y with GL row 0 = image row 0.
    const double W = canvasWidth, H = canvasHeight;
    glm::mat4 m(0.0f);
    m[0][0] = float(2.0 * camera.fx / W);
    m[2][0] = float(2.0 * (canvasCx + 0.5) / W - 1.0);
    m[1][1] = float(2.0 * camera.fy / H);
    m[2][1] = float(2.0 * (canvasCy + 0.5) / H - 1.0);
    m[2][2] = (f + n) / (f - n);
    m[3][2] = -2.0f * f * n / (f - n);
    m[2][3] = 1.0f;
    return m;
}

glm::dvec2 CameraProjection::projectToCanvas(const glm::dvec3& pc) const {
    return {camera.fx * pc.x / pc.z + canvasCx, camera.fy * pc.y / pc.z + canvasCy};
}

std::vector<glm::vec2> CameraProjection::canvasToCameraTable() const {
    const int cw = canvasWidth, ch = canvasHeight;
    std::vector<glm::vec2> table(size_t(cw) * size_t(ch), glm::vec2(-1e4f));
    for (int y = 0; y < ch; ++y)
        for (int x = 0; x < cw; ++x) {
            const glm::dvec3 ray((x - canvasCx) / camera.fx, (y - canvasCy) / camera.fy, 1.0);
            if (auto q = camera.project(ray))
                table[size_t(y) * size_t(cw) + size_t(x)] = glm::vec2(*q);
        }
    return table;
}

}  // namespace mirage::render
