// `mirage render` end to end: outputs by extension, errors for a missing camera node.
#include <gtest/gtest.h>

#include "core/image/ImageIO.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

std::string showcase() {
    return (test::testDataDir() / "scenes/good/showcase.gltf").string();
}

TEST(RaytraceRenderCommand, WritesLinearAndToneMappedImages) {
    auto dir = test::outputDir("rt_render_command");
    auto exr = (dir / "main.exr").string(), png = (dir / "main.png").string();
    auto r = test::runMirage({"render", showcase(), "--camera", "MainCamera", "-o", exr, "--width",
                              "48", "--height", "32", "--spp", "4", "--threads", "2"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    cv::Mat linear = readLinearRgb(exr);
    EXPECT_EQ(linear.cols, 48);
    EXPECT_EQ(linear.rows, 32);
    EXPECT_GT(cv::norm(linear, cv::NORM_INF), 0.0);
    r = test::runMirage({"render", showcase(), "--camera", "MainCamera", "-o", png, "--width", "48",
                         "--height", "32", "--spp", "4", "--threads", "2", "--mode", "composite"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(readLinearRgb(png).cols, 48);
}

TEST(RaytraceRenderCommand, MissingCameraListsCameraNodes) {
    auto dir = test::outputDir("rt_render_command_err");
    auto r = test::runMirage(
        {"render", showcase(), "--camera", "NoSuchCamera", "-o", (dir / "x.exr").string()});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.output.find("NoSuchCamera"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("MainCamera"), std::string::npos) << r.output;
    r = test::runMirage(
        {"render", showcase(), "--camera", "MainCamera", "-o", (dir / "x.bmp").string()});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.output.find(".exr"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mirage
