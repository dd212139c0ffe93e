#pragma once
// Which frames a camera's recording actually holds on disk, found without decoding them:
// a Matroska video's complete blocks (MatroskaScanner), another video's frame count as the
// container states it, or an image folder's numbered files.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace mirage {

struct FrameInventory {
    bool isFolder = false;
    // Video: frames 0 .. videoFrames-1 are complete. -1 = unknown (container gives no count).
    int videoFrames = 0;
    std::map<int, std::filesystem::path> images;  // folder: frame index -> file
    std::vector<std::string> problems;            // truncation, unnumbered files, ...

    bool has(int index) const;
    int count() const;  // frames present (-1 if unknown)
};

// Throws FileError if `videoOrFolder` does not exist or cannot be opened as video.
FrameInventory inventoryFrames(const std::filesystem::path& videoOrFolder);

// Image files a folder holds (isImageFile in core/session/FrameSource.h), by frame index: the
// number at the end of each file name; if any name has none, by sorted name order.
std::map<int, std::filesystem::path> listImageFrames(const std::filesystem::path& folder,
                                                     std::vector<std::string>* problems);

}  // namespace mirage
