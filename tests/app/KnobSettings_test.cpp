// `--set KNOB=VALUE` (app/KnobSettings.h): a setting reaches the renderer's options through the
// pass's knob; a malformed setting, an unknown knob and a bad value are errors that say what to
// write. The must-fail: without the setting the option keeps its default.
#include <gtest/gtest.h>

#include <string>

#include "app/KnobSettings.h"
#include "core/Error.h"

namespace mirage::app {
namespace {

std::string errorOf(const std::string& setting) {
    try {
        render::RendererOptions o;
        applyKnobSettings({setting}, o);
    } catch (const Error& e) {
        return e.what();
    }
    return {};
}

TEST(KnobSettings, ASettingReachesTheOptions) {
    render::RendererOptions o;
    const int before = o.caustic.mapSize;
    applyKnobSettings({"caustic_map=512", "view=LRv*4"}, o);
    EXPECT_EQ(o.caustic.mapSize, 512);
    EXPECT_NE(before, 512) << "must-fail: the default is not already 512";
    EXPECT_EQ(render::findPassKnob("view")->read(o), "LRv*4");
}

TEST(KnobSettings, BadSettingsSayWhatToWrite) {
    EXPECT_NE(errorOf("caustic_map").find("write KNOB=VALUE"), std::string::npos);
    EXPECT_NE(errorOf("=512").find("write KNOB=VALUE"), std::string::npos);
    const std::string unknown = errorOf("warp=9");
    EXPECT_NE(unknown.find("no knob 'warp'"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("caustic_map"), std::string::npos) << "lists the knobs: " << unknown;
    EXPECT_NE(errorOf("caustic_refresh=9").find("knob 'caustic_refresh'"), std::string::npos);
}

}  // namespace
}  // namespace mirage::app
