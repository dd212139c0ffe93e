#include "app/PoseStage.h"

namespace mirage::app {

PoseStage::PoseStage(tracking::Tracker* tracker) : tracker_(tracker) {}

PoseRow PoseStage::decide(const cv::Mat& bgr, double t, const std::string& problem,
                          std::optional<PoseRow> given) {
    PoseRow pr;
    lastMode_.clear();
    if (bgr.empty()) {
        // Lost (damaged bytes): no image to composite into and no pose to trust; the row says
        // why, the output skips the frame.
        pr = {"lost", problem.empty() ? "frame not decodable" : problem, std::nullopt};
        if (tracker_) tracker_->markLost(t, pr.reason);
    } else if (given) {
        pr = std::move(*given);
    } else if (tracker_) {
        tracking::TrackedFrame tf = tracker_->process(bgr, t);
        pr.state = tracking::trackingStateName(tf.estimate.state);
        pr.reason = tf.estimate.reason;
        lastMode_ = tracking::trackingModeName(tf.mode);
        if (tf.estimate.state == tracking::TrackingState::Ok)
            pr.pose = tf.filtered ? tf.filtered : tf.estimate.pose;
    } else {
        pr = {"lost", "no pose source", std::nullopt};
    }
    if (pr.state == "uncertain") {
        pr.pose.reset();
        if (lastGood_ && t >= lastGoodT_ && t - lastGoodT_ <= kHoldUncertainS) {
            pr.pose = lastGood_;
            pr.reason += cv::format("; held the last ok pose (t = %.3f s)", lastGoodT_);
        }
    } else if (pr.pose) {
        lastGood_ = pr.pose;
        lastGoodT_ = t;
    }
    return pr;
}

void PoseStage::restart() {
    lastGood_.reset();
    lastGoodT_ = 0;
}

}  // namespace mirage::app
