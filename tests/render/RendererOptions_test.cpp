// RendererOptions::validate: every option out of its range is refused with its name, before the
// renderer allocates anything.
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "render/FrameContext.h"

namespace mirage::render {
namespace {

std::string refusal(const RendererOptions& o) {
    try {
        o.validate();
    } catch (const Error& e) {
        return e.what();
    }
    return "accepted";
}

TEST(RendererOptions, DefaultsAreValid) {
    EXPECT_EQ(refusal(RendererOptions{}), "accepted");
}

TEST(RendererOptions, ShadowBiasIsMetresInZeroToOne) {
    RendererOptions o;
    EXPECT_FLOAT_EQ(o.shadow.bias, 0.001f);  // 1 mm: what the shaders used before it was metres
    for (float bad : {-0.001f, 1.5f, std::numeric_limits<float>::quiet_NaN(),
                      std::numeric_limits<float>::infinity()}) {
        o.shadow.bias = bad;
        EXPECT_NE(refusal(o).find("shadow.bias must be in [0, 1] metres"), std::string::npos)
            << bad;
    }
    o.shadow.bias = 0.0f;
    EXPECT_EQ(refusal(o), "accepted");
}

TEST(RendererOptions, OtherRangesNameTheOption) {
    RendererOptions o;
    o.vpl.count = -1;
    EXPECT_NE(refusal(o).find("vpl.count"), std::string::npos);
    for (int bad : {-1, 5}) {
        o = {};
        o.indirect.scale = bad;
        EXPECT_NE(refusal(o).find("indirect.scale"), std::string::npos) << bad;
    }
    o = {};
    o.specular.backProjectionEpsilon = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(refusal(o).find("specular.backProjectionEpsilon"), std::string::npos);
    for (float bad : {0.0f, 0.6f, std::numeric_limits<float>::quiet_NaN()}) {
        o = {};
        o.caustic.gatherRadius = bad;
        EXPECT_NE(refusal(o).find("caustic.gatherRadius"), std::string::npos) << bad;
    }
    for (int bad : {-1, (1 << 20) + 1}) {
        o = {};
        o.caustic.gatherCap = bad;
        EXPECT_NE(refusal(o).find("caustic.gatherCap"), std::string::npos) << bad;
    }
}

// The automatic gather scale keeps a gather pixel every ~1/160 of the canvas width: the indirect
// light's detail relative to the image does not depend on the resolution. An explicit scale wins.
TEST(RendererOptions, AutomaticGatherScaleFollowsTheCanvasWidth) {
    RendererOptions o;
    ASSERT_EQ(o.indirect.scale, 0);
    EXPECT_EQ(o.indirect.gatherScale(160), 1);
    EXPECT_EQ(o.indirect.gatherScale(100), 1);  // never below 1
    EXPECT_EQ(o.indirect.gatherScale(320), 2);
    EXPECT_EQ(o.indirect.gatherScale(480), 3);
    EXPECT_EQ(o.indirect.gatherScale(640), 4);
    EXPECT_EQ(o.indirect.gatherScale(1920), 4);  // at most 4
    o.indirect.scale = 2;
    EXPECT_EQ(o.indirect.gatherScale(640), 2);
    EXPECT_EQ(o.indirect.gatherScale(160), 2);
}

}  // namespace
}  // namespace mirage::render

namespace mirage::render {
namespace {

// An options struct as a pass folder would declare it (render/PassOptionSet.h).
struct ProbeOptions {
    int taps = 4;
    void validate() const { checkOption(taps >= 1 && taps <= 8, "probe.taps", "1..8", taps); }
};

// A pass's options in the per-pass set: defaults until set, copied with RendererOptions (two
// renderers never share them), and validated with the rest; the must-fail: a bad value set.
TEST(RendererOptions, PassOptionSetHoldsEachPassOwnOptions) {
    RendererOptions a;
    EXPECT_EQ(std::as_const(a).passes.get<ProbeOptions>().taps, 4);
    a.passes.get<ProbeOptions>().taps = 6;
    RendererOptions b = a;
    b.passes.get<ProbeOptions>().taps = 2;
    EXPECT_EQ(std::as_const(a).passes.get<ProbeOptions>().taps, 6);
    EXPECT_EQ(std::as_const(b).passes.get<ProbeOptions>().taps, 2);
    EXPECT_NO_THROW(a.validate());
    a.passes.get<ProbeOptions>().taps = 9;
    try {
        a.validate();
        ADD_FAILURE() << "taps 9 was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("probe.taps"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mirage::render
