#include "app/live/PipelineSchedule.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mirage::app {

void PipelineSchedule::add(std::deque<double>& window, double seconds) {
    if (!std::isfinite(seconds) || seconds < 0) return;
    window.push_back(seconds);
    while (window.size() > size_t(kWindow)) window.pop_front();
}

double PipelineSchedule::median(const std::deque<double>& window) {
    if (window.empty()) return 0.0;
    std::vector<double> v(window.begin(), window.end());
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

void PipelineSchedule::addTracking(double seconds) {
    add(tracking_, seconds);
}
void PipelineSchedule::addBusy(double seconds) {
    add(busy_, seconds);
}
void PipelineSchedule::addDisplayDelay(double seconds) {
    add(display_, seconds);
}

double PipelineSchedule::nextTrackingStart(double takenAt) const {
    if (busy_.empty()) return takenAt;
    const double track = median(tracking_);
    const double lead = track * (1.0 + kLeadFraction) + kLeadSeconds;
    return takenAt + std::max(0.0, median(busy_) - lead);
}

double PipelineSchedule::expectedDisplay(double takenAt) const {
    return takenAt + median(display_);
}

}  // namespace mirage::app
