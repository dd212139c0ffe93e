#pragma once
// The reference renderer: unidirectional path tracing with next-event estimation and multiple
// importance sampling, plus probabilistic progressive photon mapping (Knaus & Zwicker 2011) for
// the light that reaches a non-specular surface through one or more perfectly specular (delta)
// bounces from a punctual light — the caustic paths L S+ D ... E that path tracing can never
// sample. Every path is counted by exactly one of the two (docs/reference-renderer.md).
//
// Output: linear RGB radiance (W / (m^2 sr) per channel, the scene's light units), CV_32FC3, with
// the image's top row first. Deterministic for a seed: every pixel sample draws from an Rng
// seeded by (seed, pixel, pass) and every photon from (seed, pass, photon index), whatever the
// thread count.
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "render/raytrace/RayTracingScene.h"

namespace mirage::raytrace {

// A camera for the reference renderer: intrinsics in OpenCV conventions (pinhole or fish-eye,
// with distortion) and T_world_camera with OpenCV camera axes (+X right, +Y down, +Z forward).
struct RenderCamera {
    CameraIntrinsics intrinsics;
    Pose T_world_camera;
};

// The camera of glTF node `nodeName` as an undistorted pinhole of width x height pixels: square
// pixels, vertical field of view = the node's yfov, principal point at the image centre
// ((w-1)/2, (h-1)/2 in OpenCV pixel-centre coordinates). Throws mirage::Error naming the camera
// nodes there are when no camera node has that name.
RenderCamera cameraFromNode(const Scene& scene, const std::string& nodeName, int width, int height);

// Light transport inside translucent objects' media: every order of scattering, or only the
// light scattered once (plus what passes unscattered), the regime the voxel number map models.
enum class MediumScattering { Single, Multiple };

struct RenderSettings {
    int samplesPerPixel = 16;  // passes; each pass = 1 camera path per pixel + 1 photon pass
    double maxSeconds = 0.0;  // > 0: stop after the pass that crosses this time (spp = upper bound)
    uint64_t seed = 1;
    int threads = 0;    // 0 = std::thread::hardware_concurrency()
    int maxDepth = 64;  // path vertices; Russian roulette ends most paths much earlier
    // Photon mapping (caustics). 0 = automatic: photons = max(20000, pixels / 2) per pass;
    // initial radius = 0.1 x the mean bounding radius of the specular objects.
    int photonsPerPass = 0;
    float initialPhotonRadius = 0.0f;  // metres
    float radiusAlpha = 2.0f / 3.0f;   // Knaus-Zwicker radius reduction (0..1)
    bool caustics = true;              // false: photon map off (the path tracer alone)
    MediumScattering mediumScattering = MediumScattering::Multiple;
    // Image rows to trace, ascending (empty: all). Other rows stay zero. A pixel's samples depend
    // on the seed, the pass and the pixel only, so a row comes out the same whichever rows are
    // traced with it: the rows of a split render (`mirage render --shard`) join bit for bit.
    std::vector<int> rows;
};

struct RenderResult {
    cv::Mat radiance;         // CV_32FC3 linear RGB
    cv::Mat virtualCoverage;  // CV_32F in [0,1]: fraction of camera rays whose first hit is VIRTUAL
    int passes = 0;
    double seconds = 0.0;
    long long photonsStored = 0;     // caustic photons deposited over all passes
    long long nonFiniteSamples = 0;  // samples dropped for NaN/Inf radiance (a bug if ever > 0)
};

// Called after each pass (from the calling thread).
using ProgressCallback =
    std::function<void(int passesDone, int passesTotal, double elapsedSeconds)>;

// Renders camera.intrinsics.width x height pixels.
RenderResult render(const RayTracingScene& scene, const RenderCamera& camera,
                    const RenderSettings& settings, const ProgressCallback& progress = {});

}  // namespace mirage::raytrace
