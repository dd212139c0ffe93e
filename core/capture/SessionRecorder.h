#pragma once
// Records frames from any FrameSources (live cameras, videos) into a session, so that a live
// run is replayable exactly: each frame of every source is appended with the source's own
// timestamp (or frame / fps when the source has no clock).
#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include "core/session/Session.h"

namespace mirage {

class SessionRecorder {
public:
    struct Options {
        SessionWriter::Options writer;
        int maxFrames = -1;  // stop after this many frames (-1: until a source ends or stop)
    };
    // `meta.cameras` names the cameras in `sources` order (default: "main", "env", ...).
    // The sources must outlive the recorder.
    SessionRecorder(const std::filesystem::path& dir, Session meta,
                    std::vector<FrameSource*> sources, Options opts);

    // Reads one frame from every source and appends it; false when any source has ended.
    // `groundTruth` (T_world_camera of the main camera) is stored when known.
    bool recordFrame(const std::optional<Pose>& groundTruth = std::nullopt);
    // Records until a source ends, maxFrames, or *stop becomes true. `onFrame` (optional) sees
    // each recorded frame's images (e.g. for a preview window). Returns frames recorded.
    int run(const std::atomic<bool>* stop = nullptr,
            const std::function<void(const std::vector<cv::Mat>&)>& onFrame = {});
    void close() { writer_.close(); }

    int framesRecorded() const { return writer_.framesWritten(); }
    const std::vector<cv::Mat>& lastImages() const { return images_; }
    const Session& session() const { return writer_.session(); }

private:
    static Session withCameraNames(Session meta, size_t count);
    std::vector<FrameSource*> sources_;
    Options opts_;
    SessionWriter writer_;
    std::vector<cv::Mat> images_;
};

}  // namespace mirage
