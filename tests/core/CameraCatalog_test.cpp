// Where `mirage live` looks for a webcam's calibration: the camera folder from the environment,
// and file names from the camera model's name.
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/capture/CameraCatalog.h"

namespace mirage {
namespace {

TEST(CameraCatalog, FileStemFromTheCardName) {
    EXPECT_EQ(cameraFileStem("HD Webcam C270"), "hd-webcam-c270");
    EXPECT_EQ(cameraFileStem("  Logitech BRIO: (USB 3.0)  "), "logitech-brio-usb-3-0");
    EXPECT_EQ(cameraFileStem("UVC Camera (046d:0825)"), "uvc-camera-046d-0825");
    EXPECT_EQ(cameraFileStem("../../etc/passwd"), "etc-passwd");  // never leaves the folder
    EXPECT_EQ(cameraFileStem("***"), "camera");
}

TEST(CameraCatalog, FolderFromTheEnvironment) {
    const char* saved[3] = {std::getenv("MIRAGE_CAMERA_DIR"), std::getenv("XDG_CONFIG_HOME"),
                            std::getenv("HOME")};
    const std::string keep[3] = {saved[0] ? saved[0] : "", saved[1] ? saved[1] : "",
                                 saved[2] ? saved[2] : ""};
    ::setenv("MIRAGE_CAMERA_DIR", "/tmp/cams", 1);
    EXPECT_EQ(cameraConfigDir(), "/tmp/cams");
    ::unsetenv("MIRAGE_CAMERA_DIR");
    ::setenv("XDG_CONFIG_HOME", "/tmp/xdg", 1);
    EXPECT_EQ(cameraConfigDir(), "/tmp/xdg/mirage/cameras");
    ::unsetenv("XDG_CONFIG_HOME");
    ::setenv("HOME", "/home/someone", 1);
    EXPECT_EQ(cameraConfigDir(), "/home/someone/.config/mirage/cameras");
    const char* names[3] = {"MIRAGE_CAMERA_DIR", "XDG_CONFIG_HOME", "HOME"};
    for (int i = 0; i < 3; ++i) {
        if (saved[i])
            ::setenv(names[i], keep[i].c_str(), 1);
        else
            ::unsetenv(names[i]);
    }
}

TEST(CameraCatalog, FilesOfACameraInTheFolder) {
    const char* saved = std::getenv("MIRAGE_CAMERA_DIR");
    const std::string keep = saved ? saved : "";
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "mirage_camera_catalog_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    ::setenv("MIRAGE_CAMERA_DIR", dir.c_str(), 1);
    const CameraFiles f = cameraFiles("HD Webcam C270");
    EXPECT_EQ(f.calibration, dir / "hd-webcam-c270.yaml");
    EXPECT_EQ(f.ownBoard, dir / "hd-webcam-c270.board.json");
    EXPECT_EQ(f.sharedBoard, dir / "board.json");
    EXPECT_EQ(f.board(), f.sharedBoard);  // neither exists: the shared one is named
    std::ofstream(f.ownBoard) << "{}";
    EXPECT_EQ(f.board(), f.ownBoard);  // the camera's own board wins
    if (saved)
        ::setenv("MIRAGE_CAMERA_DIR", keep.c_str(), 1);
    else
        ::unsetenv("MIRAGE_CAMERA_DIR");
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mirage
