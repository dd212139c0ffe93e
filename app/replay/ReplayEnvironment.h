#pragma once
// The environment stage of `mirage replay` (docs/environment.md): a session with an environment
// camera (role "environment", e.g. env.mkv) lights the scene with it, frame by frame (the
// renderer's environment pass runs when a new environment frame arrives). An unusable
// environment camera (no calibration or extrinsics, a calibration of another size, a video that
// ends early) is reported and the replay continues with the scene's static environment.
#include <optional>
#include <string>

#include "core/session/Session.h"
#include "render/Renderer.h"
#include "render/SessionEnvironment.h"

namespace mirage::app {

class ReplayEnvironment {
public:
    // `useCamera` false (--static-env): the static environment throughout.
    ReplayEnvironment(const Session& session, render::Renderer& renderer, float exposure,
                      bool useCamera);
    // Gives the renderer the environment frame of session row `row`, if there is a new one.
    void update(const FrameRecord& row);
    // Which environment lit the last row: "static", "camera" or "camera (held)" (the CSV's
    // `environment` column).
    const std::string& state() const { return state_; }

private:
    void fallBack(const std::string& why);

    render::Renderer& renderer_;
    std::optional<render::SessionEnvironment> env_;
    std::string state_ = "static";
};

}  // namespace mirage::app
