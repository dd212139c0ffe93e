#pragma once
// The timing of the pipelined live loop (docs/live.md, "How it runs"), from what the last
// frames took: when the tracking worker should start on the next frame so that it is tracked
// just when the GL thread is ready for it (tracking finished earlier would wait in the slot and
// add to the latency; later would leave the GL thread waiting), and when a frame taken now will
// be displayed (the time its pose is predicted to). Medians of the last kWindow frames, so one
// slow frame (a rebuild, a shader compile) does not move them. All times steady-clock seconds.
#include <deque>

namespace mirage::app {

class PipelineSchedule {
public:
    static constexpr int kWindow = 9;

    // A frame's pose decision took `seconds` (the worker's step).
    void addTracking(double seconds);
    // A frame taken by the GL thread was ready for the next `seconds` later (render, composite,
    // output, window: the GL thread's work per frame).
    void addBusy(double seconds);
    // A frame was displayed (written or uploaded) `seconds` after the GL thread took it.
    void addDisplayDelay(double seconds);

    // For the frame after the one taken at `takenAt`: when the worker should start tracking
    // it, the GL thread's expected readiness less the expected tracking time and a lead
    // (kLeadFraction of it plus kLeadSeconds) that absorbs their spread. `takenAt` itself
    // before anything was measured.
    double nextTrackingStart(double takenAt) const;
    // When the frame taken at `takenAt` is expected to be displayed; `takenAt` before any
    // display was measured.
    double expectedDisplay(double takenAt) const;

    double trackingSeconds() const { return median(tracking_); }
    double busySeconds() const { return median(busy_); }
    double displayDelaySeconds() const { return median(display_); }

    static constexpr double kLeadFraction = 0.25;
    static constexpr double kLeadSeconds = 0.005;

private:
    static void add(std::deque<double>& window, double seconds);
    static double median(const std::deque<double>& window);  // 0 when empty

    std::deque<double> tracking_, busy_, display_;
};

}  // namespace mirage::app
