// The rendered real proxy lands on its image in the footage within 1 px, through the calibrated
// intrinsics and lens distortion (render undistorted on an enlarged canvas, then distort in the
// compositor through CameraIntrinsics::unproject's remap).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "core/scene/Scene.h"
#include "render/Renderer.h"
#include "render/passes/composite/CompositePass.h"
#include "tests/support/HeadlessGlSuite.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage::render {
namespace {

using test::addFloor;
using test::addLight;
using test::addMaterial;
using test::lookAtPose;

struct AlignmentStats {
    double maxError = 0.0;  // px, largest distance from the projected edge to the rendered one
    int samples = 0;
};

// For points along each edge of the square proxy (world, y = 0, side `size`), project with
// `model` and find where the rendered coverage switches from empty to real along the image
// normal of the edge: the distance of that switch from the projected point is the error.
AlignmentStats measureAlignment(const cv::Mat& coverage, const CameraIntrinsics& model,
                                const Pose& T_world_camera, float size) {
    AlignmentStats st;
    const Pose T_camera_world = T_world_camera.inverse();
    const double h = size * 0.5;
    const glm::dvec3 corners[4] = {{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}};
    for (int e = 0; e < 4; ++e) {
        const glm::dvec3 a = corners[e], b = corners[(e + 1) % 4];
        for (int k = 1; k < 20; ++k) {
            const double t = k / 20.0;
            auto px = [&](double tt) { return model.project(T_camera_world * (a + (b - a) * tt)); };
            auto p = px(t), p0 = px(t - 0.01), p1 = px(t + 0.01);
            auto inward = model.project(T_camera_world *
                                        (a + (b - a) * t + (glm::dvec3(0) - (a + b) * 0.5) * 0.05));
            if (!p || !p0 || !p1 || !inward) continue;
            glm::dvec2 tan = glm::normalize(*p1 - *p0);
            glm::dvec2 n(-tan.y, tan.x);
            if (glm::dot(n, *inward - *p) < 0) n = -n;
            // Skip samples whose search line leaves the image.
            bool inside = true;
            for (double s : {-4.0, 4.0}) {
                glm::dvec2 q = *p + n * s;
                if (q.x < 0 || q.y < 0 || q.x > coverage.cols - 1 || q.y > coverage.rows - 1)
                    inside = false;
            }
            if (!inside) continue;
            double edge = 1e9;
            for (double s = -4.0; s <= 4.0; s += 0.05) {
                glm::dvec2 q = *p + n * s;
                const int x = int(std::lround(q.x)), y = int(std::lround(q.y));
                if (coverage.at<uint8_t>(y, x) == 1) {
                    edge = s;
                    break;
                }
            }
            st.maxError = std::max(st.maxError, std::abs(edge));
            ++st.samples;
        }
    }
    return st;
}

class RealtimeLens : public test::HeadlessGlSuite {
protected:
    Scene proxyScene() {
        Scene s;
        int m = addMaterial(s, glm::vec3(0.6f));
        addFloor(s, "real proxy", 0.0f, 1.2f, m, Origin::Real);
        addLight(s, Light::Type::Spot, {0, 2, 0}, {0, -1, 0}, 5.0f, Origin::Real, 1.2f, 1.0f);
        return s;
    }
    CameraIntrinsics distortedCamera() {
        CameraIntrinsics c;
        c.width = 200;
        c.height = 150;
        c.fx = 150.0;
        c.fy = 148.0;
        c.cx = 103.2;
        c.cy = 71.9;
        c.distortion = {-0.28, 0.09, 0.001, -0.0015, 0.0};  // strong barrel
        return c;
    }
    Pose pose = lookAtPose({0.4, 1.1, 1.3}, {0.05, 0.0, 0.0});
};

TEST_F(RealtimeLens, RealProxyLandsOnItsImageWithinOnePixel) {
    const CameraIntrinsics cam = distortedCamera();
    Renderer r(proxyScene(), cam);
    EXPECT_TRUE(r.projection().hasDistortion);
    EXPECT_GT(r.projection().canvasWidth, cam.width);  // barrel: the canvas must grow
    r.render({pose, {}, false});
    const AlignmentStats st = measureAlignment(r.coverage(), cam, pose, 1.2f);
    EXPECT_GT(st.samples, 40);
    EXPECT_LE(st.maxError, 1.0) << "max edge error " << st.maxError << " px";
    std::printf("distorted proxy: max edge error %.2f px over %d samples\n", st.maxError,
                st.samples);
}

TEST_F(RealtimeLens, UndistortedCameraAlignsToo) {
    CameraIntrinsics cam = distortedCamera();
    cam.distortion.clear();
    Renderer r(proxyScene(), cam);
    EXPECT_FALSE(r.projection().hasDistortion);
    EXPECT_EQ(r.projection().canvasWidth, cam.width);
    r.render({pose, {}, false});
    const AlignmentStats st = measureAlignment(r.coverage(), cam, pose, 1.2f);
    EXPECT_GT(st.samples, 40);
    EXPECT_LE(st.maxError, 1.0);
}

// The measurement catches a misaligned render: ignoring the distortion puts the edges several
// pixels off.
TEST_F(RealtimeLens, AlignmentCheckFailsWhenDistortionIsIgnored) {
    const CameraIntrinsics cam = distortedCamera();
    CameraIntrinsics pinhole = cam;
    pinhole.distortion.clear();
    Renderer r(proxyScene(), pinhole);
    r.render({pose, {}, false});
    const AlignmentStats st = measureAlignment(r.coverage(), cam, pose, 1.2f);
    EXPECT_GT(st.maxError, 2.0);
    std::printf("distortion ignored: max edge error %.2f px\n", st.maxError);
}

// Without distortion, on a canvas of the camera's size, the lens remap is the identity and the
// composite reads each canvas buffer at its own pixel; any distortion that moves a pixel by more
// than a thousandth keeps the table.
TEST_F(RealtimeLens, IdentityRemapOnlyWithoutDistortion) {
    CameraIntrinsics pinhole = distortedCamera();
    pinhole.distortion.clear();
    EXPECT_TRUE(CompositePass::isIdentityRemap(CameraProjection::make(pinhole)));
    EXPECT_FALSE(CompositePass::isIdentityRemap(CameraProjection::make(distortedCamera())));
    CameraIntrinsics slight = pinhole;
    slight.distortion = {-0.01, 0.0, 0.0, 0.0, 0.0};  // ~0.1 px at the corners
    EXPECT_FALSE(CompositePass::isIdentityRemap(CameraProjection::make(slight)));
}

// The identity-remap variant composites every pixel as the general one (through the table),
// mirror and glass pixels (the video back-projected into them) included; the comparison sees a
// remap one pixel off.
TEST_F(RealtimeLens, IdentityRemapVariantComposesAsTheTable) {
    const Scene scene = loadScene(test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf");
    const CameraIntrinsics cam = test::smallCamera(160, 120, 130.0);
    const Pose view = lookAtPose({0.05, 0.40, 0.60}, {-0.05, 0.02, 0.0});
    cv::Mat footage(cam.height, cam.width, CV_8UC3);
    cv::randu(footage, 0, 255);
    auto composite = [&](const CameraIntrinsics& c, bool identity) {
        RendererOptions o;
        o.vpl.count = 64;
        o.composite.identityRemap = identity;
        Renderer r(scene, c, o);
        r.render({view, footage, true});
        EXPECT_GT(r.specularRects().size(), 0u);
        return r.compositeLinear();
    };
    const cv::Mat fast = composite(cam, true), table = composite(cam, false);
    const double diff = cv::norm(fast, table, cv::NORM_INF);
    std::printf("identity remap against the table: max difference %.2g\n", diff);
    EXPECT_LT(diff, 1e-4);
    CameraIntrinsics shifted = cam;
    shifted.cx += 1.0;
    EXPECT_GT(cv::norm(fast, composite(shifted, false), cv::NORM_INF), 1e-2);
}

}  // namespace
}  // namespace mirage::render
