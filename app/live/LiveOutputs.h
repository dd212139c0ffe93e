#pragma once
// The record stage of a live session, part one: the composites written as they are made (-o):
// OUT.mkv (MJPEG in Matroska) or a folder of PNG frames, with a per-frame CSV beside it (OUT.csv
// or OUT/frames.csv):
//   frame,t,state,reason,camera_frame,dropped,driver_dropped,env_age_ms,tracking_ms,
//   <pass>_ms...,gpu_ms,readback_ms,frame_ms,latency_ms,handoff_ms,predict_ms,
//   tx,ty,tz,qw,qx,qy,qz
// frame = processed frame number (from 0), t = capture time (seconds, CLOCK_MONOTONIC),
// camera_frame = the camera's frame counter, dropped = camera frames dropped before this one was
// taken (newer ones replaced them while processing was busy), driver_dropped = those the V4L2
// driver dropped (sequence-number gaps), env_age_ms = main capture time minus that of the
// environment frame lighting it (empty without one), latency_ms = output written (or shown)
// minus capture time, handoff_ms = how long the tracked frame waited for the GL thread
// (pipelined; 0 serial), predict_ms = how far past its capture time the pose was predicted (to
// the expected display time; empty: not predicted, the pose as tracked). The pose is the one
// composited, T_world_camera, numbers in their shortest exact form (the file
// is a poses file for `mirage replay --poses`). Both files are written under temporary names and
// moved into place by finish(), also after an interruption (every frame written is in them).
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "app/FrameCompositor.h"
#include "core/OutputFile.h"
#include "core/capture/LatestFrameCapture.h"
#include "core/session/MatroskaWriter.h"

namespace mirage::app {

// The pipelined loop's times of a frame (ms): the tracked frame's wait in the hand-off, and the
// prediction's horizon (NaN: the pose was not predicted).
struct LivePipelineTimes {
    double handoffMs = 0;
    double predictMs = std::numeric_limits<double>::quiet_NaN();
};

class LiveOutputs {
public:
    // Checks the outputs before any work (never an input; the CSV not replaced without
    // rule.force). `out` empty: no outputs (every call below does nothing).
    LiveOutputs(const std::filesystem::path& out, const OutputRule& rule);

    // Creates the video writer and the CSV with its header (`passes`: the frame graph's order).
    void open(double fps, int jpegQuality, const std::vector<std::string>& passes);
    // The composite of processed frame `frame` (8-bit BGR sRGB) at capture time `t`.
    void writeImage(int frame, const cv::Mat& image, double t);
    // The frame's CSV row (flushed, so a crash keeps every finished row).
    void writeRow(int frame, const CapturedFrame& captured, double envAgeMs,
                  const CompositedFrame& composited, double frameMs, double latencyMs,
                  const LivePipelineTimes& pipeline = {});
    // Closes and moves the files into place; a file that would hold no frame is removed instead
    // (stopped before the first frame: nothing is left). Safe to call twice.
    void finish();

    bool enabled() const { return !out_.empty(); }
    int imagesWritten() const { return images_; }
    const std::filesystem::path& csvPath() const { return csvPath_; }

private:
    std::filesystem::path out_, csvPath_;
    bool mkv_ = false;
    std::optional<OutputFile> videoOut_, csvOut_;
    std::unique_ptr<MatroskaWriter> video_;
    std::ofstream csv_;
    std::vector<std::string> passes_;
    int images_ = 0, rows_ = 0;
};

}  // namespace mirage::app
