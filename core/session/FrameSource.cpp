// Frame sources: video files (FFmpeg through OpenCV), image folders, and a session camera's
// frames in frames.csv order.
#include <algorithm>
#include <cctype>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/Error.h"
#include "core/image/StrictJpeg.h"
#include "core/session/FrameInventory.h"
#include "core/session/MatroskaFrames.h"
#include "core/session/MatroskaScanner.h"
#include "core/session/Session.h"

namespace mirage {

namespace {

std::string lowerExtension(const std::filesystem::path& p) {
    std::string e = p.extension().string();
    for (auto& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

bool isImageFile(const std::filesystem::path& p) {
    static const std::vector<std::string> exts = {".png", ".jpg",  ".jpeg", ".bmp",
                                                  ".tif", ".tiff", ".ppm"};
    return std::find(exts.begin(), exts.end(), lowerExtension(p)) != exts.end();
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

// Reads one image file as 8-bit BGR; throws FileError if it is unreadable.
cv::Mat readImageFile(const std::filesystem::path& p) {
    std::string why;
    cv::Mat img = readImageStrict(p, &why);
    if (img.empty()) throw FileError(p.string(), "cannot decode image: " + why);
    return img;
}

// mirage's own recordings (Matroska MJPEG) are read by MatroskaFrames: exact frames or a
// reason why each is lost. Other videos go through FFmpeg.
std::unique_ptr<MatroskaFrames> openMatroskaMjpeg(const std::filesystem::path& path) {
    if (!isMatroska(path)) return nullptr;
    auto m = std::make_unique<MatroskaFrames>(path);
    if (!m->supported()) return nullptr;
    return m;
}

class VideoFileFrames final : public FrameSource {
public:
    explicit VideoFileFrames(const std::filesystem::path& path) : mkv_(openMatroskaMjpeg(path)) {
        if (mkv_) {
            count_ = mkv_->count();
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
        if (mkv_) {
            if (position_ >= count_) return false;
            MatroskaFrames::Frame f = mkv_->frame(position_++);
            bgr = f.bgr;
            problem_ = f.problem;
            last_ = f.seconds;
            return true;
        }
        if (limit_ >= 0 && position_ >= limit_) return false;
        if (!cap_.read(bgr) || bgr.empty()) return false;
        if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
        last_ = cap_.get(cv::CAP_PROP_POS_MSEC) / 1000.0;
        ++position_;
        return true;
    }
    int frameCount() const override { return count_; }
    std::optional<double> lastTimestamp() const override {
        return position_ > 0 ? std::optional<double>(last_) : std::nullopt;
    }
    std::string lastProblem() const override { return problem_; }

private:
    std::unique_ptr<MatroskaFrames> mkv_;
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
        ++next_;
        return true;
    }
    int frameCount() const override { return int(images_.size()); }
    std::optional<double> lastTimestamp() const override {
        // Image folders carry no clock; frame number / fps when a rate is known.
        if (lastIndex_ < 0 || fps_ <= 0) return std::nullopt;
        return lastIndex_ / fps_;
    }

private:
    std::map<int, std::filesystem::path> images_;
    double fps_;
    std::map<int, std::filesystem::path>::const_iterator next_;
    int lastIndex_ = -1;
};

// One camera of a session, row by row of Session::frames.
class SessionCameraFrames final : public FrameSource {
public:
    SessionCameraFrames(const Session& s, int cameraIndex)
        : rows_(s.frames), cameraIndex_(cameraIndex) {
        const auto path = s.path(s.cameras[size_t(cameraIndex)].video);
        if (std::filesystem::is_directory(path)) {
            images_ = listImageFrames(path, nullptr);
        } else {
            mkv_ = openMatroskaMjpeg(path);
            if (!mkv_) cap_ = openVideo(path);
        }
    }
    bool read(cv::Mat& bgr) override {
        if (row_ >= rows_.size()) return false;
        const int want = rows_[row_].index;
        problem_.clear();
        if (mkv_) {
            MatroskaFrames::Frame f = mkv_->frame(want);
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
            if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
        } else {
            const auto it = images_.find(want);
            if (it == images_.end()) return false;
            bgr = readImageFile(it->second);
        }
        last_ = rows_[row_].timestamps.at(size_t(cameraIndex_));
        ++row_;
        return true;
    }
    int frameCount() const override { return int(rows_.size()); }
    std::optional<double> lastTimestamp() const override {
        return row_ > 0 ? std::optional<double>(last_) : std::nullopt;
    }
    std::string lastProblem() const override { return problem_; }

private:
    std::vector<FrameRecord> rows_;
    int cameraIndex_;
    std::unique_ptr<MatroskaFrames> mkv_;
    std::string problem_;
    cv::VideoCapture cap_;
    std::map<int, std::filesystem::path> images_;
    size_t row_ = 0;
    int position_ = 0;
    double last_ = 0;
};

}  // namespace

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
        // but its stem does not end in a number).
        if (e.is_regular_file() && isImageFile(e.path())) files.push_back(e.path());
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

}  // namespace mirage
