#pragma once
// How close reconstructed real geometry is to the truth (docs/reconstruction.md, docs/results.md):
// both scenes' REAL meshes are sampled uniformly by area (one point per sampleSpacingM^2) and
// each sample's distance to the other scene's real surface is measured (Open3D's
// RaycastingScene, exact point-to-triangle distances).
//  - per true object (a real mesh instance standing on the plane, its top more than
//    objectMinHeightM above it): completeness = the share of its surface within `thresholdM` of
//    the rebuilt real geometry (the rebuilt table included: an object's underside lies on it),
//    and the mean / 95th percentile of those distances (mm);
//  - accuracy = the share of the rebuilt real surface more than objectMinHeightM above the plane
//    that lies within `thresholdM` of the true real geometry.
#include <string>
#include <vector>

#include "core/scene/Scene.h"
#include "render/reconstruction/Footage.h"

namespace mirage::reconstruction {

struct EvaluationOptions {
    double thresholdM = 0.01;
    double sampleSpacingM = 0.002;
    double objectMinHeightM = 0.01;
};

struct ObjectScore {
    std::string name;              // the true node's name
    double completeness = 0;       // fraction of its surface within the threshold
    double meanMm = 0, p95Mm = 0;  // true surface -> rebuilt surface distances
    int samples = 0;
};

struct GeometryScore {
    std::vector<ObjectScore> objects;
    double accuracy = 0;  // rebuilt above-plane surface within the threshold
    double accuracyMeanMm = 0, accuracyP95Mm = 0;
    int rebuiltSamples = 0;
};

GeometryScore evaluateGeometry(const Scene& truth, const Scene& rebuilt, const BoardPlane& plane,
                               const EvaluationOptions& options = {});

}  // namespace mirage::reconstruction
