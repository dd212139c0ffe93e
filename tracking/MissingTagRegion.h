#pragma once
// Where the board tags a decimated search missed should be (docs/tracking.md, "Adaptive
// detection"): the board's tags projected with a pose, those fully in view and large enough but
// not among the detections, and the image box to search again at full resolution.
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "tracking/Board.h"
#include "tracking/Detector.h"

namespace mirage::tracking {

struct MissingTagOptions {
    // A tag counts as in view when all 4 predicted corners lie at least this far inside the
    // image (pixels): libapriltag needs the tag's quiet zone, one cell beyond the corners.
    double borderPx = 4.0;
    // Tags whose predicted shortest side is below this (pixels) are not searched for: under
    // ~8 px libapriltag cannot decode a tag36h11 tag at any resolution (a cell under 1 px).
    double minSidePx = 8.0;
    // Each missing tag's predicted box is grown by this fraction of its longest side plus
    // marginPx on every side: the quiet zone, libapriltag's border search, and the prediction's
    // error (a pose settled from a few small tags may be off by a few pixels).
    double marginFraction = 0.5;
    double marginPx = 8.0;
};

struct MissingTags {
    std::vector<int> ids;  // board tags predicted in view, large enough, not detected
    cv::Rect region;       // union of their grown boxes, clipped to the image (empty: none)
    int predicted = 0;     // board tags predicted in view and large enough (found or not)
};

// T_world_camera: the pose that predicts the tags (this frame's, or the motion prediction).
MissingTags findMissingTags(const Board& board, const CameraIntrinsics& camera,
                            const Pose& T_world_camera, const std::vector<TagDetection>& found,
                            const MissingTagOptions& options = {});

}  // namespace mirage::tracking
