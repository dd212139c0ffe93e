#include "core/Log.h"

#include "core/Error.h"

namespace mirage {
void setLogLevel(const std::string& level) {
    auto lvl = spdlog::level::from_str(level);
    if (lvl == spdlog::level::off && level != "off")
        throw Error("unknown log level '" + level + "' (use trace, debug, info, warn, error, off)");
    spdlog::set_level(lvl);
}
}  // namespace mirage
