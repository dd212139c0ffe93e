#include "calibration/FrameSource.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/Error.h"
#include "core/image/StrictJpeg.h"

namespace mirage::calib {
namespace fs = std::filesystem;

namespace {

std::string lowerExtension(const fs::path& p) {
    std::string e = p.extension().string();
    std::transform(e.begin(), e.end(), e.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

// One entry of the stream: an image file or a video file.
struct Item {
    fs::path path;
    bool video = false;
};

class MultiSource final : public FrameSource {
public:
    MultiSource(std::vector<Item> items, FrameSourceOptions o)
        : items_(std::move(items)), options_(o) {}

    bool next(InputFrame& frame) override {
        while (index_ < items_.size()) {
            const Item& item = items_[index_];
            if (!item.video) {
                ++index_;
                std::string why;
                cv::Mat img = readImageStrict(item.path, &why);
                if (img.empty())
                    throw FileError(item.path.string(), "cannot be read as an image: " + why);
                frame.bgr = img;
                frame.name = item.path.filename().string();
                frame.timeSeconds = double(imageCount_++) / 30.0;
                return true;
            }
            if (!video_.isOpened()) {
                if (!video_.open(item.path.string()) || !video_.isOpened())
                    throw FileError(item.path.string(), "cannot be opened as a video");
                const double count = video_.get(cv::CAP_PROP_FRAME_COUNT);
                step_ = options_.allVideoFrames ? 1 : options_.videoStep;
                if (step_ <= 0)
                    step_ = count > 0 ? std::max(1, int(std::ceil(count / options_.maxVideoFrames)))
                                      : 1;
                frameIndex_ = 0;
                fps_ = video_.get(cv::CAP_PROP_FPS);
                if (!(fps_ > 0)) fps_ = 30;
                delivered_ = 0;
            }
            cv::Mat img;
            bool got = false;
            while (video_.read(img)) {
                const int idx = frameIndex_++;
                if (idx % step_ == 0) {
                    got = true;
                    frame.bgr = img.channels() == 3 ? img : toBgr(img);
                    frame.name = fmt::format("{}#{}", item.path.filename().string(), idx);
                    frame.timeSeconds = idx / fps_;
                    break;
                }
            }
            if (got) {
                ++delivered_;
                return true;
            }
            video_.release();
            if (delivered_ == 0)
                throw FileError(item.path.string(), "video has no readable frames");
            ++index_;
        }
        return false;
    }

    int frameCountHint() const override {
        int n = 0;
        for (const auto& i : items_)
            if (!i.video) ++n;
        return n == int(items_.size()) ? n : -1;
    }

private:
    static cv::Mat toBgr(const cv::Mat& m) {
        cv::Mat out;
        if (m.channels() == 1)
            cv::cvtColor(m, out, cv::COLOR_GRAY2BGR);
        else if (m.channels() == 4)
            cv::cvtColor(m, out, cv::COLOR_BGRA2BGR);
        else
            out = m;
        return out;
    }

    std::vector<Item> items_;
    FrameSourceOptions options_;
    size_t index_ = 0;
    int imageCount_ = 0;
    cv::VideoCapture video_;
    int step_ = 1, frameIndex_ = 0, delivered_ = 0;
    double fps_ = 30;
};

}  // namespace

bool isImageFile(const fs::path& p) {
    static const char* exts[] = {".png",  ".jpg", ".jpeg", ".bmp", ".tif",
                                 ".tiff", ".pgm", ".ppm",  ".webp"};
    const auto e = lowerExtension(p);
    return std::any_of(std::begin(exts), std::end(exts), [&](const char* x) { return e == x; });
}

bool isVideoFile(const fs::path& p) {
    static const char* exts[] = {".mp4", ".mkv", ".avi", ".mov", ".webm", ".m4v", ".mpg", ".mpeg"};
    const auto e = lowerExtension(p);
    return std::any_of(std::begin(exts), std::end(exts), [&](const char* x) { return e == x; });
}

std::unique_ptr<FrameSource> openFrameSource(const std::vector<std::string>& inputs,
                                             const FrameSourceOptions& options) {
    if (inputs.empty()) throw Error("no input given: name image files, a folder or a video");
    std::vector<Item> items;
    for (const auto& in : inputs) {
        const fs::path p(in);
        std::error_code ec;
        if (fs::is_directory(p, ec)) {
            std::vector<fs::path> files;
            for (const auto& e : fs::directory_iterator(p, ec))
                if (e.is_regular_file() && isImageFile(e.path())) files.push_back(e.path());
            if (ec) throw FileError(in, "cannot list the folder: " + ec.message());
            if (files.empty())
                throw FileError(in, "folder has no images (.png, .jpg, .bmp, .tif ...)");
            std::sort(files.begin(), files.end());
            for (auto& f : files) items.push_back({f, false});
        } else if (fs::is_regular_file(p, ec)) {
            if (isImageFile(p))
                items.push_back({p, false});
            else if (isVideoFile(p))
                items.push_back({p, true});
            else
                throw FileError(in, "neither an image (.png .jpg ...) nor a video (.mp4 .mkv ...)");
        } else {
            throw FileError(in, "does not exist");
        }
    }
    return std::make_unique<MultiSource>(std::move(items), options);
}

}  // namespace mirage::calib
