#pragma once
// Landmarks of natural features in the world (board) frame, with their uncertainty
// (docs/tracking.md, "Extended tracking").
//
// A landmark is kept in inverse-depth form (Civera, Davison, Montiel, IEEE T-RO 2008):
//   X = anchor + direction / rho
// anchor: the camera centre (world, metres) of the landmark's first observation; direction: unit
// world ray through the feature from there; rho: inverse depth along it (1/metres; 0 = at
// infinity). The homogeneous point h = rho (anchor - c) + direction, seen from a camera centre c,
// is what the camera projects (X_c = R_cw h up to scale), so a landmark whose depth is not known
// yet (seen only from one place, or only under a pure rotation) still predicts where it appears
// from cameras near its anchor: the depth matters only in proportion to how far the camera moved.
// Its covariance is over (two angles of the direction about the tangent axes e1, e2; rho) and
// is refined from every observation made at a known camera pose (the board's).
#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"

namespace mirage::tracking {

struct LandmarkObservation {
    Pose T_world_camera;
    glm::dvec2 pixel;
    double sigmaPx = 0;  // pixel noise of this observation (feature noise and the pose's)
};

struct Landmark {
    int id = 0;
    glm::dvec3 anchor{0.0};               // world, metres
    glm::dvec3 direction{0, 0, 1};        // unit, world
    glm::dvec3 e1{1, 0, 0}, e2{0, 1, 0};  // tangent axes of the direction's angles
    double rho = 0;                       // 1/metres
    double rhoPrior = 0, rhoPriorSigma = 0;
    // Covariance of (angle about e1, angle about e2 in radians, rho in 1/metres), row-major.
    std::array<double, 9> covariance{};
    // Standard deviation (metres) of the anchor itself: the error of the pose that created it.
    double anchorSigmaM = 0;
    // Observations at poses from the board (at most LandmarkMap::kMaxObservations, spread out).
    std::vector<LandmarkObservation> observations;
    // Reprojection RMS of the observations after the last refinement (pixels).
    double rmsPx = 0;
    // Created from a pose that came from the landmarks themselves (not from the board).
    bool derived = false;

    glm::dvec3 homogeneous(const glm::dvec3& cameraCentre) const {
        return rho * (anchor - cameraCentre) + direction;
    }
    // The point in the world; only meaningful for rho > 0.
    glm::dvec3 point() const { return anchor + direction / std::max(rho, 1e-9); }
};

class LandmarkMap {
public:
    static constexpr size_t kMaxObservations = 6;

    // New landmark from one observation at a pose with the given uncertainty: the ray through
    // `pixel`, inverse depth 1 / depthGuessM with a prior standard deviation of
    // rhoSigmaFraction x that (the depth is a guess until other views refine it).
    // Returns its id, or -1 when the pixel does not unproject.
    int add(const CameraIntrinsics& camera, const Pose& T_world_camera, const glm::dvec2& pixel,
            double pixelSigma, double rotSigmaRad, double posSigmaM, double depthGuessM,
            double rhoSigmaFraction, bool derived);
    // Adds an observation made at a board pose and refines the landmark (Gauss-Newton on its
    // three parameters over all observations and the inverse-depth prior). The observation is
    // stored only when the camera has moved (minBaselineM) or turned (minTurnRad) since the
    // nearest stored one, else it is skipped (no new information, same cost).
    void observe(int id, const CameraIntrinsics& camera, const LandmarkObservation& o,
                 double minBaselineM, double minTurnRad);
    Landmark* find(int id);
    void remove(int id);
    const std::vector<Landmark>& landmarks() const { return landmarks_; }
    void clear() { landmarks_.clear(); }

private:
    void refine(const CameraIntrinsics& camera, Landmark& l) const;
    std::vector<Landmark> landmarks_;
    int nextId_ = 0;
};

}  // namespace mirage::tracking
