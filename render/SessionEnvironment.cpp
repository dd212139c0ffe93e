#include "render/SessionEnvironment.h"

#include <fmt/format.h>

#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/Radiometry.h"
#include "core/session/FrameInventory.h"

namespace mirage::render {

SessionEnvironment::SessionEnvironment(SessionEnvironment&&) noexcept = default;
SessionEnvironment& SessionEnvironment::operator=(SessionEnvironment&&) noexcept = default;
SessionEnvironment::~SessionEnvironment() = default;

std::optional<SessionEnvironment> SessionEnvironment::open(const Session& session,
                                                           float mainExposure,
                                                           std::string& whyNot) {
    whyNot.clear();
    const SessionCamera* cam = nullptr;
    for (const SessionCamera& c : session.cameras)
        if (c.role == "environment") {
            cam = &c;
            break;
        }
    if (!cam) return std::nullopt;
    SessionEnvironment e;
    e.name_ = cam->name;
    e.video_ = cam->video;
    e.cameraIndex_ = session.cameraIndex(cam->name);
    try {
        if (cam->calibration.empty())
            throw FileError((session.dir / "session.json").string(),
                            "camera '" + cam->name +
                                "' names no calibration file; calibrate the environment camera "
                                "and name its YAML in session.json");
        const std::filesystem::path file = session.path(cam->calibration);
        const CameraCalibration cal = loadCalibration(file);
        e.setup_ = EnvironmentCameraSetup::fromCalibration(cal, file);
        const std::optional<glm::dvec3> radiometry = loadRadiometryToMain(file);
        e.hasRadiometry_ = radiometry.has_value();
        const glm::dvec3 ratio = radiometry.value_or(glm::dvec3(1.0));
        e.setup_.gain = glm::vec3(ratio / double(mainExposure));

        const FrameInventory inv = inventoryFrames(session.path(cam->video));
        e.rows_ = session;
        e.rows_.frames.clear();
        for (const FrameRecord& r : session.frames)
            if (inv.has(r.index)) {
                e.rows_.frames.push_back(r);
                e.lastIndex_ = r.index;
            }
        e.frames_ = openCameraFrames(e.rows_, cam->name);
        // The first frame tells whether the calibration belongs to this video.
        cv::Mat first;
        if (!e.rows_.frames.empty() && e.frames_->read(first) && !first.empty()) {
            const CameraIntrinsics& K = e.setup_.intrinsics;
            if (first.cols != K.width || first.rows != K.height)
                throw FileError(file.string(),
                                fmt::format("is a calibration for {}x{}, but {} holds {}x{} "
                                            "frames; use the calibration of this camera",
                                            K.width, K.height, cam->video, first.cols, first.rows));
        }
        e.frames_ = openCameraFrames(e.rows_, cam->name);  // from the start again
    } catch (const Error& err) {
        whyNot = err.what();
        return std::nullopt;
    }
    return e;
}

SessionEnvironment::Status SessionEnvironment::next(const FrameRecord& row, cv::Mat& frame,
                                                    double& time, std::string& problem) {
    problem.clear();
    if (row.index > lastIndex_) {
        problem = lastIndex_ < 0 ? fmt::format("{} holds no frame", video_)
                                 : fmt::format(
                                       "{} ends at frame {}, before frame {} of the main "
                                       "camera",
                                       video_, lastIndex_, row.index);
        return Status::Ended;
    }
    // Environment frames before this row (rows the caller skipped) are passed over.
    while (next_ < rows_.frames.size() && rows_.frames[next_].index < row.index) {
        cv::Mat skipped;
        frames_->read(skipped);
        ++next_;
    }
    if (next_ >= rows_.frames.size() || rows_.frames[next_].index != row.index) return Status::None;
    ++next_;
    if (!frames_->read(frame)) {
        problem = fmt::format("{} could not be read at frame {}", video_, row.index);
        lastIndex_ = row.index - 1;
        return Status::Ended;
    }
    if (frame.empty()) {
        problem = frames_->lastProblem();
        if (problem.empty()) problem = fmt::format("{} frame {} not decodable", video_, row.index);
        return Status::Lost;
    }
    // The row's time on the environment camera's clock (frame / fps where the session has none).
    time = frames_->lastTimestamp().value_or(row.timestamps.at(size_t(cameraIndex_)));
    return Status::Frame;
}

}  // namespace mirage::render
