#version 450 core
#include "common.glsl"
// One environment-camera frame -> the equirectangular environment map (docs/environment.md).
// Map texel (x, y) (centre at +0.5; memory row 0 = top row) is the world direction
//   phi = 2 pi x / W - pi, theta = pi / 2 - pi y / H, d = (cos theta sin phi, sin theta,
//   -cos theta cos phi)
// (the centre column looks along world -Z, the top row up +Y: tracking/EnvironmentMap's and
// GpuScene::environmentMap's convention). d is rotated into the camera frame (OpenCV axes) and
// projected with the calibrated model; where that lands inside the image within the trusted
// field (maxTheta off the optical axis) the frame is sampled bilinearly (the texture is sRGB8, so
// the sample is linear) and scaled by `gain` into scene radiance: alpha = 1.
// Unseen directions (alpha = 0) are filled by mirroring through the camera's image plane: a
// direction theta > 90 degrees off the axis takes the radiance of pi - theta at the same azimuth
// (for a camera looking up: the lower hemisphere is the mirror of the upper one), clamped to the
// largest angle inside both the trusted field and the image. Continuous at the seen border.
in vec2 uv;
layout(binding = kUnitEnvFisheye) uniform sampler2D fisheye;
uniform mat3 cameraFromWorld;  // R_camera_world = transpose of T_world_camera's rotation
uniform vec4 focal;            // fx, fy, cx, cy (pixels; (0, 0) = centre of the top-left pixel)
uniform vec4 distortion;       // Kannala-Brandt k1..k4, or Brown-Conrady k1, k2, p1, p2
uniform float distortionK3;    // Brown-Conrady k3
uniform int kannalaBrandt;     // 1: fish-eye model, 0: pinhole with Brown-Conrady distortion
uniform vec2 imageSize;        // pixels
uniform float maxTheta;        // radians off the optical axis that are trusted (reach)
uniform vec3 gain;             // linear pixel value -> scene radiance, per channel
layout(location = 0) out vec4 outEnv;

// Image position (pixels) of camera-frame direction d, if it is in the trusted field and inside
// the image (a half-pixel margin keeps bilinear taps inside).
bool projectDirection(vec3 d, out vec2 px) {
    px = vec2(-1.0);
    float r = length(d.xy);
    float theta = atan(r, d.z);
    if (!(theta <= maxTheta)) return false;
    vec2 xy;
    if (kannalaBrandt == 1) {
        float t2 = theta * theta;
        float td = theta * (1.0 + t2 * (distortion.x + t2 * (distortion.y +
                                                            t2 * (distortion.z + t2 * distortion.w))));
        xy = r > 1e-9 ? d.xy * (td / r) : vec2(0.0);
    } else {
        if (!(d.z > 1e-9)) return false;
        vec2 n = d.xy / d.z;
        float r2 = dot(n, n);
        float radial = 1.0 + r2 * (distortion.x + r2 * (distortion.y + r2 * distortionK3));
        xy = n * radial + vec2(2.0 * distortion.z * n.x * n.y + distortion.w * (r2 + 2.0 * n.x * n.x),
                               distortion.z * (r2 + 2.0 * n.y * n.y) + 2.0 * distortion.w * n.x * n.y);
    }
    px = vec2(focal.x * xy.x + focal.z, focal.y * xy.y + focal.w);
    return all(greaterThanEqual(px, vec2(0.0))) && all(lessThanEqual(px, imageSize - 1.0));
}

vec3 sampleFrame(vec2 px) {
    return texture(fisheye, (px + 0.5) / imageSize).rgb * gain;
}

void main() {
    // uv is the texel centre ((x + 0.5) / W, (y + 0.5) / H), row 0 at the top.
    float phi = 2.0 * PI * uv.x - PI;
    float lat = 0.5 * PI - PI * uv.y;
    vec3 dWorld = vec3(cos(lat) * sin(phi), sin(lat), -cos(lat) * cos(phi));
    vec3 d = cameraFromWorld * dWorld;
    vec2 px;
    if (projectDirection(d, px)) {
        outEnv = vec4(sampleFrame(px), 1.0);
        return;
    }
    // Fill: mirror through the image plane, then the largest trusted angle inside the image
    // (bisection on the angle at this azimuth).
    float r = length(d.xy);
    vec2 azimuth = r > 1e-6 ? d.xy / r : vec2(1.0, 0.0);
    float theta = atan(r, d.z);
    float target = min(theta > 0.5 * PI ? PI - theta : theta, maxTheta);
    float lo = 0.0, hi = target;
    if (projectDirection(vec3(azimuth * sin(hi), cos(hi)), px)) {
        lo = hi;
    } else {
        for (int i = 0; i < 12; ++i) {
            float mid = 0.5 * (lo + hi);
            vec2 q;
            if (projectDirection(vec3(azimuth * sin(mid), cos(mid)), q)) lo = mid;
            else hi = mid;
        }
    }
    if (!projectDirection(vec3(azimuth * sin(lo), cos(lo)), px)) px = focal.zw;
    outEnv = vec4(sampleFrame(px), 0.0);
}
