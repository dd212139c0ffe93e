#pragma once
// One frame of the Embree reference (the differential render, L_r and L_rv) and what the tests
// compare the real-time renderer with: the footage (L_r as a camera frame, 8-bit sRGB BGR) and
// the reference's differential composite of that quantised footage (Eqs. 1-2), linear and sRGB.
#include <cstdint>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "core/camera/CameraModel.h"
#include "core/image/ImageIO.h"
#include "core/math/Pose.h"
#include "core/scene/Scene.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"

namespace mirage::test {

struct ReferenceFrame {
    raytrace::DifferentialImages images;
    cv::Mat footage;          // CV_8UC3 BGR, sRGB-encoded
    cv::Mat compositeLinear;  // CV_32FC3 linear RGB
    cv::Mat composite;        // CV_8UC3 BGR, sRGB-encoded
};

// The tests' reference settings: spp passes on two threads from `seed`; caustics = the photon map.
inline raytrace::RenderSettings referenceSettings(int spp, uint64_t seed, bool caustics) {
    raytrace::RenderSettings st;
    st.samplesPerPixel = spp;
    st.threads = 2;
    st.seed = seed;
    st.caustics = caustics;
    return st;
}

// The reference with referenceSettings (the photon map on by default, as in RenderSettings). A
// non-finite sample fails the calling test.
inline ReferenceFrame renderReferenceFrame(const Scene& scene, const CameraIntrinsics& cam,
                                           const Pose& T_world_camera, int spp, uint64_t seed,
                                           bool caustics = true) {
    const raytrace::EmbreeDevice device("threads=2");
    const raytrace::RenderSettings st = referenceSettings(spp, seed, caustics);
    ReferenceFrame r;
    r.images = raytrace::renderDifferential(scene, device, {cam, T_world_camera}, st);
    EXPECT_EQ(r.images.realStats.nonFiniteSamples + r.images.mixedStats.nonFiniteSamples, 0);
    r.footage = linearRgbToSrgbBgr8(r.images.realOnly);
    r.compositeLinear = raytrace::compositeDifferential(srgbBgr8ToLinearRgb(r.footage), r.images);
    r.composite = linearRgbToSrgbBgr8(r.compositeLinear);
    return r;
}

// CV_8U: the pixels the virtual objects influence, their coverage and where they change the
// real world (shadow, bounce) by more than `threshold` (linear) in some channel.
inline cv::Mat influencedPixels(const raytrace::DifferentialImages& images,
                                float threshold = 0.01f) {
    cv::Mat diff, ch[3];
    cv::absdiff(images.realAndVirtual, images.realOnly, diff);
    cv::split(diff, ch);
    return (cv::max(cv::max(ch[0], ch[1]), ch[2]) > threshold) | (images.virtualCoverage > 0.0f);
}

}  // namespace mirage::test
