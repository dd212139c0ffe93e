// A camera whose response is not sRGB (gamma 2.6), judged against the reference renderer's ground
// truth: with the response in its calibration (what `mirage synth --response-gamma` and `mirage
// response --write` store) the footage is linearised right and the composite encoded back in the
// camera's codes; taken as sRGB, the virtual object's light and the differential shading are
// off. The bench's knob camera_response=session|srgb switches between the two.
#include <gtest/gtest.h>

#include <iostream>

#include "core/camera/CalibrationFile.h"
#include "core/camera/CameraResponse.h"
#include "core/gl/Context.h"
#include "core/session/Session.h"
#include "render/Renderer.h"
#include "render/evaluation/RealtimeBench.h"
#include "render/raytrace/GroundTruthComposite.h"
#include "render/raytrace/SyntheticSession.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"
#include "testscenes/SmallSyntheticSession.h"

namespace mirage::render {
namespace {

namespace fs = std::filesystem;

TEST(CameraResponseGroundTruth, AGammaCameraIsCompositedInItsOwnCodes) {
    const Scene scene = test::spotLitTableWithVirtualBox();
    const fs::path dir = test::outputDirForThisTest("response_gamma");
    // 4 frames of the small session, from a camera with a gamma-2.6 response.
    raytrace::SyntheticSessionOptions o =
        test::smallSyntheticSession("in-memory camera response scene", 16, 7);
    o.fps = 4.0;
    o.sensor.responseGamma = 2.6;
    raytrace::writeSyntheticSession(scene, dir, o);

    const Session session = readSession(dir);
    const auto info = readGroundTruthInfo(dir);
    ASSERT_TRUE(info.has_value());
    const CameraCalibration calib = loadSessionCalibration(session, "main");
    const std::vector<BenchFrame> frames = loadBenchFrames(session, *info, calib.intrinsics);
    ASSERT_EQ(frames.size(), 4u);
    ASSERT_EQ(frames.front().response.kind(), CameraResponse::Kind::Gamma);

    gl::Context context = gl::Context::headless();
    CompositeError known, assumed;
    for (const bool fromSession : {true, false}) {
        const std::vector<BenchConfig> grid =
            benchGrid(calib.intrinsics, true,
                      {{"camera_response", {fromSession ? "session" : "srgb"}},
                       {"exposure_match", {"on"}},
                       {"vpls", {"256"}}});
        const BenchResult r = runBenchConfig(scene, calib.intrinsics, frames, grid.at(0));
        (fromSession ? known : assumed) = r.error;
        std::cout << "[ response ] camera_response=" << (fromSession ? "session" : "srgb")
                  << ": influenced PSNR " << r.error.psnrInfluenced << " dB, SSIM "
                  << r.error.ssimInfluenced << "; frame " << r.error.psnrFrame << " dB\n";
    }
    // Measured (llvmpipe, 160x120, reference 16 spp, 4 frames, exposure matching on, as replay
    // runs): influenced PSNR 23.18 dB with the response, 22.46 dB taken as sRGB; SSIM 0.814 vs
    // 0.800. The exposure matching absorbs the scale; the curve's shape is what is left.
    EXPECT_GT(known.psnrInfluenced, assumed.psnrInfluenced + 0.5);
    EXPECT_GT(known.ssimInfluenced, assumed.ssimInfluenced);

    // The footage goes through linearisation and back unchanged where the renderer adds
    // nothing, the darkest codes too (through 8-bit sRGB codes, codes below ~8 would merge).
    RendererOptions hidden;
    hidden.composite.cameraResponse = frames.front().response;
    hidden.composite.showVirtual = false;
    Renderer renderer(scene, calib.intrinsics, hidden);
    cv::Mat dark = frames.front().footage.clone();
    for (int x = 0; x < 32; ++x) dark.at<cv::Vec3b>(0, x) = cv::Vec3b(uint8_t(x), uint8_t(x), 0);
    renderer.render({frames.front().T_world_camera, dark, true});
    EXPECT_LE(cv::norm(renderer.compositeCameraCoded(), dark, cv::NORM_INF), 1.0);
}

}  // namespace
}  // namespace mirage::render
