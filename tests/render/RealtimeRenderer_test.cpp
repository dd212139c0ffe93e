// The real-time renderer on llvmpipe, against closed forms and the routing rules of differential
// instant radiosity (docs/realtime-renderer.md "Real and virtual: routing"). Small images so the
// suite stays fast.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/direct/DirectLightPass.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"
#include "testscenes/WallPlateScene.h"

namespace mirage::render {
namespace {

// Options that keep the direct light apart (DirectRv / DirectR) in frames with VPL light, where
// the direct-light pass otherwise writes only its sum with the indirect light (LRv / LR).
RendererOptions directLightKept() {
    RendererOptions o;
    o.direct.keepDirectLight = true;
    return o;
}

using test::addBox;
using test::addFloor;
using test::addLight;
using test::addMaterial;
using test::lookAtPose;
using test::smallCamera;

class RealtimeRenderer : public test::HeadlessGlSuite {};

// Independent CPU evaluation of the shading model (Lambert + GGX/Smith-Schlick/Schlick, glTF
// metallic-roughness) for the closed-form checks.
glm::dvec3 brdfCos(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, glm::dvec3 base, double metallic,
                   double roughness) {
    const double NL = std::max(glm::dot(n, l), 0.0), NV = std::max(glm::dot(n, v), 1e-4);
    if (NL <= 0) return glm::dvec3(0);
    const glm::dvec3 h = glm::normalize(l + v);
    const double NH = std::max(glm::dot(n, h), 0.0), VH = std::max(glm::dot(v, h), 0.0);
    const double a = std::max(roughness * roughness, 1e-3), a2 = a * a;
    const double dd = NH * NH * (a2 - 1) + 1;
    const double D = a2 / (M_PI * dd * dd), k = a / 2;
    const double G = NL / (NL * (1 - k) + k) * NV / (NV * (1 - k) + k);
    const glm::dvec3 F0 = glm::mix(glm::dvec3(0.04), base, metallic);
    const glm::dvec3 F = F0 + (1.0 - F0) * std::pow(1 - VH, 5.0);
    return ((1.0 - F) * (1 - metallic) * base / M_PI + D * G * F / (4 * NL * NV)) * NL;
}

using test::floorHit;
using test::segmentHitsBox;

bool allFinite(const cv::Mat& m) {
    return cv::checkRange(m, true, nullptr, -1e30, 1e30);
}

struct SpotScene {
    Scene scene;
    glm::dvec3 lightPos{0, 2, 0};
    double intensity = 8.0, outer = 0.6, inner = 0.5, albedo = 0.8;
    Pose pose = lookAtPose({0, 2.5, 2.5}, {0, 0, 0});
    CameraIntrinsics cam = smallCamera();
    SpotScene() {
        int m = addMaterial(scene, glm::vec3(float(albedo)));
        addFloor(scene, "floor", 0.0f, 4.0f, m, Origin::Real);
        addLight(scene, Light::Type::Spot, glm::vec3(lightPos), {0, -1, 0}, float(intensity),
                 Origin::Real, float(outer), float(inner));
    }
    // Closed-form radiance (linear) of the lit floor at p, inside the inner cone.
    glm::dvec3 expected(glm::dvec3 p, double intensityScale = 1.0) const {
        const glm::dvec3 l = lightPos - p;
        const double d2 = glm::dot(l, l);
        return brdfCos({0, 1, 0}, glm::normalize(pose.translation - p), glm::normalize(l),
                       glm::dvec3(albedo), 0.0, 1.0) *
               (intensity * intensityScale / d2);
    }
    double coneAngle(glm::dvec3 p) const {
        return std::acos(glm::dot(glm::normalize(p - lightPos), glm::dvec3(0, -1, 0)));
    }
};

// The image of a lit plane matches the closed-form irradiance from a spot light (E = I cos / d^2
// through the BRDF), inside the inner cone, and is black outside the outer cone.
TEST_F(RealtimeRenderer, SpotLitPlaneMatchesClosedForm) {
    SpotScene s;
    Renderer r(s.scene, s.cam);
    const FrameReport& rep = r.render({s.pose, {}, false});
    EXPECT_TRUE(rep.ran("gbuffer"));
    EXPECT_TRUE(rep.ran("direct"));
    cv::Mat rv = r.readBuffer(kDirectRv), lr = r.readBuffer(kDirectR);
    int inside = 0, outside = 0;
    for (int y = 0; y < s.cam.height; ++y)
        for (int x = 0; x < s.cam.width; ++x) {
            auto p = floorHit(s.cam, s.pose, x, y);
            if (!p || std::abs(p->x) > 1.9 || std::abs(p->z) > 1.9) continue;
            const double angle = s.coneAngle(*p);
            const cv::Vec3f got = rv.at<cv::Vec3f>(y, x);
            if (angle < s.inner - 0.03) {
                const glm::dvec3 e = s.expected(*p);
                ASSERT_NEAR(got[0], e.x, 0.01 * e.x + 1e-4) << "pixel " << x << "," << y;
                ASSERT_NEAR(got[1], e.y, 0.01 * e.y + 1e-4);
                ASSERT_NEAR(lr.at<cv::Vec3f>(y, x)[0], got[0], 1e-6);  // all real: L_r == L_rv
                ++inside;
            } else if (angle > s.outer + 0.03) {
                ASSERT_EQ(got[0], 0.0f);
                ++outside;
            }
        }
    EXPECT_GT(inside, 500);
    EXPECT_GT(outside, 500);
}

// Point light (cube shadow map) and directional light (orthographic shadow map): the floor
// matches the closed form where lit, and a real box's shadow (under the point light: the -Y cube
// face; under the directional light: offset along the light direction) is dark in both solutions.
TEST_F(RealtimeRenderer, PointAndDirectionalLightsMatchClosedForm) {
    const CameraIntrinsics cam = smallCamera();
    const Pose pose = lookAtPose({0, 2.5, 2.5}, {0, 0, 0});
    for (Light::Type type : {Light::Type::Point, Light::Type::Directional}) {
        Scene scene;
        int m = addMaterial(scene, glm::vec3(0.6f));
        addFloor(scene, "floor", 0.0f, 4.0f, m, Origin::Real);
        addBox(scene, "box", {-0.15f, 0.6f, -0.15f}, {0.15f, 0.7f, 0.15f}, m, Origin::Real);
        const glm::dvec3 lightPos(0, 1.5, 0);
        const glm::dvec3 dir = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
        const float intensity = type == Light::Type::Point ? 5.0f : 2.0f;
        addLight(scene, type, glm::vec3(lightPos), glm::vec3(dir), intensity, Origin::Real);
        Renderer r(scene, cam);
        const FrameReport& rep = r.render({pose, {}, false});
        ASSERT_TRUE(rep.ran("shadow"));
        EXPECT_EQ(r.plan().lights[0].layers, type == Light::Type::Point ? 6 : 1);
        cv::Mat rv = r.readBuffer(kDirectRv), lr = r.readBuffer(kDirectR);
        cv::Mat cover = r.coverage();
        int lit = 0, shadowed = 0;
        for (int y = 0; y < cam.height; ++y)
            for (int x = 0; x < cam.width; ++x) {
                auto p = floorHit(cam, pose, x, y);
                if (!p || cover.at<uint8_t>(y, x) != 1 || std::abs(p->x) > 1.8 ||
                    std::abs(p->z) > 1.8)
                    continue;
                if (segmentHitsBox(pose.translation, *p, {-0.17, 0.58, -0.17}, {0.17, 0.72, 0.17}))
                    continue;  // the camera sees the box there, not the floor
                // Where does the ray from p towards the light cross the box's height (y=0.65)?
                const glm::dvec3 toL =
                    type == Light::Type::Point ? glm::normalize(lightPos - *p) : -dir;
                const glm::dvec3 c = *p + toL * (0.65 / toL.y);
                const double m2 = std::max(std::abs(c.x), std::abs(c.z));
                const glm::dvec3 v = glm::normalize(pose.translation - *p);
                glm::dvec3 e = type == Light::Type::Point
                                   ? brdfCos({0, 1, 0}, v, toL, glm::dvec3(0.6), 0, 1) *
                                         (5.0 / glm::dot(lightPos - *p, lightPos - *p))
                                   : brdfCos({0, 1, 0}, v, toL, glm::dvec3(0.6), 0, 1) * 2.0;
                const float got = rv.at<cv::Vec3f>(y, x)[0];
                if (m2 > 0.2) {
                    ASSERT_NEAR(got, e.x, 0.02 * e.x + 1e-4) << x << "," << y;
                    ++lit;
                } else if (m2 < 0.1) {
                    ASSERT_LT(got, 0.05 * e.x) << x << "," << y;
                    ASSERT_LT(lr.at<cv::Vec3f>(y, x)[0], 0.05 * e.x);
                    ++shadowed;
                }
            }
        EXPECT_GT(lit, 2000);
        EXPECT_GT(shadowed, 20);
    }
}

// The comparison used above catches a broken render: a 30 % too bright light and a light 30 cm
// off both fall far below the PSNR the correct render reaches against the closed form.
TEST_F(RealtimeRenderer, ClosedFormComparisonFailsOnBrokenRender) {
    SpotScene s;
    cv::Mat expected(s.cam.height, s.cam.width, CV_32FC3, cv::Scalar(0, 0, 0));
    cv::Mat mask(s.cam.height, s.cam.width, CV_8U, cv::Scalar(0));
    for (int y = 0; y < s.cam.height; ++y)
        for (int x = 0; x < s.cam.width; ++x) {
            auto p = floorHit(s.cam, s.pose, x, y);
            if (!p || std::abs(p->x) > 1.9 || std::abs(p->z) > 1.9 || s.coneAngle(*p) > s.inner)
                continue;
            glm::dvec3 e = s.expected(*p);
            expected.at<cv::Vec3f>(y, x) = cv::Vec3f(float(e.x), float(e.y), float(e.z));
            mask.at<uint8_t>(y, x) = 255;
        }
    auto renderMasked = [&](const Scene& scene, const Pose& pose) {
        Renderer r(scene, s.cam);
        r.render({pose, {}, false});
        cv::Mat got = r.readBuffer(kDirectRv), out(got.size(), got.type(), cv::Scalar(0));
        got.copyTo(out, mask);
        return out;
    };
    double peak = 0;  // the brightest expected radiance (linear)
    cv::minMaxLoc(expected.reshape(1), nullptr, &peak);
    const double good = test::psnr(renderMasked(s.scene, s.pose), expected, peak);
    EXPECT_GT(good, 45.0);
    std::printf("closed-form PSNR %.1f dB\n", good);
    Scene bright = s.scene;
    bright.lights[0].intensity *= 1.3f;
    EXPECT_LT(test::psnr(renderMasked(bright, s.pose), expected, peak), 30.0);
    Scene shifted = s.scene;  // the light 30 cm off its calibrated position
    shifted.nodes[1].world[3].x += 0.3;
    EXPECT_LT(test::psnr(renderMasked(shifted, s.pose), expected, peak), 30.0);
}

// A virtual box's shadow on the real floor appears only in L_rv; L_r keeps the unshadowed light,
// so the composite darkens the camera image there and leaves it unchanged elsewhere.
TEST_F(RealtimeRenderer, VirtualShadowOnlyInLrv) {
    SpotScene s;
    s.lightPos = {1.2, 2.0, 0.0};
    s.scene = Scene{};
    int white = addMaterial(s.scene, glm::vec3(float(s.albedo)));
    addFloor(s.scene, "floor", 0.0f, 4.0f, white, Origin::Real);
    const glm::vec3 lo(-0.2f, 0.0f, -0.2f), hi(0.2f, 0.4f, 0.2f);
    addBox(s.scene, "virtual box", lo, hi, white, Origin::Virtual);
    const glm::dvec3 axis = glm::normalize(glm::dvec3(-0.6, 0, 0) - s.lightPos);
    addLight(s.scene, Light::Type::Spot, glm::vec3(s.lightPos), glm::vec3(axis), 8.0f, Origin::Real,
             1.0f, 0.9f);
    RendererOptions opt;
    opt.direct.keepDirectLight = true;  // DirectRv apart from LRv (this scene has VPLs)
    opt.vpl.count = 64;
    Renderer r(s.scene, s.cam, opt);
    // Footage: the real world alone, as the camera would see it (L_r, sRGB-encoded).
    r.render({s.pose, {}, false});
    cv::Mat footage = linearRgbToSrgbBgr8(r.readBuffer(kLR));
    const FrameReport& rep = r.render({s.pose, footage, false});
    // Second frame, same plan: the shadow maps and VPLs of the first are reused.
    EXPECT_TRUE(rep.reused("shadow")) << rep.summary();
    EXPECT_TRUE(rep.reused("vpl")) << rep.summary();
    EXPECT_TRUE(r.plan().lights[0].needsRealOnlyMap);
    cv::Mat drv = r.readBuffer(kDirectRv), dr = r.readBuffer(kDirectR);
    cv::Mat comp = r.compositeLinear(), cover = r.coverage();
    cv::Mat ci = srgbBgr8ToLinearRgb(footage);

    // Segment p -> light against the box (slab test), shrunk/grown to stay off the penumbra.
    auto blocked = [&](glm::dvec3 p, double grow) {
        glm::dvec3 d = s.lightPos - p, l = glm::dvec3(lo) - grow, h = glm::dvec3(hi) + grow;
        double t0 = 0, t1 = 1;
        for (int i = 0; i < 3; ++i) {
            if (std::abs(d[i]) < 1e-12) {
                if (p[i] < l[i] || p[i] > h[i]) return false;
                continue;
            }
            double a = (l[i] - p[i]) / d[i], b = (h[i] - p[i]) / d[i];
            t0 = std::max(t0, std::min(a, b));
            t1 = std::min(t1, std::max(a, b));
        }
        return t0 <= t1;
    };
    int shadowed = 0, lit = 0;
    for (int y = 0; y < s.cam.height; ++y)
        for (int x = 0; x < s.cam.width; ++x) {
            if (cover.at<uint8_t>(y, x) != 1) continue;
            auto p = floorHit(s.cam, s.pose, x, y);
            if (!p || s.coneAngle(*p) > 0.85) continue;
            const float rv = drv.at<cv::Vec3f>(y, x)[0], rr = dr.at<cv::Vec3f>(y, x)[0];
            if (blocked(*p, -0.04)) {  // well inside the shadow
                EXPECT_LT(rv, 0.05f * rr) << x << "," << y;
                EXPECT_GT(rr, 0.05f);
                EXPECT_LT(comp.at<cv::Vec3f>(y, x)[0], 0.6f * ci.at<cv::Vec3f>(y, x)[0]);
                ++shadowed;
            } else if (!blocked(*p, 0.06)) {  // well outside
                EXPECT_NEAR(rv, rr, 1e-4f);
                ++lit;
            }
        }
    EXPECT_GT(shadowed, 30);
    EXPECT_GT(lit, 1000);
    // Away from the box, the composite is the footage (within the VPL bleeding it adds).
    cv::Mat realMask = cover == 1;
    EXPECT_GT(test::psnr(comp.clone().setTo(0, ~realMask), ci.clone().setTo(0, ~realMask), 1.0),
              20.0);
    // The box itself shows L_rv.
    EXPECT_GT(cv::countNonZero(cover == 2), 100);
}

// With only real objects, routing puts everything in both solutions: L_rv == L_r (VPLs, ISMs
// and shadows included, pass culling off) and the composite reproduces the camera image.
TEST_F(RealtimeRenderer, RealOnlySceneCompositeEqualsFootage) {
    SpotScene s;
    int red = addMaterial(s.scene, {0.8f, 0.1f, 0.1f});
    addBox(s.scene, "real box", {-0.3f, 0.0f, -0.3f}, {0.3f, 0.5f, 0.3f}, red, Origin::Real);
    RendererOptions opt;
    opt.graph.cullPasses = false;
    opt.vpl.count = 64;
    Renderer r(s.scene, s.cam, opt);
    cv::Mat footage(s.cam.height, s.cam.width, CV_8UC3);
    cv::randu(footage, 0, 255);
    const FrameReport& rep = r.render({s.pose, footage, false});
    ASSERT_TRUE(rep.ran("vpl")) << rep.summary();
    ASSERT_TRUE(rep.ran("ism"));
    ASSERT_TRUE(rep.ran("gifilter"));
    cv::Mat rv = r.readBuffer(kLRv), lr = r.readBuffer(kLR);
    EXPECT_LE(cv::norm(rv, lr, cv::NORM_INF), 1e-6);
    EXPECT_GT(cv::norm(rv, cv::NORM_INF), 0.1);  // something was lit
    EXPECT_GT(test::psnr(r.compositeSrgb(), footage, 255.0), 50.0);
}

// A black real surface (L_r = 0) and a virtual light on a surface real light does not reach:
// alpha stays finite (fades to 1 where L_r ~ 0), the composite is finite and bounded.
TEST_F(RealtimeRenderer, ZeroLrIsGuarded) {
    Scene scene;
    int black = addMaterial(scene, glm::vec3(0.0f));
    int grey = addMaterial(scene, glm::vec3(0.5f));
    addFloor(scene, "black floor", 0.0f, 4.0f, black, Origin::Real);
    addFloor(scene, "grey tile", 0.001f, 1.0f, grey, Origin::Real, 0.8f, 0.0f);
    addLight(scene, Light::Type::Spot, {0, 2, 0}, {0, -1, 0}, 20.0f, Origin::Virtual, 1.0f, 0.9f);
    const CameraIntrinsics cam = smallCamera();
    const Pose pose = lookAtPose({0, 2.5, 2.5}, {0, 0, 0});
    Renderer r(scene, cam);
    cv::Mat footage(cam.height, cam.width, CV_8UC3, cv::Scalar(40, 90, 140));
    r.render({pose, footage, false});
    cv::Mat comp = r.compositeLinear(), lr = r.readBuffer(kDirectR), rv = r.readBuffer(kDirectRv);
    ASSERT_TRUE(allFinite(comp));
    EXPECT_EQ(cv::norm(lr, cv::NORM_INF), 0.0);  // a virtual light never reaches L_r
    EXPECT_GT(cv::norm(rv, cv::NORM_INF), 0.5);  // but lights the grey tile in L_rv
    cv::Mat ci = srgbBgr8ToLinearRgb(footage);
    double maxRv = cv::norm(rv, cv::NORM_INF);
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = comp.at<cv::Vec3f>(y, x)[c];
                ASSERT_GE(v, 0.0f);
                ASSERT_LE(v, ci.at<cv::Vec3f>(y, x)[c] + maxRv + 1e-3) << x << "," << y;
            }
}

// A very bright light and a virtual object crossing the near plane: no NaN or Inf in any buffer.
TEST_F(RealtimeRenderer, BrightLightAndNearPlaneStayFinite) {
    Scene scene;
    int white = addMaterial(scene, glm::vec3(0.9f));
    addFloor(scene, "floor", 0.0f, 4.0f, white, Origin::Real);
    addLight(scene, Light::Type::Point, {0.3f, 1.0f, 0.0f}, {0, -1, 0}, 1e7f, Origin::Real);
    const Pose pose = lookAtPose({0, 1.0, 2.0}, {0, 0, 0});
    // A virtual box whose front part is behind the camera: it crosses the near plane.
    addBox(scene, "near box", {-0.3f, 0.7f, 1.6f}, {0.3f, 1.3f, 2.4f}, white, Origin::Virtual);
    const CameraIntrinsics cam = smallCamera();
    Renderer r(scene, cam, directLightKept());
    cv::Mat footage(cam.height, cam.width, CV_8UC3, cv::Scalar(200, 200, 200));
    const FrameReport& rep = r.render({pose, footage, false});
    ASSERT_TRUE(rep.ran("vpl")) << rep.summary();
    for (Resource b : {kDirectRv, kDirectR, kLRv, kLR})
        EXPECT_TRUE(allFinite(r.readBuffer(b))) << resourceName(b);
    EXPECT_TRUE(allFinite(r.compositeLinear()));
    EXPECT_GT(cv::countNonZero(r.coverage() == 2), 50);
    cv::Mat srgb = r.compositeSrgb();
    double maxVal = 0;
    cv::minMaxLoc(srgb.reshape(1), nullptr, &maxVal);
    EXPECT_EQ(maxVal, 255.0);
}

// The test scenes' UV sphere is wound outward: the reference renderer takes a glass surface's
// outside from the winding (an inward-wound glass sphere renders as an air bubble in glass).
TEST(RenderTestScenes, UvSphereIsWoundOutward) {
    Scene s;
    const glm::vec3 centre(0.3f, 0.5f, -0.2f);
    test::addUvSphere(s, "sphere", centre, 0.4f, test::addMaterial(s, glm::vec3(0.5f)),
                      Origin::Real, 8, 12);
    const Primitive& p = s.meshes.back().primitives.front();
    int checked = 0;
    for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
        const glm::vec3 a = p.positions[p.indices[t]], b = p.positions[p.indices[t + 1]],
                        c = p.positions[p.indices[t + 2]];
        const glm::vec3 ng = glm::cross(b - a, c - a);
        if (glm::length(ng) < 1e-8f) continue;  // degenerate triangles at the poles
        EXPECT_GT(glm::dot(ng, (a + b + c) / 3.0f - centre), 0.0f) << "triangle " << t / 3;
        ++checked;
    }
    EXPECT_GT(checked, 8 * 12);
}

// Shadow maps, RSMs, VPLs and ISMs do not depend on the camera: from the second frame on they are
// reused (reported, 0 ms), and the frame is the one a renderer running every pass produces.
TEST_F(RealtimeRenderer, CameraIndependentPassesAreReusedAcrossFrames) {
    SpotScene s;
    int red = addMaterial(s.scene, {0.8f, 0.1f, 0.1f});
    addBox(s.scene, "virtual box", {-0.3f, 0.0f, -0.3f}, {0.3f, 0.5f, 0.3f}, red, Origin::Virtual);
    RendererOptions opt;
    opt.vpl.count = 64;
    opt.temporalBlend = 0.0f;  // frames comparable one by one
    cv::Mat footage(s.cam.height, s.cam.width, CV_8UC3, cv::Scalar(90, 100, 110));
    const Pose second = lookAtPose({0.8, 2.2, 2.6}, {0, 0.2, 0});
    Renderer reusing(s.scene, s.cam, opt);
    const FrameReport& first = reusing.render({s.pose, footage, true});
    for (const char* pass : {"shadow", "vpl", "ism"}) EXPECT_TRUE(first.ran(pass)) << pass;
    const FrameReport& rep = reusing.render({second, footage, true});
    for (const char* pass : {"shadow", "vpl", "ism"}) {
        EXPECT_FALSE(rep.ran(pass)) << pass;
        EXPECT_TRUE(rep.reused(pass)) << rep.summary();
    }
    EXPECT_TRUE(rep.ran("indirect"));
    EXPECT_NE(rep.summary().find("reused"), std::string::npos);

    opt.graph.reuseStaticPasses = false;
    Renderer fresh(s.scene, s.cam, opt);
    fresh.render({s.pose, footage, true});
    const FrameReport& again = fresh.render({second, footage, true});
    for (const char* pass : {"shadow", "vpl", "ism"}) EXPECT_TRUE(again.ran(pass)) << pass;
    EXPECT_GT(test::psnr(reusing.compositeSrgb(), fresh.compositeSrgb(), 255.0), 60.0);
    // The comparison can fail: the first pose's frame differs from the second's.
    fresh.render({s.pose, footage, true});
    EXPECT_LT(test::psnr(reusing.compositeSrgb(), fresh.compositeSrgb(), 255.0), 40.0);
}

// Passes run only when the scene needs them, and say why.
TEST_F(RealtimeRenderer, ReportsWhichPassesRanAndWhy) {
    SpotScene s;
    {
        Renderer r(s.scene, s.cam);
        const FrameReport& rep = r.render({s.pose, {}, false});
        EXPECT_TRUE(rep.ran("shadow"));
        EXPECT_FALSE(rep.ran("vpl"));
        EXPECT_FALSE(rep.ran("ism"));
        EXPECT_FALSE(rep.ran("indirect"));
        EXPECT_TRUE(rep.ran("composite"));
        EXPECT_NE(rep.summary().find("no light reaches a virtual object"), std::string::npos)
            << rep.summary();
        for (const PassReport& p : rep.passes) EXPECT_FALSE(p.reason.empty()) << p.name;
    }
    {
        Scene up = s.scene;  // the spot light turned to the sky: no caster in its cone
        int m = addMaterial(up, glm::vec3(0.5f));
        addBox(up, "virtual box", {-0.1f, 0.0f, -0.1f}, {0.1f, 0.2f, 0.1f}, m, Origin::Virtual);
        up.nodes[1].world = glm::dmat4(1.0);            // node -Z = world -Z, light at the origin
        up.nodes[1].world[3] = glm::dvec4(0, 5, 0, 1);  // outside the floor's bounds
        up.nodes[1].world[2] = glm::dvec4(0, -1, 0, 0);
        up.nodes[1].world[1] = glm::dvec4(0, 0, 1, 0);
        Renderer r(up, s.cam);
        const FrameReport& rep = r.render({s.pose, {}, false});
        EXPECT_FALSE(rep.ran("shadow")) << rep.summary();
        EXPECT_NE(rep.summary().find("no light has a shadow caster"), std::string::npos);
        EXPECT_FALSE(rep.ran("vpl"));
    }
}

// VPLs on a lit virtual red wall bleed red onto the real white floor: in L_rv only.
TEST_F(RealtimeRenderer, VirtualColourBleedsOntoRealFloor) {
    Scene scene;
    int white = addMaterial(scene, glm::vec3(0.8f));
    int red = addMaterial(scene, {0.9f, 0.05f, 0.05f});
    addFloor(scene, "floor", 0.0f, 4.0f, white, Origin::Real);
    addBox(scene, "red wall", {0.3f, 0.0f, -0.6f}, {0.5f, 0.8f, 0.6f}, red, Origin::Virtual);
    addLight(scene, Light::Type::Spot, {-0.8f, 1.2f, 0.0f},
             glm::normalize(glm::vec3(0.4f, 0.3f, 0.0f) - glm::vec3(-0.8f, 1.2f, 0.0f)), 10.0f,
             Origin::Real, 1.0f, 0.9f);
    const CameraIntrinsics cam = smallCamera();
    const Pose pose = lookAtPose({-0.5, 1.6, 2.2}, {0.1, 0.0, 0.0});
    Renderer r(scene, cam, directLightKept());
    r.render({pose, {}, false});
    cv::Mat rv = r.readBuffer(kLRv), lr = r.readBuffer(kLR);
    // For inspection (linear EXR; PNG is sRGB-encoded).
    const auto out = test::outputDir("realtime_bleed");
    writeLinearRgb(out / "L_rv.exr", rv);
    writeLinearRgb(out / "L_r.exr", lr);
    writeLinearRgb(out / "L_rv.png", rv);
    writeLinearRgb(out / "L_r.png", lr);
    cv::Mat drv = r.readBuffer(kDirectRv), dr = r.readBuffer(kDirectR);
    cv::Mat cover = r.coverage();
    double sumR = 0, sumG = 0;
    int n = 0;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            auto p = floorHit(cam, pose, x, y);
            if (!p || cover.at<uint8_t>(y, x) != 1) continue;
            if (p->x < 0.0 || p->x > 0.28 || std::abs(p->z) > 0.4) continue;
            // Indirect difference only (direct light is not shadowed there).
            cv::Vec3f d = (rv.at<cv::Vec3f>(y, x) - drv.at<cv::Vec3f>(y, x)) -
                          (lr.at<cv::Vec3f>(y, x) - dr.at<cv::Vec3f>(y, x));
            sumR += d[0];
            sumG += d[1];
            ++n;
        }
    ASSERT_GT(n, 50);
    EXPECT_GT(sumR / n, 0.005);
    EXPECT_GT(sumR, 4.0 * std::abs(sumG));
}

// The imperfect shadow maps get the boxes' points (floor VPLs do not see the floor itself: it
// lies in their horizon), and the real-only atlas holds fewer (the virtual box is left out).
TEST_F(RealtimeRenderer, ImperfectShadowMapsAreFilled) {
    SpotScene s;
    int m = addMaterial(s.scene, glm::vec3(0.5f));
    addBox(s.scene, "virtual box", {-0.3f, 0.0f, -0.3f}, {0.3f, 0.6f, 0.3f}, m, Origin::Virtual);
    addBox(s.scene, "real box", {0.5f, 0.0f, -0.3f}, {0.9f, 0.6f, 0.3f}, m, Origin::Real);
    RendererOptions opt;
    opt.vpl.count = 16;
    Renderer r(s.scene, s.cam, opt);
    r.render({s.pose, {}, false});
    ASSERT_TRUE(r.plan().needRealOnlyIsm);
    cv::Mat all = r.readIsmAtlas(false), real = r.readIsmAtlas(true);
    const int tile = opt.ism.tileSize;
    int coveredAll = 0, coveredReal = 0;
    for (int y = 0; y < all.rows; ++y)
        for (int x = 0; x < all.cols; ++x) {
            coveredAll += std::isfinite(all.at<float>(y, x));
            coveredReal += std::isfinite(real.at<float>(y, x));
            if (std::isfinite(all.at<float>(y, x)) && std::isfinite(real.at<float>(y, x))) {
                ASSERT_LE(all.at<float>(y, x), real.at<float>(y, x));  // min over a superset
            }
        }
    std::printf("ISM coverage: %.1f %% (all), %.1f %% (real only) of %d tiles\n",
                100.0 * coveredAll / (16.0 * tile * tile),
                100.0 * coveredReal / (16.0 * tile * tile), 16);
    EXPECT_GT(coveredAll, 16 * tile * tile / 20);
    EXPECT_GT(coveredReal, 16 * tile * tile / 100);
    EXPECT_LT(coveredReal, coveredAll);
}

// A virtual plate between a lit real wall and the real floor blocks the bounced light in L_rv
// (ISM over all points) but not in L_r (ISM over real points only).
TEST_F(RealtimeRenderer, VirtualOccluderBlocksBouncedLightOnlyInLrv) {
    const test::WallPlateScene s = test::makeWallPlateScene();
    const CameraIntrinsics& cam = s.cam;
    const Pose& pose = s.pose;
    Renderer r(s.scene, cam, directLightKept());
    const FrameReport& rep = r.render({pose, {}, false});
    ASSERT_TRUE(rep.ran("ism")) << rep.summary();
    cv::Mat rv = r.readBuffer(kLRv), lr = r.readBuffer(kLR);
    cv::Mat drv = r.readBuffer(kDirectRv), dr = r.readBuffer(kDirectR);
    cv::Mat cover = r.coverage();
    double indRv = 0, indR = 0;
    int n = 0;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            auto p = floorHit(cam, pose, x, y);
            if (!p || cover.at<uint8_t>(y, x) != 1) continue;
            if (p->x < -0.75 || p->x > -0.4 || std::abs(p->z) > 0.3) continue;
            indRv += rv.at<cv::Vec3f>(y, x)[0] - drv.at<cv::Vec3f>(y, x)[0];
            indR += lr.at<cv::Vec3f>(y, x)[0] - dr.at<cv::Vec3f>(y, x)[0];
            ++n;
        }
    ASSERT_GT(n, 30);
    std::printf("bounced light under the plate: L_rv %.4f, L_r %.4f (mean, red)\n", indRv / n,
                indR / n);
    EXPECT_GT(indR / n, 0.01);
    EXPECT_LT(indRv, 0.7 * indR);
}

// Temporal smoothing: history is used on the next frame of a static view and dropped on a
// reset (cut or tracking loss); a static scene converges to the same image either way.
TEST_F(RealtimeRenderer, TemporalHistoryUsedAndReset) {
    SpotScene s;
    int m = addMaterial(s.scene, {0.2f, 0.7f, 0.2f});
    addBox(s.scene, "virtual box", {-0.2f, 0.0f, -0.2f}, {0.2f, 0.4f, 0.2f}, m, Origin::Virtual);
    Renderer r(s.scene, s.cam);
    r.render({s.pose, {}, false});
    EXPECT_NE(r.lastReport().summary().find("history reset"), std::string::npos);
    cv::Mat first = r.readBuffer(kLRv);
    r.render({s.pose, {}, false});
    EXPECT_NE(r.lastReport().summary().find("history used"), std::string::npos);
    cv::Mat second = r.readBuffer(kLRv);
    EXPECT_GT(test::psnr(first, second, 1.0), 50.0);  // static: nothing to flicker
    r.render({s.pose, {}, true});
    EXPECT_NE(r.lastReport().summary().find("history reset"), std::string::npos);
    // A moving camera reprojects history without producing NaN.
    for (int i = 0; i < 3; ++i) {
        Pose p = lookAtPose({0.1 * i, 2.5, 2.5}, {0, 0, 0});
        r.render({p, {}, false});
        EXPECT_TRUE(allFinite(r.readBuffer(kLRv)));
    }
}

// The history really reaches the image: after a small camera move, the smoothed indirect light
// differs from a fresh render of the same view (the previous frame's light is blended in), yet
// stays close to it (the scene is static, both estimate the same light). A pass that lost its
// history between frames (e.g. by reallocating it) would match the fresh render exactly.
TEST_F(RealtimeRenderer, TemporalHistoryReachesTheImage) {
    SpotScene s;
    int m = addMaterial(s.scene, {0.2f, 0.7f, 0.2f});
    addBox(s.scene, "virtual box", {-0.2f, 0.0f, -0.2f}, {0.2f, 0.4f, 0.2f}, m, Origin::Virtual);
    const Pose before = lookAtPose({0.0, 2.5, 2.5}, {0, 0, 0});
    const Pose after = lookAtPose({0.03, 2.5, 2.5}, {0, 0, 0});
    Renderer smoothed(s.scene, s.cam);
    smoothed.render({before, {}, false});
    smoothed.render({after, {}, false});
    ASSERT_TRUE(smoothed.lastReport().summary().find("history used") != std::string::npos);
    const cv::Mat withHistory = smoothed.readBuffer(kLRv);
    Renderer fresh(s.scene, s.cam);
    fresh.render({after, {}, true});
    const cv::Mat withoutHistory = fresh.readBuffer(kLRv);
    double maxDiff = 0.0;
    const cv::Mat diff = cv::abs(withHistory - withoutHistory);
    cv::minMaxLoc(diff.reshape(1), nullptr, &maxDiff);
    EXPECT_GT(maxDiff, 1e-3) << "the history left no trace";
    std::printf("[ temporal ] max |smoothed - fresh| = %g, PSNR %.1f dB\n", maxDiff,
                test::psnr(withHistory, withoutHistory, 1.0));
    EXPECT_GT(test::psnr(withHistory, withoutHistory, 1.0), 35.0);
    EXPECT_TRUE(allFinite(withHistory));
}

// Constant environment radiance Le on a Lambertian plane: L = albedo * Le (irradiance pi Le).
TEST_F(RealtimeRenderer, ConstantEnvironmentGivesAlbedoTimesRadiance) {
    const auto dir = test::outputDir("realtime_env");
    cv::Mat env(32, 64, CV_32FC3, cv::Scalar(0.7, 0.7, 0.7));
    writeLinearRgb(dir / "env.exr", env);
    Scene scene;
    int m = addMaterial(scene, glm::vec3(0.5f));
    addFloor(scene, "floor", 0.0f, 4.0f, m, Origin::Real);
    scene.environment.kind = Environment::Kind::Equirectangular;
    scene.environment.image = dir / "env.exr";
    const CameraIntrinsics cam = smallCamera();
    Renderer r(scene, cam);
    r.render({lookAtPose({0, 2.5, 2.5}, {0, 0, 0}), {}, false});
    cv::Mat rv = r.readBuffer(kDirectRv);
    // Lambert part 0.5 * 0.7 = 0.35 (plus (1-F) weighting: F0 = 0.04 -> within 5 %).
    const cv::Vec3f c = rv.at<cv::Vec3f>(cam.height / 2, cam.width / 2);
    EXPECT_NEAR(c[0], 0.35, 0.35 * 0.05);
}

// Base colour textures are sRGB-decoded and mapped with glTF's UV convention ((0,0) = top left
// of the image): a 2x2 checker on the floor under a constant environment.
TEST_F(RealtimeRenderer, BaseColorTextureIsDecodedAndMapped) {
    const auto dir = test::outputDir("realtime_texture");
    cv::Mat env(16, 32, CV_32FC3, cv::Scalar(0.7, 0.7, 0.7));
    writeLinearRgb(dir / "env.exr", env);
    Scene scene;
    Texture tex;
    tex.name = "checker";
    tex.width = tex.height = 2;
    tex.srgb = true;
    // Row 0 (v = 0): encoded 188 (linear 0.503), 0; row 1: 0, 188.
    tex.pixels = {188, 188, 188, 255, 0, 0, 0, 255, 0, 0, 0, 255, 188, 188, 188, 255};
    scene.textures.push_back(tex);
    int m = addMaterial(scene, glm::vec3(1.0f));
    scene.materials[size_t(m)].baseColorTexture.texture = 0;
    addFloor(scene, "floor", 0.0f, 4.0f, m, Origin::Real);
    auto& prim = scene.meshes.back().primitives[0];
    for (const glm::vec3& p : prim.positions) prim.uv0.push_back({(p.x + 2) / 4, (p.z + 2) / 4});
    scene.environment.kind = Environment::Kind::Equirectangular;
    scene.environment.image = dir / "env.exr";
    const CameraIntrinsics cam = smallCamera();
    const Pose pose = lookAtPose({0, 4.0, 0.5}, {0, 0, 0});
    Renderer r(scene, cam);
    r.render({pose, {}, false});
    cv::Mat rv = r.readBuffer(kDirectRv);
    auto at = [&](glm::dvec3 w) {
        auto px = cam.project(pose.inverse() * w);
        EXPECT_TRUE(px.has_value());
        return rv.at<cv::Vec3f>(int(std::lround(px->y)), int(std::lround(px->x)))[0];
    };
    const float lit = 0.7f * srgbToLinear(188.0f / 255.0f);
    EXPECT_NEAR(at({-1, 0, -1}), lit, 0.02);  // u, v = 0.25: texel (0, 0)
    EXPECT_NEAR(at({1, 0, -1}), 0.0, 0.02);   // texel (1, 0)
    EXPECT_NEAR(at({-1, 0, 1}), 0.0, 0.02);   // texel (0, 1)
    EXPECT_NEAR(at({1, 0, 1}), lit, 0.02);
}

}  // namespace
}  // namespace mirage::render
