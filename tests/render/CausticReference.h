#pragma once
// The Embree reference of a caustic test scene, rendered with caustics on (the differential pair)
// and L_rv again with caustics off: the caustic tests judge the real-time caustic against their
// difference.
#include <cstdint>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "core/image/ImageIO.h"
#include "render/raytrace/DifferentialRendering.h"
#include "render/raytrace/EmbreeDevice.h"
#include "testscenes/CausticTestScenes.h"

namespace mirage::test {

struct CausticReferenceRender {
    raytrace::DifferentialImages on;  // caustics on: L_r (the footage) and L_rv
    cv::Mat footage;                  // 8-bit sRGB BGR: L_r as footage
    cv::Mat compositeSrgb;            // 8-bit sRGB BGR: the reference composite
    cv::Mat caustic;                  // linear RGB: L_rv(caustics on) - L_rv(caustics off), >= 0
};

inline CausticReferenceRender renderCausticReference(const CausticScene& s, int spp,
                                                     uint64_t seed) {
    const raytrace::EmbreeDevice device("threads=2");
    raytrace::RenderSettings st;
    st.samplesPerPixel = spp;
    st.threads = 2;
    st.seed = seed;
    st.caustics = true;
    CausticReferenceRender r;
    r.on = raytrace::renderDifferential(s.scene, device, {s.cam, s.pose}, st);
    EXPECT_EQ(r.on.realStats.nonFiniteSamples + r.on.mixedStats.nonFiniteSamples, 0);
    st.caustics = false;
    const raytrace::RayTracingScene mixed(s.scene, raytrace::SceneSubset::All, device);
    const raytrace::RenderResult off = raytrace::render(mixed, {s.cam, s.pose}, st);
    r.footage = linearRgbToSrgbBgr8(r.on.realOnly);
    r.compositeSrgb =
        linearRgbToSrgbBgr8(raytrace::compositeDifferential(srgbBgr8ToLinearRgb(r.footage), r.on));
    r.caustic = cv::max(r.on.realAndVirtual - off.radiance, 0.0);
    return r;
}

}  // namespace mirage::test
