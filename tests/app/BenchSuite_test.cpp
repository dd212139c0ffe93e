// `mirage bench --suite` on a tiny suite (2 effects, 2 values per knob, 80x60, 2 frames): every
// plot, table and crop of the results page is written and non-empty, a renderer with the virtual
// contribution removed (the `virtual=off` knob) is flagged as not beating the footage while the
// default is not, the sessions are reused on a second run, and a bad suite file is refused with
// its field named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;
using test::runMirage;

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path writeSuite(const fs::path& dir, const std::string& body) {
    fs::create_directories(dir);
    const fs::path file = dir / "suite.json";
    std::ofstream(file) << body;
    return file;
}

std::string tinySuite() {
    const std::string scene = (test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf").string();
    // The second effect in a scene of its own (the translucent tabletop, which holds the mirror).
    const std::string translucent =
        (test::dataDir() / "scenes" / "tabletop" / "tabletop_translucent.gltf").string();
    return R"({
  "scene": ")" +
           scene + R"(",
  "width": 80, "height": 60, "fps": 2, "seconds": 1, "spp": 4, "repeats": 1,
  "effects": [
    {"name": "diffuse", "hide": ["glass_sphere", "mirror"], "environment_camera": true,
     "sweeps": {"vpls": ["16", "64"], "virtual": ["on", "off"], "env_source": ["static", "camera"]}},
    {"name": "mirror", "scene": ")" +
           translucent + R"(", "hide": ["glass_sphere", "jade_cube"],
     "sweeps": {"impostor_resolution": ["32", "64"]}}
  ],
  "scaling": {"resolutions": ["40x30", "80x60"], "vpls": ["16", "32"], "triangles": [200, 2000]},
  "tracking": {"widths": [640]}
})";
}

TEST(BenchSuite, TinySuiteWritesEveryPlotTableAndCropAndFlagsABrokenRenderer) {
    const fs::path dir = test::outputDir("bench_suite");
    fs::remove_all(dir);
    const fs::path suite = writeSuite(dir, tinySuite());
    const fs::path out = dir / "results";
    const auto r = runMirage({"bench", "--suite", out.string(), "--suite-file", suite.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;

    const std::string md = readAll(out / "results.md");
    ASSERT_FALSE(md.empty());
    EXPECT_NE(md.find("sessions/mirror-"), std::string::npos) << md;
    // The tracker against ArUco: both methods on the video and on single frames, each with
    // every frame's pose and none wrong (the synthetic views are easy: both find the board).
    for (const char* row : {"| video | mirage | 640x480 |", "| video | ArUco | 640x480 |",
                            "| single | mirage | 640x480 |", "| single | ArUco | 640x480 |"})
        EXPECT_NE(md.find(row), std::string::npos) << row;
    EXPECT_NE(md.find("| 60/60 | 0 |"), std::string::npos) << md;
    EXPECT_NE(r.output.find("tabletop_translucent.gltf"), std::string::npos) << r.output;
    for (const char* needle :
         {"## diffuse", "## mirror", "## Scaling", "machine:", "GL renderer:", "load average",
          "footage only", "passes.svg", "diffuse_time_error.svg", "mirror_time_error.svg"})
        EXPECT_NE(md.find(needle), std::string::npos) << needle;
    for (const char* svg :
         {"passes.svg", "diffuse_time_error.svg", "mirror_time_error.svg", "scaling_pixels.svg",
          "scaling_vpls.svg", "scaling_triangles.svg", "tracking_time_error.svg"}) {
        const std::string s = readAll(out / "results" / svg);
        EXPECT_GT(s.size(), 500u) << svg;
        EXPECT_NE(s.find("</svg>"), std::string::npos) << svg;
        EXPECT_EQ(s.find("nan"), std::string::npos) << svg;
    }
    for (const char* png : {"images/diffuse_default.png", "images/diffuse_cheapest.png",
                            "images/mirror_default.png", "images/mirror_cheapest.png"})
        EXPECT_GT(fs::file_size(out / "results" / png), 100u) << png;

    // The hidden-virtual point is flagged (red, and named in the tables); the default is not.
    EXPECT_NE(md.find("virtual=off (not above footage)"), std::string::npos) << md;
    EXPECT_EQ(md.find("| default (not above footage)"), std::string::npos) << md;
    const std::string diffuse = readAll(out / "results" / "diffuse_time_error.svg");
    EXPECT_NE(diffuse.find("#D00000"), std::string::npos);
    const std::string mirror = readAll(out / "results" / "mirror_time_error.svg");
    EXPECT_EQ(mirror.find("#D00000"), std::string::npos) << "no mirror setting should be broken";
    // One point per setting: diffuse has default, vpls=16, vpls=64, virtual=off and
    // env_source=camera, lit by the session's environment camera (vpls=256, virtual=on and
    // env_source=static are the default).
    size_t points = 0;
    for (size_t p = diffuse.find("class=\"point\""); p != std::string::npos;
         p = diffuse.find("class=\"point\"", p + 1))
        ++points;
    EXPECT_EQ(points, 5u);
    EXPECT_NE(md.find("| env_source=camera |"), std::string::npos) << md;

    // A second run reuses the sessions.
    const auto again =
        runMirage({"bench", "--suite", out.string(), "--suite-file", suite.string()});
    ASSERT_EQ(again.exitCode, 0) << again.output;
    EXPECT_NE(again.output.find("reusing the session"), std::string::npos) << again.output;
}

TEST(BenchSuite, BadSuiteFilesAreRefusedWithTheirField) {
    const fs::path dir = test::outputDir("bench_suite_bad");
    fs::remove_all(dir);
    const struct {
        std::string body, expect;
    } cases[] = {
        {"{\"effects\": []}", "effects"},
        {"{\"width\": 4, \"effects\": [{\"name\": \"a\"}]}", "width"},
        {"{\"effects\": [{\"name\": \"a\", \"sweeps\": {\"vpls\": \"64\"}}]}", "wrong type"},
        {"{\"effects\": [{\"name\": \"a\", \"sweeps\": {\"warp\": [\"1\"]}}]}", "unknown knob"},
        {"{\"effects\": [{\"name\": \"a\", \"hide\": [\"no_such_node\"]}]}", "no_such_node"},
        {"not json", "not valid JSON"},
        {"{\"tracking\": {\"widths\": [800]}, \"effects\": [{\"name\": \"a\"}]}",
         "tracking.widths"},
        {"{\"effects\": [{\"name\": \"a\", \"scene\": \"nope.gltf\"}]}",
         "effect 'a': its scene does not exist"},
    };
    for (const auto& c : cases) {
        const fs::path suite = writeSuite(dir, c.body);
        const auto r =
            runMirage({"bench", "--suite", (dir / "out").string(), "--suite-file", suite.string()});
        EXPECT_NE(r.exitCode, 0) << c.body;
        EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.body << "\n" << r.output;
        EXPECT_FALSE(fs::exists(dir / "out" / "results.md"));
    }
    const auto both = runMirage({"bench", "S", "--suite", (dir / "out").string()});
    EXPECT_NE(both.exitCode, 0);
    EXPECT_NE(both.output.find("no SESSION"), std::string::npos) << both.output;
}

}  // namespace
}  // namespace mirage
