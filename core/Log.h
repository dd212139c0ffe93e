#pragma once
// Logging goes through spdlog. Levels: trace/debug for developers, info for what a user wants to
// see, warn for degraded-but-working, error right before a non-zero exit.
#include <spdlog/spdlog.h>

namespace mirage {
// Sets the global level from a name ("trace", "debug", "info", "warn", "error", "off").
void setLogLevel(const std::string& level);
}  // namespace mirage
