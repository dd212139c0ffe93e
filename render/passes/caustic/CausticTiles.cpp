#include "render/passes/caustic/CausticTiles.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace mirage::render {

namespace {

// The history's same-surface test (temporal.glsl): a stored distance s passes for a point at
// distance e from last frame's camera when |s - e| < 0.02 e + 0.005 m. These invert it for the
// range of e a stored range [near, far] can pass, with a margin for rounding.
constexpr float kSameSurfaceRelative = 0.02f;
constexpr float kSameSurfaceAbsoluteM = 0.005f;
constexpr float kRoundingMargin = 1e-3f;  // relative

// Unit world direction from last frame's camera through its canvas position q (pixels).
glm::vec3 previousRay(const glm::mat4& prevInvViewProj, const CausticReprojection& c, glm::vec2 q) {
    const glm::vec4 ndc(q.x / float(c.width) * 2.0f - 1.0f, q.y / float(c.height) * 2.0f - 1.0f,
                        0.0f, 1.0f);
    const glm::vec4 w = prevInvViewProj * ndc;
    return glm::normalize(glm::vec3(w) / w.w - c.prevCameraPos);
}

// The camera distance range of the pixels resolved in the 3x3 tiles around (tx, ty): a bilinear
// history lookup near the tile's edge blends its neighbours' texels. False: none resolved.
bool neighbourhoodRange(const CausticHistoryTiles& h, int tx, int ty, float& nearM, float& farM) {
    nearM = INFINITY;
    farM = -INFINITY;
    for (int y = std::max(ty - 1, 0); y <= std::min(ty + 1, h.tilesY - 1); ++y)
        for (int x = std::max(tx - 1, 0); x <= std::min(tx + 1, h.tilesX - 1); ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(h.tilesX) + std::size_t(x);
            if (!(h.nearM[i] <= h.farM[i])) continue;
            nearM = std::min(nearM, h.nearM[i]);
            farM = std::max(farM, h.farM[i]);
        }
    return nearM <= farM;
}

}  // namespace

void markHistoryTiles(const CausticHistoryTiles& history, const CausticReprojection& cameras,
                      std::vector<std::uint8_t>& marks) {
    const int tilesX = history.tilesX, tilesY = history.tilesY;
    const float w = float(cameras.width), h = float(cameras.height);
    const glm::mat4 prevInv = glm::inverse(cameras.prevViewProj);
    const float t = float(kCausticTileSize);
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) {
            if (history.lit[std::size_t(ty) * std::size_t(tilesX) + std::size_t(tx)] == 0u)
                continue;
            float nearM, farM;
            if (!neighbourhoodRange(history, tx, ty, nearM, farM)) continue;
            // Distances from last frame's camera whose surfaces can pass the same-surface test.
            const float e0 = std::max((nearM - kSameSurfaceAbsoluteM) /
                                          (1.0f + kSameSurfaceRelative) * (1.0f - kRoundingMargin),
                                      1e-4f);
            const float e1 = (farM + kSameSurfaceAbsoluteM) / (1.0f - kSameSurfaceRelative) *
                             (1.0f + kRoundingMargin);
            // The last frame's canvas positions whose bilinear footprint touches the tile
            // (texels tx*8-1 .. tx*8+8), with a pixel of margin, clamped to the canvas.
            const glm::vec2 lo(std::max(tx * t - 1.5f, 0.0f), std::max(ty * t - 1.5f, 0.0f));
            const glm::vec2 hi(std::min((tx + 1) * t + 1.5f, w), std::min((ty + 1) * t + 1.5f, h));
            const std::array<glm::vec2, 4> corners{lo, {hi.x, lo.y}, hi, {lo.x, hi.y}};
            const glm::vec3 axis = previousRay(prevInv, cameras, 0.5f * (lo + hi));
            std::array<glm::vec3, 4> rays;
            float cosMin = 1.0f;
            for (int k = 0; k < 4; ++k) {
                rays[std::size_t(k)] = previousRay(prevInv, cameras, corners[std::size_t(k)]);
                cosMin = std::min(cosMin, glm::dot(rays[std::size_t(k)], axis));
            }
            // The slab lies between two planes across the axis: the nearest of its points is at
            // e0 cosMin along it, the farthest at e1; the pyramid of the four corner rays cut by
            // them holds it. Its eight corners, projected, bound it in this frame's canvas.
            glm::vec2 pmin(INFINITY), pmax(-INFINITY);
            bool behind = !(cosMin > 0.1f);
            for (int k = 0; k < 4 && !behind; ++k) {
                const glm::vec3 r = rays[std::size_t(k)];
                const float along = glm::dot(r, axis);
                for (float axial : {e0 * cosMin, e1}) {
                    const glm::vec3 p = cameras.prevCameraPos + r * (axial / along);
                    const glm::vec4 clip = cameras.viewProj * glm::vec4(p, 1.0f);
                    if (!(clip.w > 1e-5f)) {
                        behind = true;
                        break;
                    }
                    const glm::vec2 px((clip.x / clip.w * 0.5f + 0.5f) * w,
                                       (clip.y / clip.w * 0.5f + 0.5f) * h);
                    pmin = glm::min(pmin, px);
                    pmax = glm::max(pmax, px);
                }
            }
            if (behind) {  // the projection is unbounded: every tile
                std::fill(marks.begin(), marks.end(), std::uint8_t(1));
                return;
            }
            // Pixels whose centres fall in the box (a pixel of margin for rounding), as tiles.
            const float x0 = std::max(std::floor(pmin.x) - 1.0f, 0.0f);
            const float y0 = std::max(std::floor(pmin.y) - 1.0f, 0.0f);
            const float x1 = std::min(std::ceil(pmax.x) + 1.0f, w - 1.0f);
            const float y1 = std::min(std::ceil(pmax.y) + 1.0f, h - 1.0f);
            if (!(x0 <= x1 && y0 <= y1)) continue;  // off this frame's canvas
            for (int my = int(y0) / kCausticTileSize; my <= int(y1) / kCausticTileSize; ++my)
                for (int mx = int(x0) / kCausticTileSize; mx <= int(x1) / kCausticTileSize; ++mx)
                    marks[std::size_t(my) * std::size_t(tilesX) + std::size_t(mx)] = 1;
        }
}

float newViewShare(const CausticReprojection& cameras, float nearM, float farM) {
    constexpr int kGridX = 16, kGridY = 12;
    const float w = float(cameras.width), h = float(cameras.height);
    const glm::mat4 inv = glm::inverse(cameras.viewProj);
    int fresh = 0;
    for (int gy = 0; gy < kGridY; ++gy)
        for (int gx = 0; gx < kGridX; ++gx) {
            const glm::vec2 ndc((float(gx) + 0.5f) / kGridX * 2.0f - 1.0f,
                                (float(gy) + 0.5f) / kGridY * 2.0f - 1.0f);
            const glm::vec4 p = inv * glm::vec4(ndc, 0.0f, 1.0f);
            const glm::vec3 ray = glm::normalize(glm::vec3(p) / p.w - cameras.cameraPos);
            bool seen = true;
            for (float d : {nearM, 0.5f * (nearM + farM), farM}) {
                const glm::vec4 c =
                    cameras.prevViewProj * glm::vec4(cameras.cameraPos + d * ray, 1.0f);
                if (!(c.w > 1e-6f)) {
                    seen = false;
                    break;
                }
                const glm::vec2 q = (glm::vec2(c) / c.w * 0.5f + 0.5f) * glm::vec2(w, h);
                seen = seen && q.x >= 0.0f && q.y >= 0.0f && q.x <= w && q.y <= h;
            }
            fresh += seen ? 0 : 1;
        }
    return float(fresh) / float(kGridX * kGridY);
}

std::vector<glm::vec2> tileQuads(const std::vector<std::uint8_t>& marks, int tilesX, int tilesY,
                                 int width, int height) {
    std::vector<glm::vec2> quads;
    const auto ndcX = [&](int x) { return float(std::min(x, width)) / float(width) * 2.0f - 1.0f; };
    const auto ndcY = [&](int y) {
        return float(std::min(y, height)) / float(height) * 2.0f - 1.0f;
    };
    for (int ty = 0; ty < tilesY; ++ty) {
        const float y0 = ndcY(ty * kCausticTileSize), y1 = ndcY((ty + 1) * kCausticTileSize);
        for (int tx = 0; tx < tilesX;) {
            if (marks[std::size_t(ty) * std::size_t(tilesX) + std::size_t(tx)] == 0) {
                ++tx;
                continue;
            }
            int end = tx;
            while (end < tilesX && marks[std::size_t(ty) * std::size_t(tilesX) + std::size_t(end)])
                ++end;
            const float x0 = ndcX(tx * kCausticTileSize), x1 = ndcX(end * kCausticTileSize);
            quads.insert(quads.end(), {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y0}, {x1, y1}, {x0, y1}});
            tx = end;
        }
    }
    return quads;
}

}  // namespace mirage::render
