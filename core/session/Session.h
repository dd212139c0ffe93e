#pragma once
// A session: recorded (or synthetic) footage in a folder, the format of docs/session.md:
//   session.json   format "mirage-session", version, cameras, frame rate, files, creation info
//   main.mkv       main camera video (MJPEG in Matroska, one cluster per frame so that every
//                  completed frame survives a crash) — or a folder of numbered PNG/JPEG images
//   env.mkv        optional fish-eye environment camera
//   <camera>.yaml  OpenCV calibration per camera (core/camera/CalibrationFile.h)
//   board.json     the tag board (tracking/ reads it; the session only names it)
//   frames.csv     frame,t_<camera>...,gt_tx,gt_ty,gt_tz,gt_qw,gt_qx,gt_qy,gt_qz (gt optional)
//
// Images are 8-bit BGR, sRGB-encoded, as cameras deliver them. Times are seconds on the
// recording's clock (a live recording: the camera driver's monotonic clock; synthetic: i / fps).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/math/Pose.h"
#include "core/session/FrameSource.h"

namespace mirage {

inline constexpr const char* kSessionFormat = "mirage-session";
inline constexpr int kSessionVersion = 1;  // the newest version this build reads and writes

struct SessionCamera {
    std::string name;         // "main", "env"
    std::string video;        // file (.mkv) or folder of images, relative to the session folder
    std::string calibration;  // OpenCV YAML, relative to the session folder; may be empty
    std::string role;         // "main" or "environment"
    // The exposure time per frame (seconds the shutter is open), when the camera or the
    // synthesiser reported it; 0 = an instantaneous shutter (no motion blur). session.json's
    // optional cameras[].shutter.
    std::optional<double> shutter = std::nullopt;
};

struct FrameRecord {
    int index = 0;  // position of the frame in every camera's video (0-based), or image number
    std::vector<double> timestamps;   // seconds, one per camera in Session::cameras order
    std::optional<Pose> groundTruth;  // T_world_camera of the main camera (OpenCV axes)
};

struct Session {
    std::filesystem::path dir;
    std::string format = kSessionFormat;
    int version = kSessionVersion;
    double fps = 30.0;
    std::vector<SessionCamera> cameras;
    std::string board = "board.json";  // relative; may be empty
    std::string scene;                 // optional: the scene the footage was synthesised from
    std::string framesFile = "frames.csv";
    std::string createdBy, createdAt;
    // After readSession: only rows whose images are readable in every camera, in file order.
    std::vector<FrameRecord> frames;

    const SessionCamera* camera(const std::string& name) const;
    int cameraIndex(const std::string& name) const;  // -1 if absent
    std::filesystem::path path(const std::string& relative) const { return dir / relative; }
};

// What reading found wrong but could live with (truncated video, unreadable rows...).
struct SessionReadReport {
    std::vector<std::string> warnings;
    int framesListed = 0;    // valid rows in frames.csv
    int framesReadable = 0;  // rows whose images exist in every camera's video
    bool ok() const { return warnings.empty(); }
};

// Reads session.json and frames.csv. Throws mirage::FileError when the folder is not a session
// at all (no or unparseable session.json, wrong format, newer version, no cameras); otherwise
// keeps what is there and lists what is missing in the report (logged as warnings instead when
// no report is asked for).
Session readSession(const std::filesystem::path& dir, SessionReadReport* report = nullptr);

// The calibration of one camera of a session (its `calibration` file). Throws FileError if the
// camera does not exist, names no calibration file, or the file is missing or invalid.
struct CameraCalibration;
CameraCalibration loadSessionCalibration(const Session& s, const std::string& camera);

// Every file and folder of a session a command reads (the folder, session.json, frames.csv,
// board, each camera's video and calibration): what an output must never overwrite.
std::vector<std::filesystem::path> sessionInputs(const Session& s);

// Writes session.json (atomically). Used by SessionWriter; exposed for tools that edit sessions.
void writeSessionJson(const Session& s);

// The frames of one camera of a session, one per row of Session::frames (in that order; video
// frames without a row are skipped), with the row's timestamp. Throws FileError if the camera
// does not exist or its video cannot be opened.
std::unique_ptr<FrameSource> openCameraFrames(const Session& s, const std::string& camera);

// Writes a session frame by frame. Crash-safe: session.json is written first (atomically),
// each frame's images are flushed before its frames.csv row, and frames.csv is flushed per row,
// so an interrupted write leaves every completed frame readable.
class SessionWriter {
public:
    struct Options {
        double fps = 30.0;
        int jpegQuality = 92;
        bool imageSequence = false;  // PNG folders instead of MKV
        // fsync video and frames.csv after every frame: survives power loss, not only a crash
        // of the process (which plain writes already survive). Costs a disk flush per frame.
        bool fsyncEachFrame = false;
    };
    // `meta` gives the cameras (default: one camera "main"), board, scene, calibration names;
    // empty video names become "<camera>.mkv" (or "<camera>/" for image sequences). Throws
    // FileError if `dir` already holds a session (never overwrites footage) or is not writable.
    SessionWriter(const std::filesystem::path& dir, Session meta, Options opts);
    ~SessionWriter();
    SessionWriter(const SessionWriter&) = delete;
    SessionWriter& operator=(const SessionWriter&) = delete;
    // One 8-bit BGR image per camera, in Session::cameras order; timestamps one per camera
    // (seconds) or empty for index / fps. groundTruth is T_world_camera of the main camera.
    void append(const std::vector<cv::Mat>& images, const std::vector<double>& timestamps,
                const std::optional<Pose>& groundTruth);
    void close();  // finalises files (also done by the destructor)
    int framesWritten() const;
    const Session& session() const;  // the metadata as written (video names filled in)

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace mirage
