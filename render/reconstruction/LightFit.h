#pragma once
// The real lights and the diffuse albedo of the real proxies, from the footage
// (docs/reconstruction.md):
//  - the environment camera's image gives the room's irradiance on the table (E_env, per
//    channel): a cosine-weighted integral over the hemisphere above the plane;
//  - the table's observed radiance per cell is the model L(x) = a + b * S(x) per channel, where
//    S(x) = spot(angle off the axis) * cos(incidence) / r^2 is the light's geometry (position,
//    direction, inner and outer cone: the renderers' KHR_lights_punctual falloff) and a, b are
//    solved linearly for each S; the geometry is fitted by Levenberg-Marquardt (core/math) from
//    several starts above the bright pool, cells that disagree (shadows, highlights) trimmed;
//  - a = albedo * E_env / pi and b = albedo * I / pi then give the table's albedo and the light's
//    intensity I (candela, the renderers' unit); every proxy's albedo is its observed radiance
//    times pi divided by the irradiance the fitted lights give there.
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "render/reconstruction/ProxyGeometry.h"

namespace mirage::reconstruction {

struct FittedSpotLight {
    glm::dvec3 position{0.0};              // world, metres
    glm::dvec3 direction{0.0, -1.0, 0.0};  // world, unit, the way it shines
    double innerConeRad = 0.3, outerConeRad = 0.5;
    glm::dvec3 intensity{0.0};  // candela per channel (linear RGB)
    double rmsResidual = 0;     // of the table's radiance (linear camera units)
    int cellsUsed = 0, cellsTrimmed = 0;
    double contrast = 0;  // spot term / environment term at the pool's centre
};

struct LightFitOptions {
    double sampleCellM = 0.012;  // table cells the fit samples
    // Cells this close to an object's footprint are left out (contact shadows, occlusion).
    double objectMarginM = 0.03;
    // A spot is only reported when its light at the pool's centre is at least this fraction of
    // the environment's (otherwise the table is lit evenly and there is nothing to fit).
    double minContrast = 0.15;
    int maxIterations = 60;
    double maxDistanceM = 2.5;  // a fitted light farther from the board's centre is refused
    // The written proxies' material: a dielectric (F0 0.04) of this roughness, whose GGX lobe
    // reflects a share of the room's light on top of the diffuse albedo (the renderers' glTF
    // model). That share (dielectricSpecularAlbedo at viewCosine) is taken out of the observed
    // radiance before it is divided by the irradiance, so the albedo is the diffuse one.
    double surfaceRoughness = 0.8;
    // The cameras' median cosine to the table's normal (reconstruct() measures it from the
    // footage); <= 0: unknown, no specular share is taken out.
    double viewCosine = 0.0;
};

struct LightingEstimate {
    glm::dvec3 environmentIrradiance{0.0};  // on the table plane, W/m^2-like linear camera units
    bool environmentMeasured = false;       // false: no environment camera (albedo assumed)
    std::optional<FittedSpotLight> spot;
    glm::dvec3 tableAlbedo{0.5};  // median over the observed table, linear
    // The written material's specular share of the room's light taken out of every albedo
    // (LightFitOptions::surfaceRoughness, viewCosine); 0 when the view is unknown.
    double specularShare = 0;
    cv::Mat tableAlbedoTexture;            // CV_32FC3 linear RGB, rows along v
    std::vector<glm::dvec3> objectAlbedo;  // one per FusedGeometry::objects
    std::vector<std::string> notes;        // what was assumed, for the report
};

// Irradiance on a plane with normal `up` from a fish-eye environment image (8-bit BGR, sRGB),
// its intrinsics, pose (T_world_camera) and gain (linear pixel -> radiance). Directions the
// camera does not see are left out of the average (the rest is renormalised).
glm::dvec3 environmentIrradiance(const cv::Mat& bgr, const CameraIntrinsics& camera,
                                 const Pose& T_world_camera, const glm::vec3& gain,
                                 const glm::dvec3& up);

// `environment`: E_env measured by environmentIrradiance, or nullopt (then the table's albedo is
// assumed 0.5 grey and the note says so).
LightingEstimate estimateLighting(const FusedGeometry& geometry,
                                  const std::optional<glm::dvec3>& environment,
                                  const LightFitOptions& options = {});

// Directional albedo of the renderers' GGX specular lobe (Smith-Schlick G, Schlick F, F0 0.04:
// a dielectric) under uniform light: the share of a uniform room's irradiance / pi that a
// surface of this roughness reflects specularly towards a viewer at cos(angle to the normal)
// viewCosine.
double dielectricSpecularAlbedo(double viewCosine, double roughness);

// The spot's geometric term S(x) for a surface point x with normal n (metres, world).
double spotGeometry(const FittedSpotLight& light, const glm::dvec3& x, const glm::dvec3& n);

}  // namespace mirage::reconstruction
