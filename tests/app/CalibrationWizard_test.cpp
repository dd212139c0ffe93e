// The calibration wizard: its input stage alone (app/wizard/CalibrationWizard.h), and the whole
// window under a virtual X server.
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "app/wizard/CalibrationWizard.h"
#include "core/Error.h"
#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

fs::path sample() {
    return dataDir() / "sessions" / "sample";
}

// Input: every frame of a video, named by the source or "frame N"; no source is refused.
TEST(WizardInput, DeliversEveryFrameOfAVideoAndRefusesNoSource) {
    app::WizardOptions o;
    o.inputs = {(sample() / "main.mkv").string()};
    app::WizardInput in(o);
    EXPECT_FALSE(in.stillImages());
    cv::Mat bgr;
    std::string name;
    int n = 0;
    while (in.next(bgr, name)) {
        ASSERT_FALSE(bgr.empty());
        EXPECT_FALSE(name.empty());
        ++n;
    }
    EXPECT_EQ(n, 36);
    EXPECT_THROW(app::WizardInput(app::WizardOptions{}), Error);
}

// The window under xvfb: the sample's frames with the detected board drawn over them, the
// panels beside them.
TEST(CalibrationWizard, ShowsTheSampleWithItsBoardUnderXvfb) {
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
    const fs::path dir = outputDir("calibration_wizard");
    const fs::path shot = dir / "wizard.png";
    fs::remove(shot);
    const std::string cmd =
        "xvfb-run -a -s '-screen 0 1280x1024x24' '" + std::string(MIRAGE_BINARY) + "' calibrate '" +
        (sample() / "main.mkv").string() + "' --board '" + (sample() / "board.json").string() +
        "' --screenshot '" + shot.string() + "' --screenshot-after 3 > '" +
        (dir / "log.txt").string() + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const cv::Mat png = cv::imread(shot.string());
    ASSERT_FALSE(png.empty());
    EXPECT_EQ(png.size(), cv::Size(1280, 800));
    // The camera panel shows the footage (a lit table), the calibration panel text.
    EXPECT_GT(cv::mean(png(cv::Rect(20, 40, 600, 440)))[1], 40.0);
    cv::Mat grey;
    cv::cvtColor(png(cv::Rect(660, 0, 620, 800)), grey, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(grey > 180), 500);
}

}  // namespace
}  // namespace mirage::test
