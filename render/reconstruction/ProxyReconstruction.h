#pragma once
// The whole reconstruction (docs/reconstruction.md): check the footage, stereo depth, fusion and
// the proxies' geometry, the lights and albedo; and its report (SCENE.report.json).
#include <functional>
#include <optional>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "render/reconstruction/FootageCheck.h"
#include "render/reconstruction/LightFit.h"
#include "render/reconstruction/ProxyGeometry.h"
#include "render/reconstruction/StereoDepth.h"

namespace mirage::reconstruction {

// The footage cannot support a reconstruction; what() says why and what to record.
class FootageRefused : public Error {
public:
    using Error::Error;
};

struct ReconstructionOptions {
    FootageCheckOptions check;
    StereoOptions stereo;
    GeometryOptions geometry;
    CarvingOptions carving;  // carving.enabled = false: objects from the fused stereo alone
    LightFitOptions light;
};

struct Reconstruction {
    FootageCheck check;
    int depthMaps = 0;
    double meanValidFraction = 0;  // of the depth maps' pixels
    CarvedHeights carving;         // empty when carving is off
    FusedGeometry geometry;
    LightingEstimate lighting;
    double stereoSeconds = 0, carvingSeconds = 0, fusionSeconds = 0, lightSeconds = 0;  // wall
};

// stage: "stereo", "carving", "fusion", "lights"; done/total within it.
using ReconstructionProgress = std::function<void(const std::string& stage, int done, int total)>;

// Throws FootageRefused when checkFootage says no. `environment`: the environment camera's
// irradiance on the table (environmentIrradiance), if the session has one.
Reconstruction reconstruct(const Footage& footage, const std::optional<glm::dvec3>& environment,
                           const ReconstructionOptions& options = {},
                           const ReconstructionProgress& progress = {});

// Everything found, with sizes, residuals and confidence: the report's JSON.
nlohmann::json reconstructionReport(const Reconstruction& r);
// A few lines for the console.
std::string reconstructionSummary(const Reconstruction& r);

}  // namespace mirage::reconstruction
