// The `mirage` command line: subcommands are listed, bad usage and bad input exit non-zero with
// a message, never a crash.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

TEST(Cli, HelpListsSubcommands) {
    auto r = runMirage({"--help"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("info"), std::string::npos) << r.output;
}

TEST(Cli, UnknownSubcommandFails) {
    auto r = runMirage({"no-such-command"});
    EXPECT_NE(r.exitCode, 0);
}

TEST(Cli, NoSubcommandFails) {
    auto r = runMirage({});
    EXPECT_NE(r.exitCode, 0);
}

TEST(Cli, InfoMakesAHeadlessContext) {
    auto r = runMirage({"info"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("OpenGL"), std::string::npos) << r.output;
}

// The frame graph of a scene: every pass with its declarations and what it did in the frame.
TEST(Cli, InfoPassesPrintsTheFrameGraph) {
    const std::string scene =
        std::string(MIRAGE_DATA_DIR) + "/scenes/tabletop/tabletop_diffuse.gltf";
    const std::string dot = (outputDir("cli_info_passes") / "graph.dot").string();
    auto r =
        runMirage({"info", "--passes", scene, "--width", "160", "--height", "120", "--dot", dot});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* s : {"gbuffer", "composite", "writes GBufferPosition", "reads  CameraImage"})
        EXPECT_NE(r.output.find(s), std::string::npos) << s << "\n" << r.output;
    std::ifstream in(dot);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_NE(text.str().find("digraph frame"), std::string::npos) << text.str();

    // Without lights nothing casts a shadow: the shadow pass and everything VPL are skipped.
    auto dark =
        runMirage({"info", "--passes", scene, "--no-lights", "--width", "160", "--height", "120"});
    ASSERT_EQ(dark.exitCode, 0) << dark.output;
    EXPECT_NE(dark.output.find("shadow     skipped no light has a shadow caster"),
              std::string::npos)
        << dark.output;
}

TEST(Cli, InfoPassesRejectsBadInput) {
    EXPECT_NE(runMirage({"info", "--passes", "/no/such/scene.gltf"}).exitCode, 0);
    EXPECT_NE(runMirage({"info", "--dot", "x.dot"}).exitCode, 0);
    const std::string scene =
        std::string(MIRAGE_DATA_DIR) + "/scenes/tabletop/tabletop_diffuse.gltf";
    auto r = runMirage({"info", "--passes", scene, "--camera", "no-such-camera"});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.output.find("camera"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mirage::test
