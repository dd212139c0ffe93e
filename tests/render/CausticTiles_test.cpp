// The caustic resolve's choice of tiles from last frame's history (CausticTiles.h), on the CPU:
// a scene of a table plane and a ball seen by two cameras; every pixel of this frame whose
// history lookup (temporal.glsl, as caustic_resolve.frag does it) can take a lit texel must lie
// in a marked tile, for small and large camera motions, and the marks stay far from the whole
// canvas.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <optional>

#include "render/passes/caustic/CausticTiles.h"

namespace mirage::render {
namespace {

constexpr int kWidth = 160, kHeight = 120;
const glm::vec3 kBallCentre(0.05f, 0.04f, 0.0f);
constexpr float kBallRadius = 0.04f;

struct View {
    glm::mat4 viewProj;
    glm::mat4 inverse;
    glm::vec3 position;
};

View orbitView(float azimuthDeg, float height, float radius, glm::vec3 target = glm::vec3(0.0f)) {
    const float a = glm::radians(azimuthDeg);
    const glm::vec3 eye(radius * std::sin(a), height, radius * std::cos(a));
    const glm::mat4 vp =
        glm::perspective(glm::radians(50.0f), float(kWidth) / float(kHeight), 0.01f, 20.0f) *
        glm::lookAt(eye, target, glm::vec3(0.0f, 1.0f, 0.0f));
    return {vp, glm::inverse(vp), eye};
}

// The nearest of the table (y = 0, 1 m square) and the ball along the ray; none: empty.
std::optional<glm::vec3> traceScene(glm::vec3 o, glm::vec3 d) {
    float best = INFINITY;
    if (d.y < 0.0f) {
        const float t = -o.y / d.y;
        const glm::vec3 p = o + t * d;
        if (std::abs(p.x) < 0.5f && std::abs(p.z) < 0.5f) best = t;
    }
    const glm::vec3 oc = o - kBallCentre;
    const float b = glm::dot(oc, d), c = glm::dot(oc, oc) - kBallRadius * kBallRadius;
    const float disc = b * b - c;
    if (disc >= 0.0f) {
        const float t = -b - std::sqrt(disc);
        if (t > 0.0f) best = std::min(best, t);
    }
    if (!std::isfinite(best)) return std::nullopt;
    return o + best * d;
}

// The surface at canvas pixel (x, y)'s centre.
std::optional<glm::vec3> surfaceAt(const View& v, int x, int y) {
    const glm::vec4 ndc((float(x) + 0.5f) / kWidth * 2.0f - 1.0f,
                        (float(y) + 0.5f) / kHeight * 2.0f - 1.0f, 0.0f, 1.0f);
    const glm::vec4 w = v.inverse * ndc;
    return traceScene(v.position, glm::normalize(glm::vec3(w) / w.w - v.position));
}

// Last frame's resolve: every surface pixel resolved (its camera distance held); the caustic lit
// on the table in a disc reaching the ball.
struct History {
    std::vector<float> distance;  // 0: none
    std::vector<bool> lit;
    CausticHistoryTiles tiles;
};

History resolveLastFrame(const View& v) {
    History h;
    h.distance.assign(kWidth * kHeight, 0.0f);
    h.lit.assign(kWidth * kHeight, false);
    const int tx = (kWidth + 7) / 8, ty = (kHeight + 7) / 8;
    h.tiles.tilesX = tx;
    h.tiles.tilesY = ty;
    h.tiles.lit.assign(std::size_t(tx * ty), 0u);
    h.tiles.nearM.assign(std::size_t(tx * ty), INFINITY);
    h.tiles.farM.assign(std::size_t(tx * ty), -INFINITY);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const auto p = surfaceAt(v, x, y);
            if (!p) continue;
            const int i = y * kWidth + x;
            const std::size_t t = std::size_t((y / 8) * tx + x / 8);
            h.distance[std::size_t(i)] = glm::length(*p - v.position);
            h.tiles.nearM[t] = std::min(h.tiles.nearM[t], h.distance[std::size_t(i)]);
            h.tiles.farM[t] = std::max(h.tiles.farM[t], h.distance[std::size_t(i)]);
            const bool onTable = std::abs(p->y) < 1e-4f;
            if (onTable && glm::length(glm::vec2(p->x + 0.06f, p->z - 0.02f)) < 0.08f) {
                h.lit[std::size_t(i)] = true;
                h.tiles.lit[t] = 1u;
            }
        }
    return h;
}

// caustic_resolve.frag's history lookup for this frame's surface point p: true when it blends in
// a lit texel (reprojection inside last frame's canvas, the same-surface test on the held
// texels' weighted distance).
bool takesLitHistory(const History& h, const View& last, glm::vec3 p) {
    const glm::vec4 clip = last.viewProj * glm::vec4(p, 1.0f);
    if (!(clip.w > 1e-6f)) return false;
    const glm::vec2 uv = glm::vec2(clip) / clip.w * 0.5f + 0.5f;
    if (uv.x < 0.0f || uv.y < 0.0f || uv.x > 1.0f || uv.y > 1.0f) return false;
    const glm::vec2 q = uv * glm::vec2(kWidth, kHeight) - 0.5f;
    const glm::ivec2 f0 = glm::ivec2(glm::floor(q));
    const glm::vec2 fr = q - glm::vec2(f0);
    float heldWeight = 0.0f, weighted = 0.0f;
    bool anyLit = false;
    for (int k = 0; k < 4; ++k) {
        const glm::ivec2 o(k & 1, k >> 1);
        const glm::ivec2 t = glm::clamp(f0 + o, glm::ivec2(0), glm::ivec2(kWidth - 1, kHeight - 1));
        const float w = (o.x ? fr.x : 1.0f - fr.x) * (o.y ? fr.y : 1.0f - fr.y);
        const std::size_t i = std::size_t(t.y * kWidth + t.x);
        if (h.distance[i] > 0.0f) {
            heldWeight += w;
            weighted += w * h.distance[i];
        }
        anyLit = anyLit || (h.lit[i] && w > 0.0f);
    }
    if (!anyLit || heldWeight <= 0.0f) return false;
    const float expected = glm::length(p - last.position);
    return std::abs(weighted / heldWeight - expected) < 0.02f * expected + 0.005f;
}

struct Outcome {
    int needed = 0;  // pixels that take lit history
    int missed = 0;  // of those, outside every marked tile
    int marked = 0;  // tiles marked
    int litTiles = 0;
};

Outcome check(const View& last, const View& now, bool reprojectTiles) {
    const History h = resolveLastFrame(last);
    std::vector<std::uint8_t> marks(h.tiles.lit.size(), 0);
    if (reprojectTiles) {
        markHistoryTiles(
            h.tiles, {now.viewProj, last.viewProj, last.position, kWidth, kHeight, now.position},
            marks);
    } else {  // the broken choice: last frame's lit tiles where they were
        for (std::size_t i = 0; i < marks.size(); ++i) marks[i] = h.tiles.lit[i] ? 1 : 0;
    }
    Outcome o;
    for (auto l : h.tiles.lit) o.litTiles += l ? 1 : 0;
    for (auto m : marks) o.marked += m;
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const auto p = surfaceAt(now, x, y);
            if (!p || !takesLitHistory(h, last, *p)) continue;
            ++o.needed;
            if (!marks[std::size_t((y / 8) * h.tiles.tilesX + x / 8)]) ++o.missed;
        }
    return o;
}

TEST(CausticTiles, EveryPixelThatTakesLitHistoryIsInAMarkedTile) {
    const View last = orbitView(0.0f, 0.35f, 0.45f);
    const int tiles = ((kWidth + 7) / 8) * ((kHeight + 7) / 8);
    for (float azimuth : {0.5f, 5.0f, 33.0f, -60.0f}) {
        // Turned round the table and aimed 6 cm aside: the caustic moves over the canvas.
        const View now = orbitView(azimuth, 0.33f, 0.47f, glm::vec3(0.06f, 0.0f, 0.0f));
        const Outcome o = check(last, now, true);
        std::cout << "[ caustic tiles ] camera turned " << azimuth << " deg: " << o.needed
                  << " pixels take lit history, " << o.missed << " outside the " << o.marked
                  << " marked tiles (" << o.litTiles << " lit last frame, of " << tiles << ")\n";
        EXPECT_GT(o.needed, 100) << azimuth;
        EXPECT_EQ(o.missed, 0) << azimuth;
        EXPECT_LT(o.marked, tiles / 2) << azimuth;
    }
}

TEST(CausticTiles, LastFramesLitTilesWhereTheyWereMissPixelsOnceTheCameraTurns) {
    const Outcome o = check(orbitView(0.0f, 0.35f, 0.45f),
                            orbitView(33.0f, 0.33f, 0.47f, glm::vec3(0.06f, 0.0f, 0.0f)), false);
    std::cout << "[ caustic tiles ] last frame's lit tiles unmoved: " << o.missed << " of "
              << o.needed << " pixels that take lit history outside them (must fail)\n";
    EXPECT_GT(o.needed, 100);
    EXPECT_GT(o.missed, o.needed / 10);  // the check can fail
}

TEST(CausticTiles, ASlabReachingBehindTheCameraMarksEveryTile) {
    const View last = orbitView(0.0f, 0.35f, 0.45f);
    // This frame's camera stands over the lit disc looking away from it.
    const glm::vec3 eye(-0.06f, 0.05f, 0.02f);
    const glm::mat4 vp =
        glm::perspective(glm::radians(50.0f), float(kWidth) / float(kHeight), 0.01f, 20.0f) *
        glm::lookAt(eye, eye + glm::vec3(0.0f, 0.2f, -1.0f), glm::vec3(0.0f, 1.0f, 0.0f));
    const History h = resolveLastFrame(last);
    std::vector<std::uint8_t> marks(h.tiles.lit.size(), 0);
    markHistoryTiles(h.tiles, {vp, last.viewProj, last.position, kWidth, kHeight, eye}, marks);
    for (auto m : marks) ASSERT_EQ(m, 1);
}

// The share of a view that the view before did not show, at the receivers' distances.
TEST(CausticTiles, NewViewShareGrowsWithTheTurnAndIsZeroStandingStill) {
    const View last = orbitView(0.0f, 0.35f, 0.45f);
    const auto share = [&](const View& now) {
        return newViewShare(
            {now.viewProj, last.viewProj, last.position, kWidth, kHeight, now.position}, 0.4f,
            0.7f);
    };
    EXPECT_EQ(share(last), 0.0f);
    // 1 mm aside (the tracking's jitter): nothing new.
    EXPECT_EQ(share(orbitView(0.13f, 0.35f, 0.45f)), 0.0f);
    const float turned5 = share(orbitView(5.0f, 0.35f, 0.45f, glm::vec3(0.03f, 0.0f, 0.0f)));
    const float turned33 = share(orbitView(33.0f, 0.35f, 0.45f, glm::vec3(0.15f, 0.0f, 0.0f)));
    std::cout << "[ caustic tiles ] new share of the view: turned 5 deg " << turned5 << ", 33 deg "
              << turned33 << "\n";
    EXPECT_GT(turned5, 0.02f);
    EXPECT_LT(turned5, turned33);
    EXPECT_GT(turned33, 0.3f);
    // From the same place, looking the other way: all of it.
    EXPECT_EQ(share(orbitView(0.0f, 0.35f, 0.45f, glm::vec3(0.0f, 0.35f, 0.9f))), 1.0f);
}

TEST(CausticTiles, QuadsCoverTheMarkedTilesAndNothingElse) {
    const int tx = 5, ty = 3, w = 37, h = 20;  // the last column and row are partial tiles
    std::vector<std::uint8_t> marks(tx * ty, 0);
    marks[0] = marks[1] = marks[4] = marks[2 * tx + 3] = 1;
    const std::vector<glm::vec2> quads = tileQuads(marks, tx, ty, w, h);
    ASSERT_EQ(quads.size(), 3u * 6u);  // runs: tiles 0-1, tile 4, tile (3, 2)
    float area = 0.0f;
    for (std::size_t i = 0; i < quads.size(); i += 6) {
        const glm::vec2 lo = glm::min(quads[i], quads[i + 2]),
                        hi = glm::max(quads[i], quads[i + 2]);
        EXPECT_GE(lo.x, -1.0f);
        EXPECT_LE(hi.x, 1.0f);
        EXPECT_LE(hi.y, 1.0f);
        area += (hi.x - lo.x) * 0.5f * float(w) * (hi.y - lo.y) * 0.5f * float(h);
    }
    // 16x8 + (37 - 32)x8 + 8x(20 - 16) pixels.
    EXPECT_NEAR(area, 16.0f * 8.0f + 5.0f * 8.0f + 8.0f * 4.0f, 1e-3f);
}

}  // namespace
}  // namespace mirage::render
