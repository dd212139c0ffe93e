#pragma once
// Board poses shared by the calibration tests that render whole sequences (the batch command,
// the wizard): close to the camera and spread over the image, every corner well inside it.
#include <random>
#include <vector>

#include "calibration/SyntheticViews.h"
#include "core/camera/CameraModel.h"

namespace mirage::test {

// n poses of `board` 0.3-0.5 m from `camera`, board centres over 90 % of the image, corners at
// least 12 px from the border. Deterministic for a seed.
inline std::vector<calib::BoardPose> closeBoardPoses(const CameraIntrinsics& camera,
                                                     const calib::ChessboardGeometry& board, int n,
                                                     unsigned seed) {
    std::mt19937 rng(seed);
    calib::PoseSamplerOptions po;
    po.minDistance = 0.3;
    po.maxDistance = 0.5;
    po.marginPx = 12;
    po.imageSpread = 0.9;
    return calib::sampleBoardPoses(camera, board, n, po, rng);
}

}  // namespace mirage::test
