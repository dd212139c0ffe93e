#include "tracking/TagFamily.h"

#include <cstdlib>
#include <utility>

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>

#include "core/Error.h"

namespace mirage::tracking {
namespace {
struct FamilyEntry {
    const char* name;
    apriltag_family_t* (*create)();
    void (*destroy)(apriltag_family_t*);
};
const FamilyEntry kFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
};
}  // namespace

std::vector<std::string> TagFamily::supportedNames() {
    std::vector<std::string> names;
    for (const auto& f : kFamilies) names.emplace_back(f.name);
    return names;
}

TagFamily::TagFamily(const std::string& name) : name_(name) {
    for (const auto& f : kFamilies) {
        if (name == f.name) {
            family_ = f.create();
            destroy_ = f.destroy;
            break;
        }
    }
    if (!family_) {
        std::string list;
        for (const auto& n : supportedNames()) list += (list.empty() ? "" : ", ") + n;
        throw Error("unknown AprilTag family '" + name + "' (supported: " + list + ")");
    }
}

TagFamily::~TagFamily() {
    if (family_) destroy_(family_);
}

TagFamily::TagFamily(TagFamily&& o) noexcept
    : name_(std::move(o.name_)),
      family_(std::exchange(o.family_, nullptr)),
      destroy_(std::exchange(o.destroy_, nullptr)) {}

TagFamily& TagFamily::operator=(TagFamily&& o) noexcept {
    if (this != &o) {
        if (family_) destroy_(family_);
        name_ = std::move(o.name_);
        family_ = std::exchange(o.family_, nullptr);
        destroy_ = std::exchange(o.destroy_, nullptr);
    }
    return *this;
}

int TagFamily::codeCount() const {
    return int(family_->ncodes);
}
int TagFamily::widthAtBorder() const {
    return family_->width_at_border;
}
int TagFamily::totalWidth() const {
    return family_->total_width;
}

cv::Mat TagFamily::codeImage(int id) const {
    if (id < 0 || id >= codeCount())
        throw Error("tag id " + std::to_string(id) + " is outside family " + name_ + " (0.." +
                    std::to_string(codeCount() - 1) + ")");
    image_u8_t* im = apriltag_to_image(family_, id);
    MR_CHECK(im != nullptr, "apriltag_to_image failed");
    cv::Mat out(im->height, im->width, CV_8UC1);
    for (int y = 0; y < im->height; ++y)
        for (int x = 0; x < im->width; ++x) out.at<uint8_t>(y, x) = im->buf[y * im->stride + x];
    // Debian's libapriltag 3.3 does not export image_u8_destroy; it is free(buf) + free(im).
    std::free(im->buf);
    std::free(im);
    return out;
}

}  // namespace mirage::tracking
