#pragma once
// A session: recorded (or synthetic) footage in a folder, the format of docs/session.md:
//   session.json   format "mirage-session", version, cameras, frame rate, files, creation info
//   main.mkv       main camera video (MJPEG in Matroska, one cluster per frame so that every
//                  completed frame survives a crash) — or a folder of numbered PNG/JPEG images
//   env.mkv        optional fish-eye environment camera
//   <camera>.yaml  OpenCV calibration per camera (core/camera/CalibrationFile.h)
//   board.json     the tag board (tracking/ reads it; the session only names it)
//   frames.csv     frame,t_<camera>...,gt_tx,gt_ty,gt_tz,gt_qw,gt_qx,gt_qy,gt_qz (gt optional)
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/math/Pose.h"

namespace mirage {

struct SessionCamera {
    std::string name;         // "main", "env"
    std::string video;        // file (.mkv) or folder of images, relative to the session folder
    std::string calibration;  // OpenCV YAML, relative to the session folder
    std::string role;         // "main" or "environment"
};

struct FrameRecord {
    int index = 0;
    std::vector<double> timestamps;  // seconds, one per camera in Session::cameras order
    std::optional<Pose> groundTruth;  // T_world_camera of the main camera (OpenCV axes)
};

struct Session {
    std::filesystem::path dir;
    std::string format = "mirage-session";
    int version = 1;
    double fps = 30.0;
    std::vector<SessionCamera> cameras;
    std::string board = "board.json";  // relative; may be empty
    std::string scene;                  // optional: the scene the footage was synthesised from
    std::string createdBy, createdAt;
    std::vector<FrameRecord> frames;

    const SessionCamera* camera(const std::string& name) const;
    std::filesystem::path path(const std::string& relative) const { return dir / relative; }
};

// What reading found wrong but could live with (truncated video, unreadable rows...).
struct SessionReadReport {
    std::vector<std::string> warnings;
    int framesListed = 0;    // rows in frames.csv
    int framesReadable = 0;  // rows whose images exist in every camera's video
};

// Reads session.json and frames.csv. Throws mirage::FileError when the folder is not a session
// at all; otherwise keeps what is there and lists what is missing in the report.
Session readSession(const std::filesystem::path& dir, SessionReadReport* report = nullptr);

// Sequential frame access for one camera of a session (video file or image folder).
class FrameSource {
public:
    virtual ~FrameSource() = default;
    // Next frame as 8-bit BGR (sRGB-encoded, as cameras deliver it); false at the end.
    virtual bool read(cv::Mat& bgr) = 0;
    virtual int frameCount() const = 0;  // -1 if unknown
};
std::unique_ptr<FrameSource> openCameraFrames(const Session& s, const std::string& camera);
// A plain video file or image folder, outside a session.
std::unique_ptr<FrameSource> openFrames(const std::filesystem::path& videoOrFolder);

// Writes a session frame by frame. Crash-safe: session.json is written first (atomically),
// each frame's images are flushed before its frames.csv row, and frames.csv is flushed per row,
// so an interrupted write leaves every completed frame readable.
class SessionWriter {
public:
    struct Options {
        double fps = 30.0;
        int jpegQuality = 92;
        bool imageSequence = false;  // PNG folders instead of MKV
    };
    SessionWriter(const std::filesystem::path& dir, Session meta, Options opts);
    ~SessionWriter();
    SessionWriter(const SessionWriter&) = delete;
    SessionWriter& operator=(const SessionWriter&) = delete;
    // One 8-bit BGR image per camera, in Session::cameras order.
    void append(const std::vector<cv::Mat>& images, const std::vector<double>& timestamps,
                const std::optional<Pose>& groundTruth);
    void close();  // finalises files (also done by the destructor)
    int framesWritten() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace mirage
