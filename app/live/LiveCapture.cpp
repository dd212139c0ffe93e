#include "app/live/LiveCapture.h"

#include <algorithm>

#include "core/Log.h"

namespace mirage::app {

LiveCapture::LiveCapture(CameraInput& camera, EnvironmentInput* env)
    : main_(std::move(camera.source), camera.pacing) {
    if (env) {
        env_.emplace(std::move(env->source), env->pacing);
        envHalfPeriodS_ = 0.5 / env->fps;
    }
}

bool LiveCapture::next(LiveFrame& frame, double timeoutSeconds) {
    frame.newEnvironment = false;
    if (!main_.next(frame.main, timeoutSeconds)) return false;
    if (env_) {
        CapturedFrame ef;
        bool haveEnv = env_->next(ef, 0.0) && !ef.bgr.empty();
        const double newest = haveEnv ? ef.captureSeconds : envLatestS_;
        if (!env_->ended() && (newest < frame.main.captureSeconds - envHalfPeriodS_ ||
                               (!haveEnv && envLatest_.empty()))) {
            CapturedFrame later;
            if (env_->next(later, std::min(envHalfPeriodS_, 0.05)) && !later.bgr.empty()) {
                ef = std::move(later);
                haveEnv = true;
            }
        }
        if (haveEnv) {
            envLatest_ = ef.bgr;
            envLatestS_ = ef.captureSeconds;
            frame.newEnvironment = true;
        } else if (!envEnded_ && env_->ended()) {
            envEnded_ = true;
            spdlog::warn(
                "live: the environment camera ended ({}); lighting stays with its last frame",
                env_->error().empty() ? "end of its stream" : env_->error());
        }
    }
    frame.envBgr = envLatest_;
    frame.envSeconds = envLatestS_;
    return true;
}

std::string LiveCapture::stop() {
    const std::string error = main_.error();
    main_.stop();
    if (env_) env_->stop();
    return error;
}

}  // namespace mirage::app
