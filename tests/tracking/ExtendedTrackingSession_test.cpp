// Extended tracking end to end: sessions rendered by the reference renderer (`mirage synth`) of
// the textured room scene (data/scenes/room/) and of the flat tabletop, with a final pan that
// takes the board out of view, tracked by `mirage track` (docs/tracking.md, "Extended tracking").
// The sessions are small (320x240, 4 samples per pixel) and rendered once: a later run reuses a
// session made with the same arguments.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "tests/support/TestSupport.h"

namespace mirage::tracking {
namespace {

std::vector<std::string> synthArgs(const std::string& scene, const std::filesystem::path& out) {
    return {"synth",     std::string(MIRAGE_DATA_DIR) + "/scenes/" + scene,
            "-o",        out.string(),
            "--width",   "320",
            "--height",  "240",
            "--fps",     "10",
            "--seconds", "4",
            "--spp",     "4",
            "--pan-deg", "100",
            "--seed",    "3",
            "--no-env",  "--image-sequence",
            "--force"};
}

// The session made by `mirage synth args`, rendered unless the folder holds one made with the
// same arguments.
std::filesystem::path renderedSession(const std::string& scene, const std::string& name) {
    // Not test::outputDir (which empties the folder): the session is kept for the next run.
    const auto dir = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / ("extended_" + name);
    std::filesystem::create_directories(dir);
    const auto session = dir / "session";
    const auto args = synthArgs(scene, session);
    std::string stamp;
    for (const auto& a : args) stamp += a + "\n";
    const auto stampFile = dir / "synth_args.txt";
    std::ifstream in(stampFile);
    std::stringstream had;
    had << in.rdbuf();
    if (had.str() != stamp || !std::filesystem::exists(session / "session.json")) {
        const auto r = test::runMirage(args);
        EXPECT_EQ(r.exitCode, 0) << r.output;
        std::ofstream(stampFile) << stamp;
    }
    return session;
}

struct Tracked {
    int frames = 0, ok = 0, featuresOnlyOk = 0, wrongOk = -1;
    double medianRotDeg = -1, medianPosPercent = -1;
    std::string output;
};

Tracked track(const std::filesystem::path& session, const std::vector<std::string>& extra) {
    const auto csv = session.parent_path() / (extra.empty() ? "poses.csv" : "poses_extra.csv");
    std::vector<std::string> args = {"track", session.string(), "-o", csv.string(), "--force"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = test::runMirage(args);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    Tracked t;
    t.output = r.output;
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
        ++t.frames;
        const bool ok = line.find(",ok,") != std::string::npos;
        t.ok += ok;
        t.featuresOnlyOk += ok && line.find(",features only,") != std::string::npos;
    }
    std::smatch m;
    if (std::regex_search(r.output, m,
                          std::regex("wrong-but-ok frames \\(> 2 deg or > 2 %\\): (\\d+)")))
        t.wrongOk = std::stoi(m[1]);
    if (std::regex_search(r.output, m,
                          std::regex("raw: rotation error median ([0-9.]+) deg.*?translation error "
                                     "median [0-9.]+ m \\(([0-9.]+) % of distance\\)"))) {
        t.medianRotDeg = std::stod(m[1]);
        t.medianPosPercent = std::stod(m[2]);
    }
    return t;
}

TEST(ExtendedTrackingSession, TexturedRoomPanPastTheBoardIsNeverWrong) {
    const auto session = renderedSession("room/room.gltf", "room");
    const Tracked boardOnly = track(session, {"--board-only"});
    const Tracked t = track(session, {});
    EXPECT_EQ(t.frames, 40);
    EXPECT_EQ(boardOnly.featuresOnlyOk, 0);
    // Features never cost a frame the board gives, and never give a wrong ok pose. (Measured at
    // 320x240: the board's small tags leave most frames uncertain, 14 ok; the goal of 95 % ok
    // through the pan is not reached: docs/tracking.md, "Extended tracking".)
    EXPECT_GE(t.ok, boardOnly.ok) << t.output;
    EXPECT_EQ(t.wrongOk, 0) << t.output;
    EXPECT_EQ(boardOnly.wrongOk, 0) << boardOnly.output;
}

TEST(ExtendedTrackingSession, FlatTabletopPanIsLostNotWrong) {
    const auto session = renderedSession("tabletop/tabletop.gltf", "tabletop");
    const Tracked t = track(session, {});
    EXPECT_EQ(t.frames, 40);
    EXPECT_EQ(t.wrongOk, 0) << t.output;
}

}  // namespace
}  // namespace mirage::tracking
