// Frame sources: video files (MJPEG in Matroska or AVI through the strict readers of
// StrictVideoFrames.h; other videos through FFmpeg), image folders, a session camera's frames in
// frames.csv order, and lists of image files, folders and videos (calibration inputs).
#include "core/session/FrameSource.h"

#include <algorithm>
#include <cctype>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/OutputFile.h"
#include "core/image/StrictJpeg.h"
#include "core/session/FrameInventory.h"
#include "core/session/MatroskaScanner.h"
#include "core/session/Session.h"
#include "core/session/StrictVideoFrames.h"

namespace mirage {

namespace {

std::string lowerExtension(const std::filesystem::path& p) {
    std::string e = p.extension().string();
    for (auto& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

bool isMatroska(const std::filesystem::path& p) {
    const std::string e = lowerExtension(p);
    return e == ".mkv" || e == ".webm" || e == ".mka";
}

// Trailing decimal number of a file stem ("frame_000123" -> 123); -1 if none.
long long trailingNumber(const std::string& stem) {
    size_t i = stem.size();
    while (i > 0 && std::isdigit(static_cast<unsigned char>(stem[i - 1]))) --i;
    if (i == stem.size() || stem.size() - i > 12) return -1;
    return std::stoll(stem.substr(i));
}

cv::VideoCapture openVideo(const std::filesystem::path& path) {
    cv::VideoCapture cap;
    try {
        cap.open(path.string(), cv::CAP_FFMPEG);
    } catch (const cv::Exception& e) {
        throw FileError(path.string(), std::string("cannot open video: ") + e.err);
    }
    if (!cap.isOpened())
        throw FileError(path.string(), "cannot open video (not a video FFmpeg can read, or empty)");
    return cap;
}

// Video decoders may deliver grey or BGRA frames; sources deliver BGR.
void toBgr(cv::Mat& img) {
    if (img.channels() == 1)
        cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
    else if (img.channels() == 4)
        cv::cvtColor(img, img, cv::COLOR_BGRA2BGR);
}

// Reads one image file as 8-bit BGR; throws FileError if it is unreadable.
cv::Mat readImageFile(const std::filesystem::path& p) {
    std::string why;
    cv::Mat img = readImageStrict(p, &why);
    if (img.empty()) throw FileError(p.string(), "cannot decode image: " + why);
    return img;
}

class VideoFileFrames final : public FrameSource {
public:
    explicit VideoFileFrames(const std::filesystem::path& path)
        : strict_(openStrictVideo(path)), fileName_(path.filename().string()) {
        if (strict_) {
            count_ = strict_->count();
            return;
        }
        cap_ = openVideo(path);
        if (isMatroska(path)) {
            const MatroskaScan scan = scanMatroska(path);
            count_ = scan.completeFrames;
            // A cut-short last block must not come back as a half-grey frame.
            limit_ = scan.truncated ? count_ : -1;
        } else {
            const double n = cap_.get(cv::CAP_PROP_FRAME_COUNT);
            count_ = n > 0 ? int(n) : -1;
        }
    }
    bool read(cv::Mat& bgr) override {
        if (strict_) {
            if (position_ >= count_) return false;
            StrictVideoFrames::Frame f = strict_->frame(position_++);
            bgr = f.bgr;
            problem_ = f.problem;
            last_ = f.seconds;
            return true;
        }
        if (limit_ >= 0 && position_ >= limit_) return false;
        if (!cap_.read(bgr) || bgr.empty()) return false;
        toBgr(bgr);
        last_ = cap_.get(cv::CAP_PROP_POS_MSEC) / 1000.0;
        ++position_;
        return true;
    }
    int frameCount() const override { return count_; }
    std::optional<double> lastTimestamp() const override {
        return position_ > 0 ? std::optional<double>(last_) : std::nullopt;
    }
    std::string lastProblem() const override { return problem_; }
    std::string lastName() const override {
        return position_ > 0 ? fmt::format("{}#{}", fileName_, position_ - 1) : std::string();
    }

private:
    std::unique_ptr<StrictVideoFrames> strict_;  // MJPEG in Matroska or AVI; else FFmpeg
    std::string fileName_;
    cv::VideoCapture cap_;
    int count_ = -1, limit_ = -1, position_ = 0;
    double last_ = 0;
    std::string problem_;
};

class ImageFolderFrames final : public FrameSource {
public:
    ImageFolderFrames(std::map<int, std::filesystem::path> images, double fps)
        : images_(std::move(images)), fps_(fps), next_(images_.begin()) {}
    bool read(cv::Mat& bgr) override {
        if (next_ == images_.end()) return false;
        bgr = readImageFile(next_->second);
        lastIndex_ = next_->first;
        lastName_ = next_->second.filename().string();
        ++next_;
        return true;
    }
    int frameCount() const override { return int(images_.size()); }
    std::optional<double> lastTimestamp() const override {
        // Image folders carry no clock; frame number / fps when a rate is known.
        if (lastIndex_ < 0 || fps_ <= 0) return std::nullopt;
        return lastIndex_ / fps_;
    }
    std::string lastName() const override { return lastName_; }

private:
    std::map<int, std::filesystem::path> images_;
    double fps_;
    std::map<int, std::filesystem::path>::const_iterator next_;
    int lastIndex_ = -1;
    std::string lastName_;
};

// One camera of a session, row by row of Session::frames.
class SessionCameraFrames final : public FrameSource {
public:
    SessionCameraFrames(const Session& s, int cameraIndex)
        : rows_(s.frames), cameraIndex_(cameraIndex) {
        const auto path = s.path(s.cameras[size_t(cameraIndex)].video);
        fileName_ = path.filename().string();
        if (std::filesystem::is_directory(path)) {
            images_ = listImageFrames(path, nullptr);
        } else {
            strict_ = openStrictVideo(path);
            if (!strict_) cap_ = openVideo(path);
        }
    }
    bool read(cv::Mat& bgr) override {
        if (row_ >= rows_.size()) return false;
        const int want = rows_[row_].index;
        problem_.clear();
        if (strict_) {
            StrictVideoFrames::Frame f = strict_->frame(want);
            bgr = f.bgr;
            problem_ = f.problem;
        } else if (cap_.isOpened()) {
            // Skip video frames that have no row (deleted or bad rows) without decoding them.
            while (position_ < want) {
                if (!cap_.grab()) return false;
                ++position_;
            }
            if (!cap_.read(bgr) || bgr.empty()) return false;
            ++position_;
            toBgr(bgr);
        } else {
            const auto it = images_.find(want);
            if (it == images_.end()) return false;
            bgr = readImageFile(it->second);
        }
        lastName_ = images_.empty() ? fmt::format("{}#{}", fileName_, want)
                                    : images_.find(want)->second.filename().string();
        last_ = rows_[row_].timestamps.at(size_t(cameraIndex_));
        ++row_;
        return true;
    }
    int frameCount() const override { return int(rows_.size()); }
    std::optional<double> lastTimestamp() const override {
        return row_ > 0 ? std::optional<double>(last_) : std::nullopt;
    }
    std::string lastProblem() const override { return problem_; }
    std::string lastName() const override { return lastName_; }

private:
    std::vector<FrameRecord> rows_;
    int cameraIndex_;
    std::string fileName_, lastName_;
    std::unique_ptr<StrictVideoFrames> strict_;
    std::string problem_;
    cv::VideoCapture cap_;
    std::map<int, std::filesystem::path> images_;
    size_t row_ = 0;
    int position_ = 0;
    double last_ = 0;
};

// Image files, folders and videos as one stream (openFrameList).
class FrameListFrames final : public FrameSource {
public:
    struct Item {
        std::filesystem::path path;
        enum Kind { Image, Folder, Video } kind;
    };
    FrameListFrames(std::vector<Item> items, const FrameListOptions& o)
        : items_(std::move(items)), options_(o) {
        for (const Item& i : items_) {
            if (i.kind == Item::Video) {
                count_ = -1;
                break;
            }
            count_ += i.kind == Item::Image ? 1 : int(listImageFrames(i.path, nullptr).size());
        }
    }

    bool read(cv::Mat& bgr) override {
        while (index_ < items_.size()) {
            const Item& item = items_[index_];
            if (item.kind == Item::Image) {
                ++index_;
                bgr = readImageFile(item.path);
                name_ = item.path.filename().string();
                problem_.clear();
                timestamp_.reset();
                return true;
            }
            if (!current_) open(item);
            if (readSampled(bgr)) return true;
            if (item.kind == Item::Video && delivered_ == 0)
                throw FileError(item.path.string(), "video has no readable frames");
            current_.reset();
            ++index_;
        }
        return false;
    }
    int frameCount() const override { return count_; }
    std::optional<double> lastTimestamp() const override { return timestamp_; }
    std::string lastProblem() const override { return problem_; }
    std::string lastName() const override { return name_; }

private:
    void open(const Item& item) {
        current_ = openFrames(item.path);
        step_ = 1;
        if (item.kind == Item::Video && !options_.allVideoFrames) {
            step_ = options_.videoStep;
            const int n = current_->frameCount();
            if (step_ <= 0)
                step_ = n > 0 ? std::max(1, (n + options_.maxVideoFrames - 1) /
                                                std::max(1, options_.maxVideoFrames))
                              : 1;
        }
        read_ = delivered_ = 0;
    }
    // The next frame of the current item whose index is a multiple of the step.
    bool readSampled(cv::Mat& bgr) {
        while (current_->read(bgr)) {
            if (read_++ % step_ != 0) continue;
            ++delivered_;
            name_ = current_->lastName();
            problem_ = current_->lastProblem();
            timestamp_ = current_->lastTimestamp();
            return true;
        }
        return false;
    }

    std::vector<Item> items_;
    FrameListOptions options_;
    int count_ = 0;
    size_t index_ = 0;
    std::unique_ptr<FrameSource> current_;
    int step_ = 1, read_ = 0, delivered_ = 0;
    std::string name_, problem_;
    std::optional<double> timestamp_;
};

}  // namespace

bool isImageFile(const std::filesystem::path& p) {
    static const char* const exts[] = {".png",  ".jpg", ".jpeg", ".bmp", ".tif",
                                       ".tiff", ".pgm", ".ppm",  ".webp"};
    const std::string e = lowerExtension(p);
    return std::any_of(std::begin(exts), std::end(exts), [&](const char* x) { return e == x; });
}

bool isVideoFile(const std::filesystem::path& p) {
    static const char* const exts[] = {".mp4",  ".mkv", ".avi", ".mov",
                                       ".webm", ".m4v", ".mpg", ".mpeg"};
    const std::string e = lowerExtension(p);
    return std::any_of(std::begin(exts), std::end(exts), [&](const char* x) { return e == x; });
}

bool FrameInventory::has(int index) const {
    if (isFolder) return images.count(index) > 0;
    return index >= 0 && (videoFrames < 0 || index < videoFrames);
}

int FrameInventory::count() const {
    return isFolder ? int(images.size()) : videoFrames;
}

std::map<int, std::filesystem::path> listImageFrames(const std::filesystem::path& folder,
                                                     std::vector<std::string>* problems) {
    std::vector<std::filesystem::path> files;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(folder, ec))
        // Skip temporary files of atomic writes ("000012.png.tmp.png" has a .png extension
        // but its stem does not end in a number) and of outputs being written
        // ("out.partial-123.png", core/OutputFile.h): never read a command's own partial output.
        if (e.is_regular_file() && isImageFile(e.path()) && !isPartialOutputName(e.path()))
            files.push_back(e.path());
    if (ec) throw FileError(folder.string(), "cannot list image folder: " + ec.message());
    std::sort(files.begin(), files.end());
    std::map<int, std::filesystem::path> byNumber;
    bool numbered = true;
    for (const auto& f : files) {
        const std::string stem = f.stem().string();
        if (stem.find(".tmp") != std::string::npos) continue;
        const long long n = trailingNumber(stem);
        if (n < 0 || n > 1'000'000'000 || byNumber.count(int(n))) {
            numbered = false;
            break;
        }
        byNumber.emplace(int(n), f);
    }
    if (numbered) return byNumber;
    if (problems)
        problems->push_back(folder.string() +
                            ": image names are not all distinctly numbered; frames taken in "
                            "name order");
    std::map<int, std::filesystem::path> byOrder;
    int i = 0;
    for (const auto& f : files)
        if (f.stem().string().find(".tmp") == std::string::npos) byOrder.emplace(i++, f);
    return byOrder;
}

FrameInventory inventoryFrames(const std::filesystem::path& path) {
    FrameInventory inv;
    if (std::filesystem::is_directory(path)) {
        inv.isFolder = true;
        inv.images = listImageFrames(path, &inv.problems);
        return inv;
    }
    if (!std::filesystem::exists(path)) throw FileError(path.string(), "video file is missing");
    if (const auto strict = openStrictVideo(path); strict && !isMatroska(path)) {
        inv.videoFrames = strict->count();
        if (!strict->containerProblem().empty())
            inv.problems.push_back(path.filename().string() + ": " + strict->containerProblem());
        return inv;
    }
    if (isMatroska(path)) {
        const MatroskaScan scan = scanMatroska(path);
        // Frames lost inside damaged bytes keep their numbers: the rows after them still match.
        inv.videoFrames = scan.blocks.empty() ? 0 : scan.blocks.back().position + 1;
        if (scan.truncated || !scan.problem.empty())
            inv.problems.push_back(path.filename().string() + ": " + scan.problem + "; " +
                                   std::to_string(scan.completeFrames) + " complete frames kept");
        return inv;
    }
    cv::VideoCapture cap = openVideo(path);
    const double n = cap.get(cv::CAP_PROP_FRAME_COUNT);
    inv.videoFrames = n > 0 ? int(n) : -1;
    return inv;
}

std::unique_ptr<FrameSource> openFrames(const std::filesystem::path& videoOrFolder) {
    if (std::filesystem::is_directory(videoOrFolder)) {
        auto images = listImageFrames(videoOrFolder, nullptr);
        if (images.empty())
            throw FileError(videoOrFolder.string(), "folder holds no image files (.png, .jpg...)");
        return std::make_unique<ImageFolderFrames>(std::move(images), 0.0);
    }
    if (!std::filesystem::exists(videoOrFolder))
        throw FileError(videoOrFolder.string(), "no such video file or image folder");
    return std::make_unique<VideoFileFrames>(videoOrFolder);
}

std::unique_ptr<FrameSource> openCameraFrames(const Session& s, const std::string& camera) {
    const int i = s.cameraIndex(camera);
    if (i < 0) {
        std::string names;
        for (const auto& c : s.cameras) names += (names.empty() ? "" : ", ") + c.name;
        throw FileError((s.dir / "session.json").string(),
                        "no camera named '" + camera + "' (cameras: " + names + ")");
    }
    return std::make_unique<SessionCameraFrames>(s, i);
}

std::unique_ptr<FrameSource> openFrameList(const std::vector<std::string>& inputs,
                                           const FrameListOptions& options) {
    namespace fs = std::filesystem;
    if (inputs.empty()) throw Error("no input given: name image files, a folder or a video");
    std::vector<FrameListFrames::Item> items;
    for (const std::string& in : inputs) {
        const fs::path p(in);
        std::error_code ec;
        if (fs::is_directory(p, ec)) {
            if (listImageFrames(p, nullptr).empty())
                throw FileError(in, "folder has no images (.png, .jpg, .bmp, .tif ...)");
            items.push_back({p, FrameListFrames::Item::Folder});
        } else if (fs::is_regular_file(p, ec)) {
            if (isImageFile(p))
                items.push_back({p, FrameListFrames::Item::Image});
            else if (isVideoFile(p))
                items.push_back({p, FrameListFrames::Item::Video});
            else
                throw FileError(in, "neither an image (.png .jpg ...) nor a video (.mp4 .mkv ...)");
        } else {
            throw FileError(in, "does not exist");
        }
    }
    return std::make_unique<FrameListFrames>(std::move(items), options);
}

}  // namespace mirage
