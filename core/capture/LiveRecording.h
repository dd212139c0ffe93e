#pragma once
// A live session recorded as it runs, in the session format (docs/session.md), so that
// `mirage replay` of it reproduces what was shown live:
//   session.json, main.mkv, frames.csv   as SessionWriter writes them (crash-safe)
//   main.yaml, board.json                copies of the calibration and board the session used
//   env.mkv, env.yaml                    with an environment camera: per main frame the
//                                        environment frame that lit it, and a copy of its
//                                        calibration (intrinsics, extrinsics, radiometry)
//   poses.csv                            the pose of every recorded frame as tracked live (the
//                                        `mirage track` format; replay it with --poses)
// Only the frames the live loop processed are recorded (a frame dropped because processing was
// slower than the camera is neither shown nor recorded), so the replay sees the same frames in
// the same order, with the same temporal history.
//
// Crash safety: copies and session.json before any footage; per frame the image, then its
// frames.csv row, then its poses.csv row, each with write(2). A process killed at any point
// leaves every frame with a frames.csv row readable, and all but at most the last with a pose.
#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "core/session/PosesCsv.h"
#include "core/session/Session.h"

namespace mirage {

class LiveRecording {
public:
    struct Options {
        double fps = 30;  // nominal frame rate of the camera (session.json)
        int jpegQuality = 92;
        std::string createdBy = "mirage live";
        // The environment camera's calibration: when set, the session has a second camera
        // "env" (role environment) and every append() must give its frame.
        std::filesystem::path environmentCalibration;
    };
    // `dir` must not exist or be an empty folder (recorded footage is never mixed with or
    // written over other files); throws FileError otherwise, or when a copy fails.
    // `board` may be empty (no board file in the session).
    LiveRecording(const std::filesystem::path& dir, const std::filesystem::path& calibration,
                  const std::filesystem::path& board, Options options);
    ~LiveRecording();
    // The constructor's check of `dir` alone, for callers that check their outputs before work.
    static void checkFolder(const std::filesystem::path& dir);
    LiveRecording(const LiveRecording&) = delete;
    LiveRecording& operator=(const LiveRecording&) = delete;

    // One frame: 8-bit BGR sRGB as the camera delivered it, its time (seconds, CLOCK_MONOTONIC
    // for a camera) and the pose decision for it.
    void append(const cv::Mat& bgr, double t, const PoseRow& pose);
    // The same with the environment frame that lit it (8-bit BGR as its camera delivered it) and
    // that frame's capture time. An environment frame held over several main frames is appended
    // with each, under its own time: replay sees the same time again and keeps its lighting, as
    // live did.
    void append(const cv::Mat& bgr, double t, const PoseRow& pose, const cv::Mat& envBgr,
                double envT);
    bool hasEnvironment() const { return hasEnvironment_; }
    void close();
    int frames() const;
    const std::filesystem::path& dir() const { return dir_; }

private:
    std::filesystem::path dir_;
    std::unique_ptr<SessionWriter> writer_;
    int posesFd_ = -1;
    bool hasEnvironment_ = false;
};

}  // namespace mirage
