#pragma once
// The Embree reference of a caustic test scene, rendered with caustics on (the differential pair)
// and L_rv again with caustics off: the caustic tests judge the real-time caustic against their
// difference.
#include <cstdint>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/image/ImageIO.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "testscenes/CausticTestScenes.h"
#include "testscenes/ReferenceFrame.h"

namespace mirage::test {

struct CausticReferenceRender {
    raytrace::DifferentialImages on;  // caustics on: L_r (the footage) and L_rv
    cv::Mat footage;                  // 8-bit sRGB BGR: L_r as footage
    cv::Mat compositeSrgb;            // 8-bit sRGB BGR: the reference composite
    cv::Mat caustic;                  // linear RGB: L_rv(caustics on) - L_rv(caustics off), >= 0
    // CV_8U: the caustic region, where the caustic (smoothed over 5x5 px against the photon
    // map's noise) adds > 5 % to L_rv and L_rv > 5 % of the brightest directly lit real surface
    // (the lit table, not the dark room). Each test narrows it to what it judges.
    cv::Mat region;
};

// Luminance (Rec. 709 weights) of a linear RGB float image, CV_32F.
inline cv::Mat linearLuminance(const cv::Mat& rgb) {
    cv::Mat y;
    cv::transform(rgb, y, cv::Matx13f(0.2126f, 0.7152f, 0.0722f));
    return y;
}

inline CausticReferenceRender renderCausticReference(const CausticScene& s, int spp,
                                                     uint64_t seed) {
    ReferenceFrame on = renderReferenceFrame(s.scene, s.cam, s.pose, spp, seed, true);
    CausticReferenceRender r;
    r.on = std::move(on.images);
    r.footage = on.footage;
    r.compositeSrgb = on.composite;
    // L_rv again without the photon map, same passes and seed.
    const raytrace::EmbreeDevice device("threads=2");
    const raytrace::RayTracingScene mixed(s.scene, raytrace::SceneSubset::All, device);
    const raytrace::RenderResult off =
        raytrace::render(mixed, {s.cam, s.pose}, referenceSettings(spp, seed, false));
    r.caustic = cv::max(r.on.realAndVirtual - off.radiance, 0.0);
    cv::Mat yc = linearLuminance(r.caustic);
    const cv::Mat yon = linearLuminance(r.on.realAndVirtual);
    cv::GaussianBlur(yc, yc, cv::Size(5, 5), 1.0);
    double peak = 0;
    cv::minMaxLoc(linearLuminance(r.on.realOnly), nullptr, &peak);
    r.region = (yc > 0.05 * yon) & (yon > 0.05 * peak);
    return r;
}

}  // namespace mirage::test
