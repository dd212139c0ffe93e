#pragma once
// A one-line progress bar on stderr ("\r" redrawn), used by `mirage render` and `mirage synth`.
// Redraws at most every 100 ms; finish() ends the line. Silent when stderr is not a terminal
// unless forced, so logs and CI output stay readable (one final line is still printed).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace mirage::app {

class TerminalProgress {
public:
    explicit TerminalProgress(std::string label)
        : label_(std::move(label)), tty_(isatty(STDERR_FILENO) != 0) {}

    // `done` of `total` units; `detail` is appended (e.g. "3.2 s").
    void update(double done, double total, const std::string& detail = "") {
        auto now = std::chrono::steady_clock::now();
        bool last = done >= total;
        if (!tty_ || (!last && now - lastDraw_ < std::chrono::milliseconds(100))) {
            lastDone_ = done;
            lastTotal_ = total;
            lastDetail_ = detail;
            return;
        }
        lastDraw_ = now;
        draw(done, total, detail);
    }

    void finish() {
        if (!tty_) draw(lastDone_, lastTotal_, lastDetail_);
        std::fputc('\n', stderr);
        std::fflush(stderr);
    }

private:
    void draw(double done, double total, const std::string& detail) {
        constexpr int kWidth = 30;
        double f = total > 0 ? std::min(1.0, done / total) : 0.0;
        int filled = int(f * kWidth + 0.5);
        std::string bar(size_t(filled), '#');
        bar.append(size_t(kWidth - filled), '.');
        std::fprintf(stderr, "%s%s [%s] %5.1f%% %s", tty_ ? "\r" : "", label_.c_str(), bar.c_str(),
                     100.0 * f, detail.c_str());
        if (tty_) std::fputs("\033[K", stderr);  // clear the rest of the line
        std::fflush(stderr);
    }

    std::string label_;
    bool tty_;
    std::chrono::steady_clock::time_point lastDraw_{};
    double lastDone_ = 0, lastTotal_ = 0;
    std::string lastDetail_;
};

}  // namespace mirage::app
