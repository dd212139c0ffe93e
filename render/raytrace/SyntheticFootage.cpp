#include "render/raytrace/SyntheticFootage.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "core/Error.h"
#include "core/camera/CameraResponse.h"
#include "core/image/ImageIO.h"
#include "render/raytrace/Sampling.h"

namespace mirage::raytrace {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// glTF-style look-at (camera looks down its -Z) converted to OpenCV camera axes.
Pose lookAt(const glm::dvec3& eye, const glm::dvec3& target) {
    glm::dmat4 view = glm::lookAt(eye, target, glm::dvec3(0, 1, 0));
    return Pose::fromMatrix(glm::inverse(view)) * kCvFromGltfCamera;
}

// Smooth pseudo-random signal in [-1, 1]: three sines with seeded phases and incommensurate
// frequencies (0.7 - 3.1 Hz, typical of hand tremor and sway).
double shakeSignal(uint64_t seed, int channel, double t) {
    Rng rng(seed, uint64_t(channel) + 100);
    const double f[3] = {0.7, 1.9, 3.1}, a[3] = {0.6, 0.3, 0.1};
    double v = 0.0;
    for (int k = 0; k < 3; ++k)
        v += a[k] * std::sin(2.0 * M_PI * f[k] * t + 2.0 * M_PI * rng.uniform());
    return v;
}

Pose orbitPose(const CameraPathOptions& o, double az) {
    glm::dvec3 eye =
        o.target + glm::dvec3(o.radius * std::sin(az), o.height, o.radius * std::cos(az));
    return lookAt(eye, o.target);
}

}  // namespace

std::string cameraPathSegment(const CameraPathOptions& o, double t) {
    double u = o.duration > 0 ? t / o.duration : 0.0;
    if (u < o.orbitFraction) return "orbit";
    if (u < o.orbitFraction + o.shakeFraction) return "shake";
    return "pan";
}

Pose cameraPathPose(const CameraPathOptions& o, double t) {
    if (!(o.duration > 0)) throw Error("camera path: duration must be positive");
    const double tOrbit = o.orbitFraction * o.duration, tShake = o.shakeFraction * o.duration;
    const double tPan = std::max(1e-9, o.duration - tOrbit - tShake);
    t = std::clamp(t, 0.0, o.duration);
    if (t < tOrbit) {
        // Smooth start and end (cosine ease) so the orbit has no velocity jumps.
        double u = 0.5 - 0.5 * std::cos(M_PI * t / tOrbit);
        return orbitPose(o, (o.orbitStartDeg + u * (o.orbitEndDeg - o.orbitStartDeg)) * kDeg);
    }
    const Pose hold = orbitPose(o, o.orbitEndDeg * kDeg);
    // Shake keeps going through the pan (the camera is still hand-held).
    auto shaken = [&](const Pose& base, double time) {
        glm::dvec3 dt(shakeSignal(o.seed, 0, time), shakeSignal(o.seed, 1, time),
                      shakeSignal(o.seed, 2, time));
        glm::dvec3 dr(shakeSignal(o.seed, 3, time), shakeSignal(o.seed, 4, time),
                      shakeSignal(o.seed, 5, time));
        glm::dvec3 axisAngle = dr * (o.shakeRotationDeg * kDeg);
        double angle = glm::length(axisAngle);
        glm::dquat q =
            angle > 0 ? glm::angleAxis(angle, axisAngle / angle) : glm::dquat(1, 0, 0, 0);
        Pose jitter;
        jitter.rotation = q;  // in the camera frame
        Pose p = base * jitter;
        p.translation += dt * o.shakeTranslation;
        return p;
    };
    if (t < tOrbit + tShake) return shaken(hold, t - tOrbit);
    // Fast pan: yaw about world +Y through the camera position, eased.
    double u = (t - tOrbit - tShake) / tPan;
    double yaw = (0.5 - 0.5 * std::cos(M_PI * u)) * o.panDeg * kDeg;
    Pose pan = hold;
    pan.rotation = glm::angleAxis(yaw, glm::dvec3(0, 1, 0)) * hold.rotation;
    return shaken(pan, t - tOrbit);
}

CameraIntrinsics pinholeFromHorizontalFov(int width, int height, double hfovDeg) {
    if (width <= 0 || height <= 0 || !kPinholeHfovDeg.contains(hfovDeg))
        throw Error("pinhole camera: size must be positive and the horizontal field of view in " +
                    kPinholeHfovDeg.text() + " degrees");
    CameraIntrinsics k;
    k.width = width;
    k.height = height;
    k.fx = k.fy = 0.5 * width / std::tan(0.5 * hfovDeg * kDeg);
    k.cx = 0.5 * width - 0.5;
    k.cy = 0.5 * height - 0.5;
    k.model = DistortionModel::BrownConrady;
    k.distortion.assign(5, 0.0);
    return k;
}

CameraIntrinsics equidistantFisheye(int size, double fovDeg) {
    if (size <= 0 || !kFisheyeFovDeg.contains(fovDeg))
        throw Error("fish-eye camera: size must be positive and the field of view in " +
                    kFisheyeFovDeg.text() + " degrees");
    CameraIntrinsics k;
    k.width = k.height = size;
    k.fx = k.fy = 0.5 * size / (0.5 * fovDeg * kDeg);
    k.cx = k.cy = 0.5 * size - 0.5;
    k.model = DistortionModel::KannalaBrandt;
    k.distortion.assign(4, 0.0);
    k.maxFisheyeTheta = std::min(0.5 * fovDeg * kDeg, 0.5 * 3.14159265358979323846);
    return k;
}

double exposureAt(const SensorOptions& s, double t, double duration) {
    double e = s.exposure;
    if (s.exposureChange) {
        double start = 0.6 * duration, ramp = 0.25;
        double u = std::clamp((t - start) / ramp, 0.0, 1.0);
        e *= 1.0 - 0.45 * (0.5 - 0.5 * std::cos(M_PI * u));
    }
    if (t >= 0.5 * duration) e *= s.exposureStep;
    return e;
}

glm::dvec3 whiteBalanceAt(const SensorOptions& s, double t, double duration) {
    const double u = duration > 0.0 ? std::clamp(t / duration, 0.0, 1.0) : 0.0;
    return glm::dvec3(1.0) + u * (s.whiteBalanceDrift - glm::dvec3(1.0));
}

cv::Mat applySensor(const cv::Mat& linearRgb, const SensorOptions& s, double exposure,
                    uint64_t seed, const glm::dvec3& whiteBalance) {
    if (linearRgb.type() != CV_32FC3)
        throw Error("applySensor: expects linear RGB float (CV_32FC3)");
    cv::Mat img = linearRgb.clone();
    const double cx = 0.5 * (img.cols - 1), cy = 0.5 * (img.rows - 1), r2max = cx * cx + cy * cy;
    for (int y = 0; y < img.rows; ++y) {
        Rng rng(seed, uint64_t(y));
        for (int x = 0; x < img.cols; ++x) {
            double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / r2max;
            float gain = float(exposure * (1.0 - s.vignette * r2));
            auto& p = img.at<cv::Vec3f>(y, x);
            for (int k = 0; k < 3; ++k) {
                float v = std::max(0.0f, p[k] * gain * float(whiteBalance[k]));
                if (s.noise > 0) {
                    // Poisson-Gaussian sensor noise: shot noise grows with the signal, read noise
                    // does not.
                    float sigma = float(std::sqrt(s.noise * v + s.noise * s.noise));
                    // Box-Muller from two uniforms.
                    float u1 = std::max(rng.uniform(), 1e-7f), u2 = rng.uniform();
                    v += sigma * std::sqrt(-2.0f * std::log(u1)) * std::cos(2.0f * kPi * u2);
                }
                p[k] = v;
            }
        }
    }
    if (s.responseGamma > 0.0) {
        // The camera's own response: sRGB codes of the same light, re-coded with the gamma.
        const CameraResponse response = CameraResponse::gamma(s.responseGamma);
        cv::Mat bgr(img.rows, img.cols, CV_8UC3);
        for (int y = 0; y < img.rows; ++y)
            for (int x = 0; x < img.cols; ++x) {
                const cv::Vec3f& p = img.at<cv::Vec3f>(y, x);
                for (int k = 0; k < 3; ++k)
                    bgr.at<cv::Vec3b>(y, x)[2 - k] = uint8_t(
                        response.code(k, std::clamp(std::isnan(p[k]) ? 0.0f : p[k], 0.0f, 1.0f)));
            }
        return bgr;
    }
    return linearRgbToSrgbBgr8(img, 1.0f);
}

}  // namespace mirage::raytrace
