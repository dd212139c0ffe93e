#pragma once
// An AprilTag family (libapriltag's apriltag_family_t) owned in RAII style, created by name.
//
// Tag geometry (libapriltag's): a tag is total_width x total_width cells; the detection corners
// are the outer corners of the width_at_border x width_at_border square centred in it (for
// tag36h11: 10 cells total, 8 at the black border, so one white cell of quiet zone on each side).
// A board's "edge length" is the distance between detection corners = widthAtBorder() cells.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

struct apriltag_family;

namespace mirage::tracking {

class TagFamily {
public:
    // Names as libapriltag spells them: tag36h11 (default in mirage), tag25h9, tag16h5,
    // tagStandard41h12, tagStandard52h13, tagCircle21h7, tagCircle49h12, tagCustom48h12.
    // Throws mirage::Error naming the supported families for any other name.
    explicit TagFamily(const std::string& name = "tag36h11");
    ~TagFamily();
    TagFamily(TagFamily&&) noexcept;
    TagFamily& operator=(TagFamily&&) noexcept;
    TagFamily(const TagFamily&) = delete;
    TagFamily& operator=(const TagFamily&) = delete;

    const std::string& name() const { return name_; }
    int codeCount() const;
    int widthAtBorder() const;  // cells between detection corners
    int totalWidth() const;     // cells of the whole tag image including its quiet zone
    // The tag's cell pattern as an 8-bit single-channel image of totalWidth() x totalWidth()
    // pixels, one pixel per cell, 0 = black, 255 = white, row 0 at the top of the printed tag
    // (libapriltag's apriltag_to_image). Throws mirage::Error if id is out of range.
    cv::Mat codeImage(int id) const;

    // Raw libapriltag family for the detector. libapriltag stores decoder tables in it, so one
    // TagFamily must not be shared by two detectors (each Detector owns its own).
    apriltag_family* raw() const { return family_; }

    static std::vector<std::string> supportedNames();

private:
    std::string name_;
    apriltag_family* family_ = nullptr;
    void (*destroy_)(apriltag_family*) = nullptr;
};

}  // namespace mirage::tracking
