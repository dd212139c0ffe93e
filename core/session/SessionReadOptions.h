#pragma once
// Reading a session with options (core/session/Session.h reads with the defaults).
#include "core/session/Session.h"

namespace mirage {

struct SessionReadOptions {
    // Keep the rows whose main-camera image exists even where an environment camera (role
    // "environment") has none, e.g. its video ends early: for readers that can do without the
    // environment (replay falls back to the scene's static one). Default: rows need every camera.
    bool environmentOptional = false;
};

Session readSession(const std::filesystem::path& dir, SessionReadReport* report,
                    const SessionReadOptions& options);

}  // namespace mirage
