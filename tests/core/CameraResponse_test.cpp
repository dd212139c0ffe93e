// The camera response (core/camera/CameraResponse.h): the sRGB default, gamma and measured
// tables, the re-coding of camera frames to the renderer's sRGB codes and back, and the
// calibration file's `response` key (round trip and malformed values).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/CameraResponse.h"
#include "core/image/ImageIO.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

TEST(CameraResponse, SrgbIsTheDefault) {
    const CameraResponse r;
    EXPECT_TRUE(r.isSrgb());
    for (int c = 0; c < 256; ++c) {
        EXPECT_FLOAT_EQ(r.linear(1, c), srgbToLinear(float(c) / 255.0f));
        EXPECT_EQ(r.code(1, r.linear(1, c)), c);
    }
}

TEST(CameraResponse, EveryCodeComesBackFromItsLight) {
    for (const double g : {1.0, 1.8, 2.6, 4.0}) {
        const CameraResponse r = CameraResponse::gamma(g);
        for (int c = 0; c < 256; ++c) {
            EXPECT_NEAR(r.linear(0, c), std::pow(double(c) / 255.0, g), 1e-6);
            for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(r.code(ch, r.linear(ch, c)), c);
            // Halfway to the next code's light rounds to the nearer code.
            if (c < 255) {
                const float mid = 0.5f * (r.linear(1, c) + r.linear(1, c + 1));
                EXPECT_TRUE(r.code(1, mid) == c || r.code(1, mid) == c + 1);
            }
        }
        EXPECT_EQ(r.code(1, -1.0f), 0);
        EXPECT_EQ(r.code(1, NAN), 0);
        EXPECT_EQ(r.code(1, 7.0f), 255);
    }
    // A gamma camera's light is not sRGB's: at code 64 sRGB says 1.87x the light of gamma 2.6.
    EXPECT_GT(CameraResponse().linear(1, 64) / CameraResponse::gamma(2.6).linear(1, 64), 1.5f);
}

TEST(CameraResponse, BadCurvesAreRefusedNamingChannelAndCode) {
    EXPECT_THROW(CameraResponse::gamma(0.5), Error);
    EXPECT_THROW(CameraResponse::gamma(NAN), Error);
    EXPECT_THROW(CameraResponse::gamma(4.5), Error);
    std::array<CameraResponse::Curve, 3> t{};
    for (auto& c : t)
        for (int i = 0; i < 256; ++i) c[size_t(i)] = float(i) * 0.01f;
    EXPECT_NO_THROW(CameraResponse::table(t));
    const CameraResponse ok = CameraResponse::table(t);
    EXPECT_FLOAT_EQ(ok.linear(0, 0), 0.0f);
    EXPECT_FLOAT_EQ(ok.linear(2, 255), 1.0f);  // normalised
    auto decreasing = t;
    decreasing[1][100] = 0.5f;
    try {
        CameraResponse::table(decreasing);
        FAIL() << "a decreasing curve was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("channel G decreases at code 100"), std::string::npos)
            << e.what();
    }
    auto nan = t;
    nan[2][7] = NAN;
    EXPECT_THROW(CameraResponse::table(nan), Error);
    std::array<CameraResponse::Curve, 3> flat{};
    EXPECT_THROW(CameraResponse::table(flat), Error);
}

TEST(CameraResponse, CalibrationFileKeyRoundTripsAndKeepsTheRest) {
    const fs::path dir = test::outputDirForThisTest("camera_response_file");
    const fs::path file = dir / "main.yaml";
    CameraCalibration cal;
    cal.intrinsics.width = 640;
    cal.intrinsics.height = 480;
    cal.intrinsics.fx = cal.intrinsics.fy = 500;
    cal.intrinsics.cx = 320;
    cal.intrinsics.cy = 240;
    saveCalibration(file, cal);
    EXPECT_FALSE(loadCameraResponse(file).has_value());
    EXPECT_TRUE(cameraResponseOrSrgb(file).isSrgb());

    saveCameraResponse(file, CameraResponse::gamma(2.4));
    auto g = loadCameraResponse(file);
    ASSERT_TRUE(g.has_value());
    EXPECT_EQ(g->kind(), CameraResponse::Kind::Gamma);
    EXPECT_DOUBLE_EQ(g->gammaValue(), 2.4);

    std::array<CameraResponse::Curve, 3> t{};
    for (int ch = 0; ch < 3; ++ch)
        for (int i = 0; i < 256; ++i)
            t[size_t(ch)][size_t(i)] = std::pow(float(i) / 255.0f, 2.0f + 0.2f * float(ch));
    saveCameraResponse(file, CameraResponse::table(t));  // replaces the gamma
    auto m = loadCameraResponse(file);
    ASSERT_TRUE(m.has_value());
    EXPECT_EQ(m->kind(), CameraResponse::Kind::Table);
    for (int ch = 0; ch < 3; ++ch)
        for (int i = 0; i < 256; i += 17)
            EXPECT_NEAR(m->linear(ch, i), t[size_t(ch)][size_t(i)], 1e-6f);
    EXPECT_EQ(loadCalibration(file).intrinsics.width, 640);  // the rest kept
}

TEST(CameraResponse, MalformedKeysAreRefusedNamingTheField) {
    const fs::path dir = test::outputDirForThisTest("camera_response_bad");
    const auto expectRefused = [&](const std::string& value, const std::string& field) {
        const fs::path file = dir / "bad.yaml";
        std::ofstream(file) << "%YAML:1.0\n---\nimage_width: 4\nresponse: " << value << "\n";
        try {
            loadCameraResponse(file);
            ADD_FAILURE() << value << " was accepted";
        } catch (const FileError& e) {
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
        }
    };
    expectRefused("3", "response");
    expectRefused("{ kind: banana }", "response.kind");
    expectRefused("{ kind: gamma }", "response.gamma");
    expectRefused("{ kind: gamma, gamma: 9 }", "response.gamma");
    expectRefused("{ kind: table, inverse_r: [ 0, 1 ] }", "response.inverse_r");
}

}  // namespace
}  // namespace mirage
