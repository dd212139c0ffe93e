#include "app/replay/ReplayOutputs.h"

#include "core/Error.h"
#include "core/image/ImageIO.h"

namespace mirage::app {

namespace fs = std::filesystem;

ReplayOutputs::ReplayOutputs(const fs::path& out, bool mkv, const fs::path& csvPath,
                             const OutputRule& rule)
    : out_(out), csvPath_(csvPath), mkv_(mkv) {
    if (mkv_) videoOut_.emplace(out_, OutputOrigin::Named, rule);
    csvOut_.emplace(csvPath_, OutputOrigin::Derived, rule);
}

void ReplayOutputs::open(double fps, int jpegQuality, const std::vector<std::string>& passes) {
    passes_ = passes;
    if (mkv_) video_ = std::make_unique<MatroskaWriter>(videoOut_->temp(), fps, jpegQuality);
    csv_.open(csvOut_->temp());
    if (!csv_) throw FileError(csvPath_.string(), "cannot create the timing CSV");
    csv_ << "frame,t,state,reason,decode_ms,tracking_ms";
    for (const std::string& p : passes_) csv_ << "," << p << "_ms";
    csv_ << ",gpu_ms,readback_ms,encode_ms,frame_ms,tx,ty,tz,qw,qx,qy,qz,exposure_r,exposure_g,"
            "exposure_b,exposure_source,environment\n";
}

bool ReplayOutputs::writeImage(int index, const cv::Mat& image, double t) {
    if (image.empty()) return false;  // a lost frame has no image: only its CSV row is written
    if (video_)
        video_->append(image, t);
    else
        writeBgr8(out_ / cv::format("frame_%06d.png", index), image);
    ++images_;
    return true;
}

void ReplayOutputs::writeRow(int index, double t, const CompositedFrame& cf,
                             const ReplayFrameTimes& times, const std::string& environment) {
    const PoseRow& pr = cf.pose;
    std::string reason = pr.reason;  // keep the CSV's columns: no commas or newlines inside
    for (char& ch : reason)
        if (ch == ',' || ch == '\n') ch = ';';
    csv_ << index << "," << t << "," << pr.state << "," << reason << "," << times.decodeMs << ","
         << cf.trackingMs;
    for (const std::string& p : passes_) {
        auto it = cf.passMs.find(p);
        csv_ << "," << (it == cf.passMs.end() ? 0.0 : it->second);
    }
    csv_ << "," << cf.gpuMs << "," << cf.readbackMs << "," << times.encodeMs << ","
         << times.frameMs;
    if (pr.pose) {
        const Pose& p = *pr.pose;
        csv_ << "," << p.translation.x << "," << p.translation.y << "," << p.translation.z << ","
             << p.rotation.w << "," << p.rotation.x << "," << p.rotation.y << "," << p.rotation.z;
    } else {
        csv_ << ",,,,,,,";
    }
    if (cf.exposureSource.empty())
        csv_ << ",,,,";
    else
        csv_ << "," << cf.exposureGain.r << "," << cf.exposureGain.g << "," << cf.exposureGain.b
             << "," << cf.exposureSource;
    csv_ << "," << environment << "\n";
    csv_.flush();
    ++rows_;
}

void ReplayOutputs::finish() {
    if (finished_) return;
    finished_ = true;
    if (video_) video_->close();
    closeChecked(csv_, csvPath_);
    if (videoOut_) videoOut_->commit();
    csvOut_->commit();
}

}  // namespace mirage::app
