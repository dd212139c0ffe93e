#pragma once
// `mirage replay` as a loop of stages (docs/replay.md), each a member that can be built and
// tested alone:
//   capture  (FrameSource)        the session's main camera, decoded frame by frame
//   track    (ReplayPoses, PoseStage)  the pose of each frame: given, or tracked (as live)
//   render + composite (Renderer, FrameCompositor, ReplayEnvironment)  as live renders
//   present  (a window, --window) the composite blitted to it
//   record   (ReplayOutputs)      the video or PNG frames and the per-frame CSV, counting both
// Frames before the first written one (--warmup) run through track and render only, so that
// temporal history is warm at the seam of a range or shard.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/FrameCompositor.h"
#include "app/PoseStage.h"
#include "app/replay/ReplayEnvironment.h"
#include "app/replay/ReplayOptions.h"
#include "app/replay/ReplayOutputs.h"
#include "app/replay/ReplayPoses.h"
#include "core/OutputFile.h"
#include "core/Shards.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/scene/Scene.h"
#include "core/session/FrameSource.h"
#include "core/session/Session.h"
#include "render/Renderer.h"

namespace mirage::app {

// What a replay did: its rows (frames replayed and written to the CSV) and the images written
// (a lost frame has a row, no image).
struct ReplaySummary {
    int rows = 0, images = 0;
    bool interrupted = false;
};

class ReplaySession {
public:
    // Reads the session, checks the outputs before any work, loads calibration and scene,
    // chooses the pose source, creates the GL context, the renderer and the outputs.
    explicit ReplaySession(const ReplayOptions& options);
    ~ReplaySession();
    ReplaySession(const ReplaySession&) = delete;
    ReplaySession& operator=(const ReplaySession&) = delete;

    // Replays the frames and finishes the outputs (interrupted too: the frames done so far).
    // Returns the exit code: 0, or 128 + the signal that stopped it.
    int run();
    const ReplaySummary& summary() const { return summary_; }

private:
    void checkOutputs();
    void loadScene();
    void createRenderer();
    void selectFrames();
    // One session frame at position `pos`; `emit` false for a warm-up frame. False when the
    // video ended.
    bool step(int pos, bool emit);
    void logLights(int index, const CompositedFrame& frame);
    void finishShard();

    ReplayOptions options_;
    Session session_;
    const SessionCamera* main_ = nullptr;
    CameraCalibration calibration_;
    Scene scene_;
    std::filesystem::path placementFile_;

    // Outputs.
    std::filesystem::path userOut_, out_;
    bool split_ = false, userMkv_ = false, mkv_ = false;
    ShardSpec shard_;
    std::optional<StagedPath> staged_;
    std::unique_ptr<ReplayOutputs> outputs_;

    // Stages.
    std::unique_ptr<FrameSource> frames_;
    std::unique_ptr<ReplayPoses> poses_;
    std::unique_ptr<PoseStage> track_;
    std::unique_ptr<gl::Context> context_;
    std::unique_ptr<render::Renderer> renderer_;
    std::unique_ptr<FrameCompositor> compositor_;
    std::unique_ptr<ReplayEnvironment> environment_;

    // The frames: [begin_, begin_ + total_) of the session's list are written, from first_ on
    // processed; listed_ in the session, wanted_ in the range asked for.
    int listed_ = 0, wanted_ = 0, begin_ = 0, total_ = 0, first_ = 0;
    std::vector<int> block_;
    int processed_ = 0;
    bool windowClosed_ = false;
    std::vector<std::pair<int, double>> written_;  // a shard's frames with an image, and times
    ReplaySummary summary_;
};

}  // namespace mirage::app
