// The radiometric ratio of a second camera to the main camera in its calibration file
// (core/camera/Radiometry.h): written, read back, replaced, and refused when malformed.
#include <gtest/gtest.h>

#include <fstream>

#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/Radiometry.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

CameraCalibration someCalibration() {
    CameraCalibration c;
    c.intrinsics.width = 96;
    c.intrinsics.height = 96;
    c.intrinsics.fx = c.intrinsics.fy = 30;
    c.intrinsics.cx = c.intrinsics.cy = 47.5;
    c.intrinsics.model = DistortionModel::KannalaBrandt;
    c.T_parent_camera = Pose();
    c.extrinsicParent = "world";
    return c;
}

TEST(Radiometry, RoundTripKeepsTheCalibrationAndReplacesTheRatio) {
    const auto dir = test::outputDir("radiometry");
    const auto file = dir / "env.yaml";
    saveCalibration(file, someCalibration());
    EXPECT_FALSE(loadRadiometryToMain(file).has_value());
    saveRadiometryToMain(file, {2.0, 1.9, 2.25});
    saveRadiometryToMain(file, {2.0, 2.1, 2.5});  // replaces, does not add a second key
    const auto r = loadRadiometryToMain(file);
    ASSERT_TRUE(r.has_value());
    EXPECT_DOUBLE_EQ(r->x, 2.0);
    EXPECT_DOUBLE_EQ(r->y, 2.1);
    EXPECT_DOUBLE_EQ(r->z, 2.5);
    const CameraCalibration back = loadCalibration(file);  // the rest still loads
    EXPECT_EQ(back.intrinsics.width, 96);
    EXPECT_EQ(back.extrinsicParent, "world");
}

TEST(Radiometry, MalformedRatiosAreRefusedNamingTheKey) {
    const auto dir = test::outputDir("radiometry_bad");
    for (const char* value :
         {"[ 1, 2 ]", "[ 1, -2, 3 ]", "[ 1, 0, 3 ]", "notalist", "[ a, b, c ]"}) {
        const auto file = dir / "env.yaml";
        saveCalibration(file, someCalibration());
        std::ofstream(file, std::ios::app) << "radiometry_to_main: " << value << "\n";
        try {
            loadRadiometryToMain(file);
            ADD_FAILURE() << value << " was accepted";
        } catch (const FileError& e) {
            EXPECT_NE(std::string(e.what()).find("radiometry_to_main"), std::string::npos)
                << value << ": " << e.what();
        }
    }
    EXPECT_THROW(saveRadiometryToMain(dir / "env.yaml", {1.0, 0.0, 1.0}), Error);
}

}  // namespace
}  // namespace mirage
