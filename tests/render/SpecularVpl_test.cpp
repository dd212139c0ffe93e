// Reflected and refracted VPLs (Knecht 2013 Sec. 5.2): a VPL whose reflective-shadow-map sample
// lands on a mirror or glass continues to the receiver of that point's photon, so light a mirror
// throws onto a wall lights the floor below it. The scene: a real spot light aimed at a virtual
// mirror plate on a real floor; the mirror throws the beam onto a real wall, and the floor in
// front of the wall sees only that bounce (the light's narrow cone falls on the mirror alone).
// Checked: the VPLs' total flux against the mirror's reflectance (the same light on the bare
// floor as the yardstick), no VPL left on the mirror, and the composite over the floor in front
// of the wall against the Embree reference with caustics (photon mapping) on. Must-fails: the
// option off (the bounce is lost), and the photon's solid-angle scaling ignored. Hard cases:
// glass (refracted VPLs), light grazing the mirror, photons leaving the scene.
#include <gtest/gtest.h>

#include <iostream>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "render/Renderer.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "tests/support/TestSupport.h"
#include "testscenes/ReferenceFrame.h"
#include "testscenes/SpecularTestScenes.h"

namespace mirage::render {
namespace {

struct RelayScene {
    Scene scene;
    CameraIntrinsics cam = test::smallCamera(96, 72, 80.0);
    Pose pose = test::lookAtPose({0.5, 0.55, 0.8}, {-0.3, 0.12, 0.0});
    glm::vec3 lightPos{0.8f, 0.62f, 0.0f};
};

struct RelayOptions {
    bool mirror = true;  // false: the bare floor under the light (the flux yardstick)
    bool glass = false;  // a glass plate in place of the mirror (refracted VPLs)
    bool wall = true;    // false: the reflected beam leaves the scene
    glm::vec3 lightPos{0.8f, 0.62f, 0.0f};
};

RelayScene makeRelay(const RelayOptions& o = {}) {
    RelayScene s;
    s.lightPos = o.lightPos;
    const int diffuse = test::addMaterial(s.scene, glm::vec3(0.7f));
    test::addFloor(s.scene, "floor", 0.0f, 3.0f, diffuse, Origin::Real);
    if (o.wall)
        test::addBox(s.scene, "wall", {-0.56f, 0.0f, -1.5f}, {-0.5f, 1.5f, 1.5f}, diffuse,
                     Origin::Real);
    const glm::vec3 target(0.0f, 0.02f, 0.0f);
    if (o.mirror) {
        const int m = o.glass ? test::addGlass(s.scene) : test::addMirror(s.scene);
        // The glass plate is held 6 cm above the floor: its refracted photons reach the floor
        // below it (a face lying on the floor would leave the photon no distance to travel).
        test::addBox(s.scene, o.glass ? "glass plate" : "mirror plate",
                     {-0.15f, o.glass ? 0.06f : 0.0f, -0.15f},
                     {0.15f, o.glass ? 0.1f : 0.02f, 0.15f}, m, Origin::Virtual);
    }
    test::addLight(s.scene, Light::Type::Spot, s.lightPos, glm::normalize(target - s.lightPos),
                   16.0f, Origin::Real, 0.1f, 0.08f);
    return s;
}

struct VplSums {
    glm::dvec3 flux{0.0};
    int valid = 0, onMirror = 0, onWall = 0;
    bool finite = true;
};

VplSums sumVpls(const std::vector<GpuVpl>& vpls) {
    VplSums s;
    for (const GpuVpl& v : vpls) {
        if (v.valid == 0) continue;
        ++s.valid;
        s.finite =
            s.finite && std::isfinite(v.flux.x + v.flux.y + v.flux.z + v.position.x + v.position.y +
                                      v.position.z + v.normal.x + v.normal.y + v.normal.z);
        s.flux += glm::dvec3(v.flux);
        if (std::abs(v.position.x) < 0.16f && std::abs(v.position.z) < 0.16f &&
            v.position.y > 0.001f && v.position.y < 0.11f)
            ++s.onMirror;
        if (v.position.x < -0.49f && v.position.y > 0.01f) ++s.onWall;
    }
    return s;
}

struct Frame {
    VplSums vpls;
    cv::Mat composite;  // sRGB8 BGR
    cv::Mat lrv;        // L_rv, linear RGB (canvas)
    FrameReport report;
};

Frame renderRealtime(const RelayScene& s, const cv::Mat& footage, RendererOptions opt = {}) {
    opt.temporalBlend = 0.0f;
    Renderer r(s.scene, s.cam, opt);
    Frame f;
    f.report = r.render({s.pose, footage, true});
    f.vpls = sumVpls(r.readVpls());
    f.composite = r.compositeSrgb();
    f.lrv = r.readBuffer(kLRv);
    EXPECT_TRUE(cv::checkRange(r.compositeLinear())) << "NaN/Inf in the composite";
    return f;
}

// Floor pixels (y = 0) in front of the wall (-0.5 < x < -0.2), away from the mirror and the
// light's own cone: lit only by the bounce off the wall. CV_8U 255 / 0.
cv::Mat floorByTheWall(const RelayScene& s) {
    cv::Mat m(s.cam.height, s.cam.width, CV_8U, cv::Scalar(0));
    const glm::dvec3 eye = s.pose.translation;
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const glm::dvec3 d = s.pose.rotation * glm::dvec3((x - s.cam.cx) / s.cam.fx,
                                                              (y - s.cam.cy) / s.cam.fy, 1.0);
            if (d.y >= -1e-6) continue;
            const glm::dvec3 q = eye + d * (-eye.y / d.y);
            if (q.x > -0.48 && q.x < -0.22 && std::abs(q.z) < 0.6) m.at<uint8_t>(y, x) = 255;
        }
    return m;
}

TEST(SpecularVpl, MirrorVplsCarryTheReflectedFluxToTheWall) {
    gl::Context context = gl::Context::headless();
    const cv::Mat black(72, 96, CV_8UC3, cv::Scalar::all(0));
    // The yardstick: the same light on the bare floor (albedo 0.7, as the wall).
    RendererOptions all;
    all.graph.cullPasses = false;  // no virtual object: VPLs only when every pass runs
    const Frame bare = renderRealtime(makeRelay({false}), black, all);
    const Frame on = renderRealtime(makeRelay(), black);
    RendererOptions offOpt;
    offOpt.vpl.throughSpecular = false;
    const Frame off = renderRealtime(makeRelay(), black, offOpt);
    ASSERT_TRUE(on.report.ran("photongbuf"));
    ASSERT_TRUE(on.vpls.finite && off.vpls.finite && bare.vpls.finite);
    const double yard = bare.vpls.flux.x + bare.vpls.flux.y + bare.vpls.flux.z;
    const double got = on.vpls.flux.x + on.vpls.flux.y + on.vpls.flux.z;
    const double lost = off.vpls.flux.x + off.vpls.flux.y + off.vpls.flux.z;
    // A polished metal of base colour 0.95 reflects 0.95-0.96 at 36 degrees (Schlick).
    std::cout << "[ vpl ] flux: bare floor " << yard << " W, via the mirror " << got << " W (ratio "
              << got / yard << "), option off " << lost << " W; VPLs on the wall " << on.vpls.onWall
              << " of " << on.vpls.valid << ", on the mirror " << on.vpls.onMirror << "\n";
    ASSERT_GT(yard, 0.0);
    EXPECT_NEAR(got / yard, 0.95, 0.08);
    EXPECT_EQ(on.vpls.onMirror, 0) << "a VPL stayed on the mirror";
    EXPECT_GT(on.vpls.onWall, on.vpls.valid / 2);
    EXPECT_LT(lost / yard, 0.05) << "with the option off the mirror's VPLs should be dark";
    EXPECT_GT(off.vpls.onMirror, 0);
}

// Hard cases: every VPL finite, none left on the specular object, no energy from nowhere (the
// total at most the bare floor's under the same light), and the expected share carried on.
TEST(SpecularVpl, GlassGrazingAndEscapingPhotonsStayFiniteAndConserveEnergy) {
    gl::Context context = gl::Context::headless();
    const cv::Mat black(72, 96, CV_8UC3, cv::Scalar::all(0));
    RendererOptions all;
    all.graph.cullPasses = false;
    struct Case {
        const char* name;
        RelayOptions options;
        double minRatio, maxRatio;  // total VPL flux / the bare floor's
    };
    RelayOptions glass;
    glass.glass = true;  // refracted VPLs under the plate, reflected ones on the wall
    RelayOptions grazing;
    grazing.lightPos = glm::vec3(0.9f, 0.1f, 0.0f);  // 5 degrees above the plate
    RelayOptions escaping;
    escaping.wall = false;  // the reflected beam leaves the modelled scene: no VPL, no light
    const Case cases[] = {{"glass plate", glass, 0.75, 1.05},
                          {"grazing", grazing, 0.0, 1.10},
                          {"escaping", escaping, 0.0, 0.02}};
    for (const Case& c : cases) {
        RelayOptions bareOptions = c.options;
        bareOptions.mirror = false;
        const Frame bare = renderRealtime(makeRelay(bareOptions), black, all);
        const Frame on = renderRealtime(makeRelay(c.options), black);
        ASSERT_TRUE(on.report.ran("photongbuf")) << c.name;
        const double yard = bare.vpls.flux.x + bare.vpls.flux.y + bare.vpls.flux.z;
        const double got = on.vpls.flux.x + on.vpls.flux.y + on.vpls.flux.z;
        std::cout << "[ vpl ] " << c.name << ": flux ratio " << got / yard << ", " << on.vpls.valid
                  << " valid VPLs, " << on.vpls.onMirror << " on the object\n";
        EXPECT_TRUE(on.vpls.finite) << c.name;
        EXPECT_EQ(on.vpls.onMirror, 0) << c.name;
        ASSERT_GT(yard, 0.0) << c.name;
        EXPECT_GE(got / yard, c.minRatio) << c.name;
        EXPECT_LE(got / yard, c.maxRatio) << c.name;
    }
}

// Floors from measurement (llvmpipe, 256 VPLs; reference 48 spp, seed 5): L_rv over the floor
// by the wall 1.0x the reference's (option off: 0.2x).
constexpr double kFloorLrvRatioTolerance = 0.25, kFloorLrvRatioOff = 0.5;

TEST(SpecularVpl, FloorLitByTheMirrorsBounceMatchesReference) {
    gl::Context context = gl::Context::headless();
    const RelayScene s = makeRelay();
    const test::ReferenceFrame ref = test::renderReferenceFrame(s.scene, s.cam, s.pose, 48, 5);
    const cv::Mat& footage = ref.footage;
    const cv::Mat& refComposite = ref.composite;
    const cv::Mat region = floorByTheWall(s);
    ASSERT_GT(cv::countNonZero(region), 200);
    const Frame on = renderRealtime(s, footage);
    RendererOptions offOpt;
    offOpt.vpl.throughSpecular = false;
    const Frame off = renderRealtime(s, footage, offOpt);
    ASSERT_EQ(on.lrv.size(),
              ref.images.realAndVirtual.size());  // an undistorted camera: canvas = image
    // L_rv there is the light the mirror throws onto the wall, bounced once (the light's cone
    // falls on the mirror alone): the reflected VPLs' work.
    const double lrvRef = test::meanLuminance(ref.images.realAndVirtual, region);
    const double ratioOn = test::meanLuminance(on.lrv, region) / lrvRef;
    const double ratioOff = test::meanLuminance(off.lrv, region) / lrvRef;
    const double psnrOn = test::psnr(on.composite, refComposite, 255.0, region);
    const double psnrOff = test::psnr(off.composite, refComposite, 255.0, region);
    std::cout << "[ vpl ] floor by the wall (" << cv::countNonZero(region)
              << " px): L_rv / reference " << ratioOn << " (option off " << ratioOff
              << "); composite PSNR " << psnrOn << " dB (off " << psnrOff << " dB)\n";
    {
        const auto dir = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / "specular_vpl";
        std::filesystem::create_directories(dir);
        cv::Mat side;
        cv::hconcat(std::vector<cv::Mat>{footage, off.composite, on.composite, refComposite}, side);
        cv::resize(side, side, cv::Size(), 3.0, 3.0, cv::INTER_NEAREST);
        writeBgr8(dir / "floor_by_the_wall.png", side);
    }
    ASSERT_GT(lrvRef, 0.0) << "the reference shows no bounce off the wall";
    EXPECT_NEAR(ratioOn, 1.0, kFloorLrvRatioTolerance);
    EXPECT_LT(ratioOff, kFloorLrvRatioOff);
    EXPECT_GT(psnrOn, psnrOff);
}

}  // namespace
}  // namespace mirage::render
