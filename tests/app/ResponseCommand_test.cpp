// `mirage response BRACKET --calibration FILE --write`: a bracket folder of PNGs with its
// exposures.csv fitted and stored in the calibration file, which replay, live and bench then
// read; bad brackets refused with the file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>

#include <opencv2/imgcodecs.hpp>

#include "core/camera/CalibrationFile.h"
#include "core/camera/CameraResponse.h"
#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

// Six pictures of a still ramp (three decades of light), each twice the exposure of the one
// before, from a camera with a gamma-2.2 response.
void writeBracket(const fs::path& dir) {
    fs::create_directories(dir);
    std::ofstream csv(dir / "exposures.csv");
    csv << "file,exposure_seconds\n";
    double t = 1.0 / 8.0;
    for (int i = 0; i < 6; ++i, t *= 2.0) {
        cv::Mat img(90, 120, CV_8UC3);
        for (int y = 0; y < img.rows; ++y)
            for (int x = 0; x < img.cols; ++x) {
                const double e = std::pow(10.0, -3.0 + 3.0 * x / (img.cols - 1)) *
                                 (1.0 + 0.3 * std::sin(0.37 * y) * std::cos(0.21 * x));
                // White-balanced light per channel (B, G, R), then the camera's curve.
                const auto code = [&](double gain) {
                    return cv::saturate_cast<uint8_t>(
                        255.0 * std::pow(std::min(1.0, gain * e * t), 1.0 / 2.2));
                };
                img.at<cv::Vec3b>(y, x) = cv::Vec3b(code(0.8), code(1.0), code(0.9));
            }
        const std::string name = "bracket_" + std::to_string(i) + ".png";
        cv::imwrite((dir / name).string(), img);
        csv << name << "," << t << "\n";
    }
}

fs::path calibrationIn(const fs::path& dir) {
    CameraCalibration cal;
    cal.intrinsics.width = 120;
    cal.intrinsics.height = 90;
    cal.intrinsics.fx = cal.intrinsics.fy = 100;
    cal.intrinsics.cx = 60;
    cal.intrinsics.cy = 45;
    saveCalibration(dir / "camera.yaml", cal);
    return dir / "camera.yaml";
}

TEST(ResponseCommand, FitsTheBracketAndWritesTheCalibration) {
    const fs::path dir = outputDirForThisTest("response_command");
    writeBracket(dir / "bracket");
    const fs::path cal = calibrationIn(dir);
    const CommandResult r = runMirage(
        {"response", (dir / "bracket").string(), "--calibration", cal.string(), "--write"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.output, m, std::regex("equivalent gamma ([0-9.]+)")))
        << r.output;
    EXPECT_NEAR(std::stod(m[1].str()), 2.2, 0.05) << r.output;
    const auto response = loadCameraResponse(cal);
    ASSERT_TRUE(response.has_value());
    EXPECT_EQ(response->kind(), CameraResponse::Kind::Table);
    EXPECT_NEAR(response->linear(1, 128), std::pow(128.0 / 255.0, 2.2), 0.02);
    EXPECT_EQ(loadCalibration(cal).intrinsics.width, 120);
}

TEST(ResponseCommand, BadBracketsAreRefusedNamingFileAndLine) {
    const fs::path dir = outputDirForThisTest("response_command_bad");
    writeBracket(dir / "bracket");
    const auto refused = [&](const std::string& csvText, const std::string& why) {
        std::ofstream(dir / "bracket" / "exposures.csv") << csvText;
        const CommandResult r = runMirage({"response", (dir / "bracket").string()});
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_NE(r.output.find(why), std::string::npos) << r.output;
    };
    refused("name,time\n", "line 1: expected the header");
    refused("file,exposure_seconds\nbracket_0.png,banana\n", "line 2: exposure_seconds 'banana'");
    refused("file,exposure_seconds\nbracket_0.png,-1\n", "line 2: exposure_seconds -1");
    refused("file,exposure_seconds\n../camera.yaml,1\n", "leaves the folder");
    refused("file,exposure_seconds\nbracket_0.png,0.1\nbracket_1.png,0.2\n", "at least 3");
    refused("file,exposure_seconds\nmissing.png,0.1\n", "missing.png");
    EXPECT_EQ(runMirage({"response", (dir / "nothing").string()}).exitCode, 1);
}

}  // namespace
}  // namespace mirage::test
