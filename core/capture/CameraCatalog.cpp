#include "core/capture/CameraCatalog.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

namespace mirage {

std::filesystem::path cameraConfigDir() {
    if (const char* d = std::getenv("MIRAGE_CAMERA_DIR"); d && *d) return d;
    if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x)
        return std::filesystem::path(x) / "mirage" / "cameras";
    const char* home = std::getenv("HOME");
    return std::filesystem::path(home && *home ? home : ".") / ".config" / "mirage" / "cameras";
}

std::string cameraFileStem(const std::string& card) {
    std::string out;
    bool dash = false;
    for (unsigned char c : card) {
        if (std::isalnum(c)) {
            if (dash && !out.empty()) out += '-';
            out += char(std::tolower(c));
            dash = false;
        } else {
            dash = true;
        }
    }
    return out.empty() ? "camera" : out;
}

std::filesystem::path CameraFiles::board() const {
    return std::filesystem::exists(ownBoard) ? ownBoard : sharedBoard;
}

CameraFiles cameraFiles(const std::string& card) {
    const std::filesystem::path dir = cameraConfigDir();
    const std::string stem = cameraFileStem(card);
    return {dir / (stem + ".yaml"), dir / (stem + ".board.json"), dir / "board.json"};
}

std::vector<std::string> v4l2DeviceNodes() {
    std::vector<std::pair<long, std::string>> found;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator("/dev", ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("video", 0) != 0 || name.size() == 5) continue;
        const std::string digits = name.substr(5);
        if (!std::all_of(digits.begin(), digits.end(),
                         [](unsigned char c) { return std::isdigit(c); }))
            continue;
        found.push_back({std::stol(digits), e.path().string()});
    }
    std::sort(found.begin(), found.end());
    std::vector<std::string> out;
    for (auto& f : found) out.push_back(f.second);
    return out;
}

}  // namespace mirage
