#include "app/FrameCompositor.h"

#include <chrono>

#include <opencv2/core/utility.hpp>

#include "core/gl/Objects.h"

namespace mirage::app {
namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
}  // namespace

FrameCompositor::FrameCompositor(render::Renderer& renderer, tracking::Tracker* tracker)
    : renderer_(renderer), tracker_(tracker) {}

CompositedFrame FrameCompositor::process(const cv::Mat& bgr, double t, const std::string& problem,
                                         std::optional<PoseRow> given, bool renderVirtual) {
    CompositedFrame out;
    PoseRow& pr = out.pose;
    const auto t1 = Clock::now();
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
        out.trackingMode = tracking::trackingModeName(tf.mode);
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
    out.trackingMs = msSince(t1);
    if (pr.pose && renderVirtual) {
        const render::FrameReport& rep =
            renderer_.render({*pr.pose, bgr, /*resetHistory=*/lastLost_});
        for (const auto& p : rep.passes) out.passMs[p.name] = p.gpuMs;
        out.gpuMs = rep.totalGpuMs;
        out.report = &rep;
        const auto t2 = Clock::now();
        out.image = renderer_.compositeSrgb();
        out.readbackMs = msSince(t2);
    } else {
        out.image = bgr;  // tracking lost (or virtual objects hidden): the footage passes through
    }
    // History is reset after every frame that was not rendered, so that a live session and the
    // replay of its recording (which sees exactly the rendered frames) agree.
    lastLost_ = !(pr.pose && renderVirtual);
    return out;
}

void FrameCompositor::blitToWindow(int width, int height) const {
    gl::Framebuffer source("composite window blit");
    source.attachColor(0, renderer_.compositeTexture());
    glBlitNamedFramebuffer(source.id(), 0, 0, 0, width, height, 0, height, width, 0,
                           GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

}  // namespace mirage::app
