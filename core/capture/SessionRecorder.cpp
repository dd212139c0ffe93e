#include "core/capture/SessionRecorder.h"

#include "core/Error.h"

namespace mirage {

Session SessionRecorder::withCameraNames(Session meta, size_t count) {
    // Checked here, before the writer creates the session folder.
    if (count == 0) throw Error("SessionRecorder: no frame sources");
    if (meta.cameras.empty())
        for (size_t i = 0; i < count; ++i)
            meta.cameras.push_back({i == 0   ? "main"
                                    : i == 1 ? "env"
                                             : "cam" + std::to_string(i),
                                    "", "", i == 0 ? "main" : "environment"});
    if (meta.cameras.size() != count)
        throw Error("SessionRecorder: " + std::to_string(meta.cameras.size()) +
                    " cameras named for " + std::to_string(count) + " sources");
    return meta;
}

SessionRecorder::SessionRecorder(const std::filesystem::path& dir, Session meta,
                                 std::vector<FrameSource*> sources, Options opts)
    : sources_(std::move(sources)),
      opts_(opts),
      writer_(dir, withCameraNames(std::move(meta), sources_.size()), opts.writer) {
    for (auto* s : sources_) MR_CHECK(s != nullptr, "SessionRecorder: null source");
}

bool SessionRecorder::recordFrame(const std::optional<Pose>& groundTruth) {
    if (opts_.maxFrames >= 0 && framesRecorded() >= opts_.maxFrames) return false;
    images_.resize(sources_.size());
    std::vector<double> times;
    for (size_t i = 0; i < sources_.size(); ++i) {
        if (!sources_[i]->read(images_[i])) return false;
        // Without a source clock: frame number / fps, the same rule readers apply.
        times.push_back(sources_[i]->lastTimestamp().value_or(framesRecorded() / opts_.writer.fps));
    }
    writer_.append(images_, times, groundTruth);
    return true;
}

int SessionRecorder::run(const std::atomic<bool>* stop,
                         const std::function<void(const std::vector<cv::Mat>&)>& onFrame) {
    int n = 0;
    while (!(stop && stop->load()) && recordFrame()) {
        ++n;
        if (onFrame) onFrame(images_);
    }
    return n;
}

}  // namespace mirage
