#pragma once
// Where mirage keeps each camera's calibration so that `mirage live` finds it without being told
// (docs/live.md, "Defaults"): one folder, one file per camera named after the camera's model
// (the V4L2 card name), e.g. "HD Webcam C270" -> <folder>/hd-webcam-c270.yaml, and optionally the
// board used with it beside it (<stem>.board.json, else board.json).
#include <filesystem>
#include <string>
#include <vector>

namespace mirage {

// $MIRAGE_CAMERA_DIR if set, else $XDG_CONFIG_HOME/mirage/cameras, else
// $HOME/.config/mirage/cameras (the folder need not exist).
std::filesystem::path cameraConfigDir();
// A file-name stem for a camera's card name: lower case, runs of anything but letters and digits
// become one '-', no '-' at either end; "camera" if nothing is left.
std::string cameraFileStem(const std::string& card);
// The files kept for the camera whose V4L2 card name is `card`, in cameraConfigDir().
struct CameraFiles {
    std::filesystem::path calibration;  // <stem>.yaml: what `mirage calibrate --camera` saves
    std::filesystem::path ownBoard;     // <stem>.board.json: the board used with this camera
    std::filesystem::path sharedBoard;  // board.json: the board of every camera without its own
    // ownBoard if it exists, else sharedBoard (which need not exist either).
    std::filesystem::path board() const;
};
CameraFiles cameraFiles(const std::string& card);
// The V4L2 device nodes present (/dev/videoN), in the order of N.
std::vector<std::string> v4l2DeviceNodes();

}  // namespace mirage
