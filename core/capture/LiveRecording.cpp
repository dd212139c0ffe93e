#include "core/capture/LiveRecording.h"

#include <fcntl.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>

#include "core/Error.h"

namespace mirage {
namespace {

void writeAll(int fd, const std::string& bytes, const std::filesystem::path& path) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            throw FileError(path.string(), std::string("write failed: ") + std::strerror(errno));
        }
        done += size_t(n);
    }
}

}  // namespace

LiveRecording::LiveRecording(const std::filesystem::path& dir,
                             const std::filesystem::path& calibration,
                             const std::filesystem::path& board, Options options)
    : dir_(dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    checkFolder(dir);
    fs::create_directories(dir, ec);
    if (ec) throw FileError(dir.string(), "cannot create the recording folder: " + ec.message());
    // The copies first: session.json names them, and the session must be complete from its
    // first frame on.
    Session meta;
    meta.cameras.push_back({"main", "main.mkv", "main.yaml", "main"});
    fs::copy_file(calibration, dir / "main.yaml", ec);
    if (ec)
        throw FileError(calibration.string(),
                        "cannot copy the calibration into the recording: " + ec.message());
    if (!options.environmentCalibration.empty()) {
        meta.cameras.push_back({"env", "env.mkv", "env.yaml", "environment"});
        fs::copy_file(options.environmentCalibration, dir / "env.yaml", ec);
        if (ec)
            throw FileError(options.environmentCalibration.string(),
                            "cannot copy the environment camera's calibration into the "
                            "recording: " +
                                ec.message());
        hasEnvironment_ = true;
    }
    meta.board.clear();
    if (!board.empty()) {
        fs::copy_file(board, dir / "board.json", ec);
        if (ec)
            throw FileError(board.string(),
                            "cannot copy the board into the recording: " + ec.message());
        meta.board = "board.json";
    }
    meta.createdBy = options.createdBy;
    SessionWriter::Options wo;
    wo.fps = options.fps;
    wo.jpegQuality = options.jpegQuality;
    writer_ = std::make_unique<SessionWriter>(dir, meta, wo);
    const auto poses = dir / "poses.csv";
    posesFd_ = ::open(poses.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
    if (posesFd_ < 0)
        throw FileError(poses.string(), std::string("cannot create: ") + std::strerror(errno));
    writeAll(posesFd_, posesCsvHeader(), poses);
}

void LiveRecording::checkFolder(const std::filesystem::path& dir) {
    namespace fs = std::filesystem;
    if (fs::exists(dir) && !(fs::is_directory(dir) && fs::is_empty(dir)))
        throw FileError(dir.string(),
                        "exists and is not an empty folder; record into a new folder so that "
                        "recorded footage is never mixed with or written over other files");
}

LiveRecording::~LiveRecording() {
    try {
        close();
    } catch (...) {
        // Every appended frame is on disk already.
    }
}

void LiveRecording::append(const cv::Mat& bgr, double t, const PoseRow& pose) {
    if (hasEnvironment_)
        throw Error(
            "LiveRecording::append: the recording has an environment camera; give its frame");
    if (posesFd_ < 0) throw Error("LiveRecording::append after close()");
    const int frame = writer_->framesWritten();
    writer_->append({bgr}, {t}, std::nullopt);  // image, then its frames.csv row
    writeAll(posesFd_, posesCsvRow(frame, t, pose), dir_ / "poses.csv");
}

void LiveRecording::append(const cv::Mat& bgr, double t, const PoseRow& pose, const cv::Mat& envBgr,
                           double envT) {
    if (!hasEnvironment_)
        throw Error("LiveRecording::append: the recording has no environment camera");
    if (posesFd_ < 0) throw Error("LiveRecording::append after close()");
    const int frame = writer_->framesWritten();
    writer_->append({bgr, envBgr}, {t, envT}, std::nullopt);  // images, then the frames.csv row
    writeAll(posesFd_, posesCsvRow(frame, t, pose), dir_ / "poses.csv");
}

void LiveRecording::close() {
    if (posesFd_ < 0) return;
    ::fsync(posesFd_);
    ::close(posesFd_);
    posesFd_ = -1;
    writer_->close();
}

int LiveRecording::frames() const {
    return writer_->framesWritten();
}

}  // namespace mirage
