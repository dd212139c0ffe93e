#include "app/replay/ReplayEnvironment.h"

#include "core/Error.h"
#include "core/Log.h"

namespace mirage::app {

ReplayEnvironment::ReplayEnvironment(const Session& session, render::Renderer& renderer,
                                     float exposure, bool useCamera)
    : renderer_(renderer) {
    if (!useCamera) return;
    std::string why;
    env_ = render::SessionEnvironment::open(session, exposure, why);
    if (env_) {
        renderer_.setEnvironmentCamera(env_->setup());
        spdlog::info("replay: the environment is camera '{}' ({}), updated with each of its frames",
                     env_->cameraName(), env_->videoName());
        if (!env_->hasRadiometry())
            spdlog::warn(
                "replay: the environment camera's calibration has no radiometry_to_main: its "
                "pixels are taken to be in the main camera's units (docs/environment.md)");
    } else if (!why.empty()) {
        fallBack(why);
    }
}

void ReplayEnvironment::fallBack(const std::string& why) {
    spdlog::warn(
        "replay: environment camera: {}; the replay continues with the scene's static "
        "environment",
        why);
    renderer_.useStaticEnvironment();
    env_.reset();
    state_ = "static";
}

void ReplayEnvironment::update(const FrameRecord& rec) {
    if (!env_) return;
    cv::Mat frame;
    double t = 0;
    std::string problem;
    switch (env_->next(rec, frame, t, problem)) {
        case render::SessionEnvironment::Status::Frame:
            try {
                renderer_.updateEnvironment(frame, t);
                state_ = "camera";
            } catch (const Error& e) {
                fallBack(e.what());
            }
            break;
        case render::SessionEnvironment::Status::Lost:
            spdlog::warn("replay: {}; the last environment frame is kept", problem);
            state_ = "camera (held)";
            break;
        case render::SessionEnvironment::Status::None:
            state_ = "camera (held)";
            break;
        case render::SessionEnvironment::Status::Ended:
            fallBack(problem);
            break;
    }
}

}  // namespace mirage::app
