#pragma once
// A session's environment camera as a stream of environment frames for the renderer
// (docs/environment.md): replay and bench walk the main camera's rows and ask for the environment
// frame of each. The camera is the session's camera with role "environment"; its calibration
// gives the intrinsics, the extrinsic pose (fixed in the world or mounted on the main camera) and
// the radiometric ratio to the main camera.
//
// Bad input never stops the caller: open() says why the environment cannot be used (no
// calibration, no extrinsics, a calibration of another size than the video), and next() says
// when the video has ended before the main camera's; the caller continues with the scene's static
// environment and says so.
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/session/Session.h"
#include "render/EnvironmentCamera.h"

namespace mirage::render {

class SessionEnvironment {
public:
    // The environment camera of `session` (read with SessionReadOptions::environmentOptional),
    // or nullopt with `whyNot` set when the session has none (whyNot empty) or it is unusable
    // (whyNot names the file and the problem). `mainExposure`: RendererOptions::composite.exposure
    // (scene radiance -> main camera units), so that gain = radiometry_to_main / mainExposure.
    static std::optional<SessionEnvironment> open(const Session& session, float mainExposure,
                                                  std::string& whyNot);

    const EnvironmentCameraSetup& setup() const { return setup_; }
    const std::string& cameraName() const { return name_; }
    const std::string& videoName() const { return video_; }
    // False when the calibration has no radiometry_to_main (gain = 1 / mainExposure is assumed).
    bool hasRadiometry() const { return hasRadiometry_; }

    enum class Status {
        Frame,  // `frame` and `time` hold the environment frame of the row
        None,   // the environment camera has no image for this row (a gap): keep the last one
        Lost,   // its image is damaged (`problem` says why): keep the last one
        Ended,  // its video ended before this row (`problem` says where): no more frames
    };
    // The environment frame of main-camera row `row` (rows in increasing frame order).
    Status next(const FrameRecord& row, cv::Mat& frame, double& time, std::string& problem);

    SessionEnvironment(SessionEnvironment&&) noexcept;
    SessionEnvironment& operator=(SessionEnvironment&&) noexcept;
    ~SessionEnvironment();

private:
    SessionEnvironment() = default;
    EnvironmentCameraSetup setup_;
    std::string name_, video_;
    bool hasRadiometry_ = false;
    int cameraIndex_ = -1;
    Session rows_;  // the session with only the rows the environment video holds
    size_t next_ = 0;
    int lastIndex_ = -1;  // the last frame the environment video holds
    std::unique_ptr<FrameSource> frames_;
};

}  // namespace mirage::render
