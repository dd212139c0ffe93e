#pragma once
// How far the pose a frame was shown with is from where the camera was when the frame was
// shown (docs/live.md, "Pose prediction"): measurable when a recorded session with ground-truth
// poses stands in for the camera, whose frame i is released i-th at a known time. Each shown
// frame is judged at its display time, against the ground truth interpolated there, twice: as
// shown (predicted to the display time) and as tracked (what the loop would show without
// prediction). The live report states both side by side from one run.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage::app {

class DisplayPoseError {
public:
    // `groundTruth[i]`: T_world_camera of the stand-in's frame i (nullopt where unknown);
    // `releaseSeconds[i]`: when the stand-in releases frame i, relative to frame 0 (seconds).
    // A looped stand-in's frame counter k is frame k mod the frame count. `camera`: the main
    // camera, for the image offset of points around the world origin.
    DisplayPoseError(std::vector<std::optional<Pose>> groundTruth,
                     std::vector<double> releaseSeconds, CameraIntrinsics camera);

    struct Sample {
        // Mean image offset of four points 10 cm around the world origin on its XZ plane (the
        // board's, where the objects stand), pixels.
        double shownPx = 0, trackedPx = 0;
        double shownMm = 0, trackedMm = 0;  // distance of the camera centre, millimetres
    };
    // Frame `sequence` (the camera's counter), captured at `captureSeconds` and displayed at
    // `displaySeconds` (steady clock), shown with `shown` and tracked as `tracked`
    // (T_world_camera). nullopt (and not counted) where the ground truth at the display time is
    // unknown: past the stand-in's last frame (a looped one starts again), a frame without
    // ground truth, or a point behind a camera.
    std::optional<Sample> add(int64_t sequence, double captureSeconds, double displaySeconds,
                              const Pose& shown, const Pose& tracked);

    int frames() const { return int(samples_.size()); }
    // Medians over the frames added: "shown X px (Y mm), without prediction Z px (W mm), N
    // frames"; empty without frames.
    std::string summary() const;
    const std::vector<Sample>& samples() const { return samples_; }

    // The ground truth at `seconds` after frame 0's release (interpolated between the two
    // frames around it with a constant velocity between them); nullopt outside.
    std::optional<Pose> groundTruthAt(double seconds) const;

private:
    std::vector<std::optional<Pose>> truth_;
    std::vector<double> release_;
    CameraIntrinsics camera_;
    std::vector<Sample> samples_;
};

}  // namespace mirage::app
