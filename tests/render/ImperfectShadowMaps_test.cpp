// Imperfect shadow maps (render/passes/ism) against exact visibility: a real wall lit by a spot,
// a virtual plate in front of it above the real floor. For every VPL on the wall and every point
// of a floor grid under and beyond the plate, the ISM's answer (the indirect pass's test:
// distance - bias against the atlas's depth in that direction) against the segment's exact
// intersection with the plate: leaks (exactly occluded, the ISM says visible) and false shadow
// (exactly visible, the ISM says occluded). Judged: the pull-push hole filling (the must-fail:
// without it the leaks through empty texels fail the bound it meets), and how the error moves
// with the points per VPL and the tile size. docs/realtime-renderer.md, "Imperfect shadow maps",
// has the figures.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <opencv2/core.hpp>

#include "render/Renderer.h"
#include "tests/support/HeadlessGlSuite.h"
#include "testscenes/WallPlateScene.h"

namespace mirage::render {
namespace {

class ImperfectShadowMaps : public test::HeadlessGlSuite {};

struct VisibilityErrors {
    int occluded = 0, leaks = 0;        // exactly occluded pairs; of those, the ISM sees through
    int visible = 0, falseShadows = 0;  // exactly visible pairs; of those, the ISM occludes
    int leaksThroughEmpty = 0;          // leaks where the texel holds nothing (no splat)
    double leakRate() const { return occluded ? double(leaks) / occluded : 0.0; }
    double falseShadowRate() const { return visible ? double(falseShadows) / visible : 0.0; }
};

VisibilityErrors measure(const IsmOptions& ism) {
    const test::WallPlateScene s = test::makeWallPlateScene();
    RendererOptions o;
    o.vpl.count = 64;
    o.ism = ism;
    Renderer r(s.scene, s.cam, o);
    r.render({s.pose, {}, false});
    const std::vector<GpuVpl> vpls = r.readVpls();
    const cv::Mat atlas = r.readIsmAtlas(false);
    const int tile = ism.tileSize, perRow = atlas.cols / tile;
    VisibilityErrors e;
    for (size_t i = 0; i < vpls.size(); ++i) {
        const GpuVpl& v = vpls[i];
        // The wall's lit face (x = -0.9): the VPLs the plate can shadow.
        if (v.valid == 0 || std::abs(v.position.x + 0.9f) > 0.01f) continue;
        const glm::dvec3 q(v.position), n(v.normal), t(v.tangent), b = glm::cross(n, t);
        const glm::ivec2 origin(int(i) % perRow * tile, int(i) / perRow * tile);
        for (double x = -0.85; x <= 0.6; x += 0.05)
            for (double z = -0.5; z <= 0.5; z += 0.05) {
                const glm::dvec3 p(x, 0.0, z), d = p - q;
                const double dist = glm::length(d);
                const glm::dvec3 w = d / dist;
                if (glm::dot(n, w) <= 0.0 || w.y >= 0.0) continue;  // outside either lobe
                // The indirect pass's lookup (common.glsl paraboloidUv / ismDistance,
                // indirect.frag's bias).
                const glm::dvec2 puv =
                    glm::dvec2(glm::dot(w, t), glm::dot(w, b)) / (1.0 + glm::dot(w, n));
                const glm::ivec2 texel =
                    glm::clamp(glm::ivec2((puv * 0.5 + 0.5) * double(tile)), 0, tile - 1);
                const float depth = atlas.at<float>(origin.y + texel.y, origin.x + texel.x);
                const bool ismVisible = dist - (0.02 + 0.03 * dist) <= double(depth);
                if (test::segmentHitsBox(q, p, s.plateLo, s.plateHi)) {
                    ++e.occluded;
                    e.leaks += ismVisible;
                    e.leaksThroughEmpty += ismVisible && std::isinf(depth);
                } else {
                    ++e.visible;
                    e.falseShadows += !ismVisible;
                }
            }
    }
    return e;
}

void print(const char* name, const VisibilityErrors& e) {
    std::printf(
        "%s: leaks %d of %d occluded pairs (%.1f %%; %d through empty texels), false "
        "shadow %d of %d visible pairs (%.1f %%)\n",
        name, e.leaks, e.occluded, 100.0 * e.leakRate(), e.leaksThroughEmpty, e.falseShadows,
        e.visible, 100.0 * e.falseShadowRate());
}

// Pull-push fills the texels no point reached: those leaks fall by more than 40 % (measured
// 1,448 -> 616 pairs, 64 texels, 1,024 points). It is no cure: most of the plate's gaps show
// the floor behind it, a depth pull-push leaves alone, so all leaks fall ~10 % (14.6 -> 13.2 %),
// and the filled texels at the plate's outline shadow ~17 % more visible pairs (54 -> 63 %; the
// floor's own grazing texels make most of those). Hence off by default.
TEST_F(ImperfectShadowMaps, PullPushClosesTheEmptyGapsInAnOccluder) {
    IsmOptions splatsOnly, filled;
    filled.pullPush = true;
    const VisibilityErrors off = measure(splatsOnly), on = measure(filled);
    print("splats only", off);
    print("pull-push", on);
    ASSERT_GT(on.occluded, 10000);
    ASSERT_GT(on.visible, 1000);
    // The must-fail: the splats alone leave at least this many leaks through empty texels.
    const int bound = int(0.6 * off.leaksThroughEmpty);
    EXPECT_LE(on.leaksThroughEmpty, bound);
    EXPECT_GT(off.leaksThroughEmpty, bound) << "must-fail";
    EXPECT_LE(on.leakRate(), off.leakRate());
    EXPECT_LE(on.falseShadowRate(), 1.25 * off.falseShadowRate());
}

// What sets the ISM's error is the points per VPL: 4x the points (4,096) halve both the leaks
// (14.6 -> 8.0 %) and the false shadow (54 -> 28 %), where a finer tile (128 texels) with the
// same points leaks more (40.8 %: each point covers fewer texels). The default stays 64 / 1,024:
// on the tabletop the composite does not change with either (docs/realtime-renderer.md).
TEST_F(ImperfectShadowMaps, MorePointsHalveTheErrorAndAFinerTileLeaksMore) {
    IsmOptions base, morePoints, finerTile;
    morePoints.pointsPerVpl = 4096;
    finerTile.tileSize = 128;
    const VisibilityErrors b = measure(base), p = measure(morePoints), t = measure(finerTile);
    print("64 texels, 1,024 points", b);
    print("64 texels, 4,096 points", p);
    print("128 texels, 1,024 points", t);
    EXPECT_LT(p.leakRate(), 0.7 * b.leakRate());
    EXPECT_LT(p.falseShadowRate(), 0.7 * b.falseShadowRate());
    EXPECT_GT(t.leakRate(), 1.5 * b.leakRate());
}

}  // namespace
}  // namespace mirage::render
