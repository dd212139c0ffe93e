#pragma once
// The record stage of `mirage replay`: OUT.mkv (MJPEG in Matroska, one cluster per frame: Ctrl-C
// or a crash leaves every finished frame playable) or a folder of PNG frames (frame_000000.png,
// sRGB 8-bit), and beside it a per-frame CSV (OUT with .csv, or OUT/frames.csv for a folder):
//   frame,t,state,reason,decode_ms,tracking_ms,<pass>_ms...,gpu_ms,readback_ms,encode_ms,
//   frame_ms,tx,ty,tz,qw,qx,qy,qz,environment
// where <pass>_ms are the GL timer-query times of the renderer's passes (0 when skipped) and the
// pose is T_world_camera (OpenCV axes). A lost frame has a row and no image. The files are
// written under temporary names and moved into place by finish(), also after an interruption.
// It counts what it wrote: the images in the video or folder, and the rows.
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "app/FrameCompositor.h"
#include "core/OutputFile.h"
#include "core/session/MatroskaWriter.h"

namespace mirage::app {

// The times of one frame's stages (ms), for its CSV row.
struct ReplayFrameTimes {
    double decodeMs = 0, encodeMs = 0, frameMs = 0;
};

class ReplayOutputs {
public:
    // `out`: OUT.mkv when `mkv`, else the folder for PNG frames (checked and created by the
    // caller); the CSV at `csvPath` is checked here (never an input; not replaced without
    // rule.force).
    ReplayOutputs(const std::filesystem::path& out, bool mkv, const std::filesystem::path& csvPath,
                  const OutputRule& rule);

    // Creates the writers and the CSV header (`passes`: the frame graph's order).
    void open(double fps, int jpegQuality, const std::vector<std::string>& passes);
    // The composite of session frame `index` at time `t` (8-bit BGR sRGB); an empty image (a
    // lost frame) writes nothing. Returns whether an image was written.
    bool writeImage(int index, const cv::Mat& image, double t);
    void writeRow(int index, double t, const CompositedFrame& frame, const ReplayFrameTimes& times,
                  const std::string& environment);
    // Closes the video and the CSV and moves them into place. Safe to call twice.
    void finish();

    int imagesWritten() const { return images_; }  // frames in the video (or PNG files)
    int rowsWritten() const { return rows_; }
    const std::filesystem::path& csvPath() const { return csvPath_; }

private:
    std::filesystem::path out_, csvPath_;
    bool mkv_;
    std::optional<OutputFile> videoOut_, csvOut_;
    std::unique_ptr<MatroskaWriter> video_;
    std::ofstream csv_;
    std::vector<std::string> passes_;
    int images_ = 0, rows_ = 0;
    bool finished_ = false;
};

}  // namespace mirage::app
