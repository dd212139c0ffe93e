#include "app/live/LiveOutputs.h"

#include <cmath>

#include "app/OutputKind.h"
#include "core/Csv.h"
#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "core/session/PosesCsv.h"

namespace mirage::app {

namespace fs = std::filesystem;

LiveOutputs::LiveOutputs(const fs::path& out, const OutputRule& rule) : out_(out) {
    if (out_.empty()) return;
    mkv_ = isVideoOutput(out_, "mirage live");
    if (mkv_) {
        videoOut_.emplace(out_, OutputOrigin::Named, rule);
        csvPath_ = fs::path(out_).replace_extension(".csv");
    } else {
        checkOutput(out_, OutputOrigin::Named, rule, /*outIsFolder=*/true);
        fs::create_directories(out_);
        csvPath_ = out_ / "frames.csv";
    }
    csvOut_.emplace(csvPath_, OutputOrigin::Derived, rule);
}

void LiveOutputs::open(double fps, int jpegQuality, const std::vector<std::string>& passes) {
    if (!enabled()) return;
    passes_ = passes;
    if (mkv_) video_ = std::make_unique<MatroskaWriter>(videoOut_->temp(), fps, jpegQuality);
    csv_.open(csvOut_->temp());
    if (!csv_) throw FileError(csvPath_.string(), "cannot create the timing CSV");
    csv_ << "frame,t,state,reason,camera_frame,dropped,driver_dropped,env_age_ms,tracking_ms";
    for (const std::string& p : passes_) csv_ << "," << p << "_ms";
    csv_ << ",gpu_ms,readback_ms,frame_ms,latency_ms,handoff_ms,predict_ms,tx,ty,tz,qw,qx,qy,qz\n";
}

void LiveOutputs::writeImage(int frame, const cv::Mat& image, double t) {
    if (!enabled() || image.empty()) return;
    if (video_)
        video_->append(image, t);
    else
        writeBgr8(out_ / cv::format("frame_%06d.png", frame), image);
    ++images_;
}

void LiveOutputs::writeRow(int frame, const CapturedFrame& f, double envAgeMs,
                           const CompositedFrame& cf, double frameMs, double latencyMs,
                           const LivePipelineTimes& pipeline) {
    if (!csv_.is_open()) return;
    csv_ << frame << "," << exactDecimal(f.captureSeconds) << "," << csvField(cf.pose.state) << ","
         << csvField(cf.pose.reason) << "," << f.sequence << "," << f.droppedBefore << ","
         << f.deviceDroppedBefore << ",";
    if (std::isfinite(envAgeMs)) csv_ << envAgeMs;
    csv_ << "," << cf.trackingMs;
    for (const std::string& p : passes_) {
        auto it = cf.passMs.find(p);
        csv_ << "," << (it == cf.passMs.end() ? 0.0 : it->second);
    }
    csv_ << "," << cf.gpuMs << "," << cf.readbackMs << "," << frameMs << "," << latencyMs << ","
         << pipeline.handoffMs << ",";
    if (std::isfinite(pipeline.predictMs)) csv_ << pipeline.predictMs;
    if (cf.pose.pose) {
        const Pose& p = *cf.pose.pose;
        for (double v : {p.translation.x, p.translation.y, p.translation.z, p.rotation.w,
                         p.rotation.x, p.rotation.y, p.rotation.z})
            csv_ << "," << exactDecimal(v);
    } else {
        csv_ << ",,,,,,,";
    }
    csv_ << "\n";
    csv_.flush();
    ++rows_;
}

void LiveOutputs::finish() {
    if (!enabled()) return;
    if (video_) video_->close();
    if (csv_.is_open()) closeChecked(csv_, csvPath_);
    // A video without a frame is no video (Matroska needs its track header, written with the
    // first frame): stopped before any frame, nothing is left; the CSV only with its rows.
    if (videoOut_ && images_ > 0) videoOut_->commit();
    if (csvOut_ && rows_ > 0) csvOut_->commit();
}

}  // namespace mirage::app
