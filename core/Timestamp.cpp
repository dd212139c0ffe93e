#include "core/Timestamp.h"

#include <chrono>
#include <cstdlib>
#include <ctime>

#include "core/Error.h"

namespace mirage {

std::string utcTimestamp() {
    std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    if (const char* epoch = std::getenv("SOURCE_DATE_EPOCH"); epoch && *epoch) {
        const std::string s = epoch;
        if (s.size() > 12 || s.find_first_not_of("0123456789") != std::string::npos)
            throw Error("SOURCE_DATE_EPOCH='" + s +
                        "' must be whole seconds since 1970-01-01 UTC (or unset)");
        t = std::time_t(std::stoll(s));
    }
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

}  // namespace mirage
