// The pass knobs (render/PassKnob.h): every knob a pass folder registers reads back what it sets,
// leaves every other knob alone, validates, and refuses a value outside what it takes with an
// Error that names it; the bench and the governor see the same knobs.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "core/Error.h"
#include "render/PassKnob.h"
#include "render/evaluation/RealtimeBench.h"
#include "render/governor/GovernedKnobs.h"

namespace mirage::render {
namespace {

std::vector<std::string> readAll(const RendererOptions& o) {
    std::vector<std::string> v;
    for (const PassKnob& k : passKnobs()) v.push_back(k.read(o));
    return v;
}

std::string applyError(const PassKnob& k, const std::string& value) {
    RendererOptions o;
    try {
        k.apply(o, value);
    } catch (const Error& e) {
        return e.what();
    }
    return {};
}

TEST(PassKnob, EveryKnobRoundTripsOnTheDefaults) {
    ASSERT_GE(passKnobs().size(), 40u);
    const RendererOptions defaults;
    const std::vector<std::string> before = readAll(defaults);
    for (const PassKnob& k : passKnobs()) {
        RendererOptions o;
        k.apply(o, k.read(defaults));
        EXPECT_EQ(readAll(o), before) << k.name << ": apply(read()) changed a knob";
        EXPECT_NO_THROW(o.validate()) << k.name;
    }
}

TEST(PassKnob, EverySweptValueReadsBackAndValidates) {
    for (const PassKnob& k : passKnobs())
        for (bool quick : {false, true}) {
            const std::vector<std::string> values = k.sweep(quick);
            ASSERT_FALSE(values.empty()) << k.name;
            for (const std::string& v : values) {
                RendererOptions o;
                k.apply(o, v);
                EXPECT_EQ(k.read(o), v) << k.name;
                EXPECT_NO_THROW(o.validate()) << k.name << "=" << v;
            }
        }
}

TEST(PassKnob, ABadValueIsAnErrorNamingTheKnob) {
    for (const PassKnob& k : passKnobs()) {
        const std::string e = applyError(k, "bogus");
        EXPECT_NE(e.find("knob '" + k.name + "'"), std::string::npos) << k.name << ": " << e;
    }
    // Out of range: the error names the knob and the range it takes.
    const std::string refresh = applyError(*findPassKnob("caustic_refresh"), "9");
    EXPECT_NE(refresh.find("knob 'caustic_refresh': '9' is not an integer in [1, 8]"),
              std::string::npos)
        << refresh;
    const std::string quad = applyError(*findPassKnob("caustic_quad"), "0.2");
    EXPECT_NE(quad.find("knob 'caustic_quad': '0.2' is not a number in [0.25, 8]"),
              std::string::npos)
        << quad;
    const std::string cone = applyError(*findPassKnob("fuzzy_cone"), "0");
    EXPECT_NE(cone.find("in (0, 60]"), std::string::npos) << cone;
    const std::string stride = applyError(*findPassKnob("specular_vpl_stride"), "8");
    EXPECT_NE(stride.find("is not 1, 4 or 16"), std::string::npos) << stride;
    EXPECT_EQ(applyError(*findPassKnob("caustic_refresh"), "8"), "");
    EXPECT_NE(applyError(*findPassKnob("caustic_map"), "100").find("multiple of 8"),
              std::string::npos);
}

TEST(PassKnob, NamesAreUniqueAndTheBenchAndGovernorUseTheRegistry) {
    std::set<std::string> names;
    for (const PassKnob& k : passKnobs()) {
        EXPECT_TRUE(names.insert(k.name).second) << k.name;
        EXPECT_FALSE(k.help.empty()) << k.name;
        const bool inBench = std::any_of(benchKnobs().begin(), benchKnobs().end(),
                                         [&](const BenchKnob& b) { return b.name == k.name; });
        EXPECT_TRUE(inBench) << k.name << " is not a bench knob";
        EXPECT_EQ(isGovernedKnob(k.name), k.governed) << k.name;
    }
    EXPECT_EQ(findPassKnob("warp"), nullptr);
    // In the frame's order of their passes (render/PassList.cpp).
    const std::vector<std::string> governed{
        "impostor_steps",      "caustic_gather_cap",        "caustic_refresh",
        "specular_resolution", "specular_trace_resolution", "specular_vpl_stride",
        "refraction_steps",    "specular_refresh",          "second_exit"};
    EXPECT_EQ(governedKnobNames(), governed);
}

TEST(PassKnob, CopyGovernedOptionsCopiesTheGovernedKnobsAlone) {
    RendererOptions from;
    applyQualitySetting({{"caustic_refresh", "3"}, {"specular_vpl_stride", "4"}}, from);
    from.caustic.mapSize = 512;  // not governed: stays
    RendererOptions to;
    copyGovernedOptions(from, to);
    EXPECT_EQ(to.caustic.refreshInterval, 3);
    EXPECT_EQ(to.specular.vplStride, 4);
    EXPECT_EQ(to.caustic.mapSize, RendererOptions{}.caustic.mapSize);
    // A bad value is refused with the knob's own error.
    RendererOptions o;
    try {
        applyQualitySetting({{"impostor_steps", "33"}}, o);
        ADD_FAILURE() << "impostor_steps=33 accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("knob 'impostor_steps'"), std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace mirage::render
