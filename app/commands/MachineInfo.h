#pragma once
// What a speed figure must be quoted with (docs/bench.md): the time it was taken, the machine's
// load and its CPU. Shared by `mirage bench` and its results page.
#include <ctime>
#include <fstream>
#include <string>

#include <fmt/format.h>

namespace mirage::app {

// /proc/loadavg's 1, 5 and 15 minute averages ("unknown" where there is none).
inline std::string loadAverage() {
    std::ifstream in("/proc/loadavg");
    double a = 0, b = 0, c = 0;
    if (!(in >> a >> b >> c)) return "unknown";
    return fmt::format("{:.2f} {:.2f} {:.2f}", a, b, c);
}

// "2026-12-02 01:12 UTC".
inline std::string utcNow() {
    std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
    return buf;
}

// The CPU's model name from /proc/cpuinfo ("unknown" where there is none).
inline std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) {
            const size_t colon = line.find(':');
            if (colon == std::string::npos) break;
            std::string v = line.substr(colon + 1);
            v.erase(0, v.find_first_not_of(" \t"));
            return v;
        }
    return "unknown";
}

}  // namespace mirage::app
