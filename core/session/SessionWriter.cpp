// SessionWriter: the write order is what makes a session crash-safe (docs/session.md):
//   1. session.json, atomically, before any footage;
//   2. per frame: every camera's image (MKV cluster via write(2), or PNG via temp + rename);
//   3. then the frame's frames.csv row, written with one write(2) call.
// A process killed between any two steps leaves rows only for frames whose images are complete.
#include <fcntl.h>
#include <unistd.h>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/Timestamp.h"
#include "core/image/ImageIO.h"
#include "core/session/AtomicFile.h"
#include "core/session/FramesCsv.h"
#include "core/session/MatroskaWriter.h"
#include "core/session/Session.h"

namespace mirage {

struct SessionWriter::Impl {
    Session session;
    Options opts;
    std::vector<std::unique_ptr<MatroskaWriter>> videos;  // per camera, MKV mode
    int csvFd = -1;
    int frames = 0;
    bool closed = false;

    void writeCsv(const std::string& bytes) {
        size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = ::write(csvFd, bytes.data() + done, bytes.size() - done);
            if (n < 0) {
                if (errno == EINTR) continue;
                throw FileError(session.path(session.framesFile).string(),
                                std::string("write failed: ") + std::strerror(errno));
            }
            done += size_t(n);
        }
    }
};

SessionWriter::SessionWriter(const std::filesystem::path& dir, Session meta, Options opts)
    : impl_(std::make_unique<Impl>()) {
    if (!(opts.fps > 0 && std::isfinite(opts.fps)))
        throw Error("SessionWriter: frame rate must be positive, got " + std::to_string(opts.fps));
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw FileError(dir.string(), "cannot create session folder: " + ec.message());
    if (std::filesystem::exists(dir / "session.json"))
        throw FileError(dir.string(),
                        "already holds a session (session.json); choose a new folder so that "
                        "recorded footage is never overwritten");

    Session& s = impl_->session;
    s = std::move(meta);
    s.dir = dir;
    s.format = kSessionFormat;
    s.version = kSessionVersion;
    s.fps = opts.fps;
    if (s.framesFile.empty()) s.framesFile = "frames.csv";
    if (s.cameras.empty()) s.cameras.push_back({"main", "", "", "main"});
    for (size_t i = 0; i < s.cameras.size(); ++i) {
        auto& c = s.cameras[i];
        if (c.name.empty() || c.name.find_first_of(", \t/") != std::string::npos)
            throw Error("SessionWriter: camera name '" + c.name +
                        "' must be a non-empty word (it names a frames.csv column)");
        if (c.role.empty()) c.role = i == 0 ? "main" : "environment";
        if (c.video.empty()) c.video = opts.imageSequence ? c.name : c.name + ".mkv";
    }
    if (s.createdBy.empty()) s.createdBy = "mirage";
    if (s.createdAt.empty()) s.createdAt = utcTimestamp();
    impl_->opts = opts;

    writeSessionJson(s);  // 1: the folder is a session before any footage exists

    for (const auto& c : s.cameras) {
        if (opts.imageSequence) {
            std::filesystem::create_directories(s.path(c.video), ec);
            if (ec) throw FileError(s.path(c.video).string(), "cannot create: " + ec.message());
            impl_->videos.push_back(nullptr);
        } else {
            impl_->videos.push_back(
                std::make_unique<MatroskaWriter>(s.path(c.video), opts.fps, opts.jpegQuality));
        }
    }
    const auto csv = s.path(s.framesFile);
    impl_->csvFd = ::open(csv.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
    if (impl_->csvFd < 0)
        throw FileError(csv.string(), std::string("cannot create: ") + std::strerror(errno));
    std::vector<std::string> names;
    for (const auto& c : s.cameras) names.push_back(c.name);
    impl_->writeCsv(framesCsvHeader(names));
}

SessionWriter::~SessionWriter() {
    try {
        close();
    } catch (...) {
        // Destructors must not throw; every completed frame is already on disk.
    }
}

void SessionWriter::append(const std::vector<cv::Mat>& images,
                           const std::vector<double>& timestamps,
                           const std::optional<Pose>& groundTruth) {
    Impl& m = *impl_;
    if (m.closed) throw Error("SessionWriter::append after close()");
    const Session& s = m.session;
    const size_t n = s.cameras.size();
    if (images.size() != n)
        throw Error("SessionWriter::append: " + std::to_string(images.size()) + " images for " +
                    std::to_string(n) + " cameras");
    if (!timestamps.empty() && timestamps.size() != n)
        throw Error("SessionWriter::append: " + std::to_string(timestamps.size()) +
                    " timestamps for " + std::to_string(n) + " cameras");
    if (groundTruth && !groundTruth->isFinite())
        throw Error("SessionWriter::append: ground-truth pose is not finite");

    FrameRecord row;
    row.index = m.frames;
    row.groundTruth = groundTruth;
    for (size_t c = 0; c < n; ++c) {
        const double t = timestamps.empty() ? m.frames / s.fps : timestamps[c];
        if (!std::isfinite(t)) throw Error("SessionWriter::append: timestamp is not finite");
        row.timestamps.push_back(t);
    }

    // 2: images first.
    for (size_t c = 0; c < n; ++c) {
        const cv::Mat& img = images[c];
        if (img.empty() || img.depth() != CV_8U || (img.channels() != 3 && img.channels() != 1))
            throw Error("SessionWriter::append: camera '" + s.cameras[c].name +
                        "' image must be 8-bit BGR (or grey)");
        if (m.videos[c]) {
            m.videos[c]->append(img, row.timestamps[c], m.opts.fsyncEachFrame);
        } else {
            char name[32];
            std::snprintf(name, sizeof name, "%06d.png", row.index);
            cv::Mat bgr = img;
            if (img.channels() == 1) cv::cvtColor(img, bgr, cv::COLOR_GRAY2BGR);
            const auto file = s.path(s.cameras[c].video) / name;
            if (m.opts.fsyncEachFrame) {
                // Encoded in memory, then temp + fsync + rename + folder fsync.
                std::vector<uint8_t> png;
                if (!cv::imencode(".png", bgr, png))
                    throw FileError(file.string(), "PNG encoding failed");
                writeFileAtomically(
                    file, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
            } else {
                writeBgr8(file, bgr);  // temp + rename
            }
        }
    }
    // 3: then the row, in one write so a crash never leaves half a row... except a torn write
    // on a full disk, which readers detect as a short last row.
    m.writeCsv(framesCsvRow(row));
    if (m.opts.fsyncEachFrame && ::fsync(m.csvFd) != 0)
        throw FileError(s.path(s.framesFile).string(),
                        std::string("fsync failed: ") + std::strerror(errno));
    ++m.frames;
}

void SessionWriter::close() {
    Impl& m = *impl_;
    if (m.closed) return;
    m.closed = true;
    std::string firstError;
    for (auto& v : m.videos) {
        if (!v) continue;
        try {
            v->close();
        } catch (const Error& e) {
            if (firstError.empty()) firstError = e.what();
        }
    }
    if (m.csvFd >= 0) {
        if (::fsync(m.csvFd) != 0 && firstError.empty())
            firstError = m.session.framesFile + ": fsync failed: " + std::strerror(errno);
        ::close(m.csvFd);
        m.csvFd = -1;
    }
    if (!firstError.empty()) throw Error(firstError);
}

int SessionWriter::framesWritten() const {
    return impl_->frames;
}
const Session& SessionWriter::session() const {
    return impl_->session;
}

}  // namespace mirage
