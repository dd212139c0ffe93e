#include "app/FrameCompositor.h"

#include <chrono>

#include "core/gl/Objects.h"

namespace mirage::app {
namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
}  // namespace

FrameCompositor::FrameCompositor(render::Renderer& renderer) : renderer_(renderer) {}

CompositedFrame FrameCompositor::composite(const cv::Mat& bgr, PoseRow pose, bool renderVirtual,
                                           double time) {
    CompositedFrame out;
    out.pose = std::move(pose);
    const PoseRow& pr = out.pose;
    if (pr.pose && renderVirtual && !bgr.empty()) {
        const render::FrameReport& rep =
            renderer_.render({*pr.pose, bgr, /*resetHistory=*/lastLost_, time});
        for (const auto& p : rep.passes) out.passMs[p.name] = p.gpuMs;
        out.gpuMs = rep.totalGpuMs;
        out.report = &rep;
        out.exposureGain = renderer_.exposure().gain;
        out.exposureSource = render::exposureSourceName(renderer_.exposure().source);
        const auto t2 = Clock::now();
        out.image = renderer_.compositeCameraCoded();
        out.readbackMs = msSince(t2);
    } else {
        out.image = bgr;  // tracking lost (or virtual objects hidden): the footage passes through
    }
    // History is reset after every frame that was not rendered, so that a live session and the
    // replay of its recording (which sees exactly the rendered frames) agree.
    lastLost_ = !(out.report != nullptr);
    return out;
}

void FrameCompositor::blitToWindow(int width, int height) const {
    gl::Framebuffer source("composite window blit");
    source.attachColor(0, renderer_.compositeTexture());
    glBlitNamedFramebuffer(source.id(), 0, 0, 0, width, height, 0, height, width, 0,
                           GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

}  // namespace mirage::app
