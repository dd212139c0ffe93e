// Bad input at the command line never gives a confident wrong answer: outputs that would destroy
// an input are refused before any work, numbers are range-checked, argument errors exit 1, and
// an interrupted command leaves consistent outputs and exits non-zero.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <random>
#include <thread>

#include "core/session/AtomicFile.h"
#include "core/session/MatroskaScanner.h"
#include "tests/support/TestSupport.h"

extern char** environ;

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

fs::path sample() {
    return dataDir() / "sessions" / "sample";
}
std::string scene() {
    return (dataDir() / "scenes" / "tabletop" / "tabletop.gltf").string();
}

// A writable copy of the sample session (the sample itself must never be an output).
fs::path copySample(const std::string& name) {
    const fs::path dir = outputDir(name) / "session";
    fs::create_directories(dir);
    for (const auto& e : fs::directory_iterator(sample()))
        fs::copy_file(e.path(), dir / e.path().filename());
    return dir;
}

bool has(const CommandResult& r, const std::string& text) {
    return r.output.find(text) != std::string::npos;
}

TEST(BadInput, ReplayRefusesToWriteOverItsVideo) {
    const fs::path s = copySample("bad_replay_over_input");
    const auto size = fs::file_size(s / "main.mkv");
    auto r = runMirage({"replay", s.string(), "--scene", scene(), "-o", (s / "main.mkv").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "is the input")) << r.output;
    EXPECT_EQ(fs::file_size(s / "main.mkv"), size);
    // Through a symbolic link, and with the CSV beside it landing on frames.csv.
    fs::create_symlink(s / "main.mkv", s.parent_path() / "link.mkv");
    r = runMirage(
        {"replay", s.string(), "--scene", scene(), "-o", (s.parent_path() / "link.mkv").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_EQ(fs::file_size(s / "main.mkv"), size);
    const std::string truth = readFileBytes(s / "frames.csv");
    r = runMirage({"replay", s.string(), "--scene", scene(), "-o", (s / "frames.mkv").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "frames.csv")) << r.output;
    EXPECT_EQ(readFileBytes(s / "frames.csv"), truth);
    // The session folder as the PNG output folder.
    r = runMirage({"replay", s.string(), "--scene", scene(), "-o", s.string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_EQ(readFileBytes(s / "frames.csv"), truth);
}

TEST(BadInput, TrackRefusesToWriteOverTheGroundTruth) {
    const fs::path s = copySample("bad_track_over_truth");
    const std::string truth = readFileBytes(s / "frames.csv");
    auto r = runMirage({"track", s.string(), "-o", (s / "frames.csv").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "is the input")) << r.output;
    EXPECT_EQ(readFileBytes(s / "frames.csv"), truth);
    r = runMirage({"track", s.string(), "-o", (s / "board.json").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
}

TEST(BadInput, UnnamedExistingFileNeedsForce) {
    const fs::path s = copySample("bad_replay_derived");
    const fs::path out = s.parent_path() / "out.mkv";
    std::ofstream(s.parent_path() / "out.csv") << "someone's notes\n";
    auto r =
        runMirage({"replay", s.string(), "--scene", scene(), "-o", out.string(), "--frames", "1"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "--force")) << r.output;
    EXPECT_EQ(readFileBytes(s.parent_path() / "out.csv"), "someone's notes\n");
    EXPECT_FALSE(fs::exists(out));
}

TEST(BadInput, ReplayRefusesAnUnknownOutputKind) {
    const fs::path dir = outputDir("bad_replay_mp4");
    auto r = runMirage(
        {"replay", sample().string(), "--scene", scene(), "-o", (dir / "out.mp4").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, ".mkv")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.mp4"));
}

TEST(BadInput, ArgumentErrorsExitOne) {
    EXPECT_EQ(runMirage({"track"}).exitCode, 1);                      // required option missing
    EXPECT_EQ(runMirage({"track", "--no-such-option"}).exitCode, 1);  // unknown option
    EXPECT_EQ(runMirage({"replay", "/nonexistent", "--scene", scene(), "-o", "x.mkv"}).exitCode, 1);
    EXPECT_EQ(runMirage({"replay", "--help"}).exitCode, 0);
    // --log-level is accepted after the subcommand too.
    auto r = runMirage({"info", "--log-level", "warn"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
}

TEST(BadInput, ReplayHelpStatesThePosesDefault) {
    auto r = runMirage({"replay", "--help"});
    EXPECT_TRUE(has(r, "live tracking")) << r.output;
}

TEST(BadInput, NumbersAreRangeChecked) {
    const fs::path dir = outputDir("bad_numbers");
    const std::string out = (dir / "x.png").string();
    const std::vector<std::vector<std::string>> cases = {
        {"render", scene(), "--camera", "c", "-o", out, "--exposure", "nan"},
        {"render", scene(), "--camera", "c", "-o", out, "--exposure", "-1"},
        {"render", scene(), "--camera", "c", "-o", out, "--max-depth", "-3"},
        {"render", scene(), "--camera", "c", "-o", out, "--width", "2000000000"},
        {"replay", sample().string(), "--scene", scene(), "-o", (dir / "r.mkv").string(),
         "--exposure", "nan"},
        {"replay", sample().string(), "--scene", scene(), "-o", (dir / "r.mkv").string(), "--start",
         "-1"},
        {"synth", scene(), "-o", (dir / "s").string(), "--noise", "nan"},
        {"synth", scene(), "-o", (dir / "s").string(), "--vignette", "5"},
        {"synth", scene(), "-o", (dir / "s").string(), "--fps", "1e9"},
        {"synth", scene(), "-o", (dir / "s").string(), "--exposure", "inf"},
        {"bench", sample().string(), "-o", (dir / "b").string(), "--start", "-1"},
    };
    for (const auto& args : cases) {
        const auto r = runMirage(args);
        std::string line;
        for (const auto& a : args) line += a + " ";
        EXPECT_EQ(r.exitCode, 1) << line << "\n" << r.output;
        EXPECT_TRUE(has(r, "[") || has(r, "(")) << "the message gives the range: " << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "s"));
}

TEST(BadInput, PosesCsvWithNanOrZeroQuaternionIsRejected) {
    const fs::path dir = outputDir("bad_poses_csv");
    const std::string header = "frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz\n";
    std::ofstream(dir / "nan.csv") << header << "0,0,ok,,0.1,0.2,nan,1,0,0,0\n";
    std::ofstream(dir / "zero.csv") << header << "0,0,ok,,0.1,0.2,0.3,0,0,0,0\n";
    for (const char* name : {"nan.csv", "zero.csv"}) {
        const auto r =
            runMirage({"replay", sample().string(), "--scene", scene(), "-o",
                       (dir / "out.mkv").string(), "--poses", (dir / name).string(), "--force"});
        EXPECT_EQ(r.exitCode, 1) << name << ": " << r.output;
        EXPECT_TRUE(has(r, "line 2")) << r.output;
    }
}

TEST(BadInput, PosesCsvOutOfRangeUnmatchedRepeatedOrUnknownStateIsRejected) {
    // Each was accepted: a camera 1e300 m away, poses of another session's frames, two rows for
    // one frame (the last silently won), a state no tracker writes.
    const fs::path dir = outputDir("bad_poses_csv_values");
    const std::string header = "frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz\n";
    const std::string ok0 = "0,0,ok,,0.1,0.2,0.3,1,0,0,0\n";
    struct Case {
        const char* name;
        std::string rows, mustSay;
    };
    const std::vector<Case> cases = {
        {"far.csv", ok0 + "1,0.1,ok,,1e300,0.2,0.3,1,0,0,0\n", "line 3, field tx: 1e300"},
        {"unmatched.csv", ok0 + "500,0.1,ok,,0.1,0.2,0.3,1,0,0,0\n",
         "line 3, field frame: frame 500 is not a frame of the session"},
        {"repeated.csv", ok0 + ok0, "line 3, field frame: frame 0 again (first on line 2)"},
        {"banana.csv", "0,0,banana,,0.1,0.2,0.3,1,0,0,0\n", "line 2, field state: 'banana'"},
        {"okwithout.csv", "0,0,ok,,,,,,,,\n", "line 2, field tx: state ok without a pose"},
    };
    for (const Case& c : cases) {
        std::ofstream(dir / c.name) << header << c.rows;
        const auto r =
            runMirage({"replay", sample().string(), "--scene", scene(), "-o",
                       (dir / "out.mkv").string(), "--poses", (dir / c.name).string(), "--force"});
        EXPECT_EQ(r.exitCode, 1) << c.name << ": " << r.output;
        EXPECT_TRUE(has(r, c.name)) << r.output;
        EXPECT_TRUE(has(r, c.mustSay)) << c.name << ": " << r.output;
    }
}

TEST(BadInput, UnreliableCalibrationIsUsedWithAWarning) {
    const fs::path s = copySample("bad_unreliable_calibration");
    std::string yaml = readFileBytes(s / "main.yaml");
    yaml.replace(yaml.find("reliable: 1"), 11, "reliable: 0\nunreliable_reason: \"too few views\"");
    std::ofstream(s / "main.yaml", std::ios::trunc) << yaml;
    const auto r = runMirage({"track", s.string(), "-o", (s.parent_path() / "poses.csv").string()});
    EXPECT_TRUE(has(r,
                    "main.yaml: the calibration is marked unreliable (reliable: 0): too few "
                    "views"))
        << r.output;
}

TEST(BadInput, RenderChecksInputsAndOutputFolderBeforeRendering) {
    const fs::path dir = outputDir("bad_render_early");
    const std::string showcase = (testDataDir() / "scenes/good/showcase.gltf").string();
    const auto t0 = std::chrono::steady_clock::now();
    auto r = runMirage({"render", showcase, "--camera", "MainCamera", "-o",
                        (dir / "x.png").string(), "--mode", "composite", "--camera-image",
                        (dir / "nope.png").string(), "--spp", "100000"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "nope.png")) << r.output;
    EXPECT_FALSE(has(r, "rendering")) << "failed only after rendering: " << r.output;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 20.0);
    // A missing output folder is created, as by every other command.
    r = runMirage({"render", showcase, "--camera", "MainCamera", "-o",
                   (dir / "new" / "x.png").string(), "--width", "16", "--height", "12", "--spp",
                   "1"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir / "new" / "x.png"));
    // An output folder that cannot be made fails before rendering.
    std::ofstream(dir / "afile") << "";
    r = runMirage({"render", showcase, "--camera", "MainCamera", "-o",
                   (dir / "afile" / "x.png").string(), "--spp", "100000"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_FALSE(has(r, "rendering")) << r.output;
}

TEST(BadInput, AnImageGivenAsSceneSaysWhatItIs) {
    const fs::path dir = outputDir("bad_png_scene");
    const std::string png = (testDataDir() / "scenes/good/mr.png").string();
    auto r = runMirage({"render", png, "--camera", "MainCamera", "-o", (dir / "x.png").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "not a glTF scene (it is a PNG image)")) << r.output;
    EXPECT_FALSE(has(r, "nesting")) << r.output;
    r = runMirage({"replay", sample().string(), "--scene", png, "-o", (dir / "r.mkv").string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "PNG image")) << r.output;
}

TEST(BadInput, TrackPrintsTheSessionReadersWarnings) {
    const fs::path s = copySample("bad_track_warnings");
    fs::remove(s / "frames.csv");
    const auto r = runMirage({"track", s.string(), "-o", (s.parent_path() / "poses.csv").string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(has(r, "frames.csv")) << "the missing frames.csv is not mentioned: " << r.output;
}

// The summary's count of ok poses (-1: no summary).
int okFrames(const CommandResult& r) {
    const std::string key = "states: ok ";
    const size_t at = r.output.find(key);
    if (at == std::string::npos) return -1;
    return std::stoi(r.output.substr(at + key.size()));
}

// The summary's count of ok poses off the ground truth (> 2 degrees or > 2 % of the distance);
// 0 when no frame is ok (the summary then has no ground-truth lines), -1 when it is missing.
int wrongButOk(const CommandResult& r) {
    if (okFrames(r) == 0) return 0;
    const std::string key = "wrong-but-ok frames (> 2 deg or > 2 %): ";
    const size_t at = r.output.find(key);
    if (at == std::string::npos) return -1;
    return std::stoi(r.output.substr(at + key.size()));
}

TEST(BadInput, DamagedSampleGivesNoWrongOkPose) {
    // The sample session with 200 XOR-ed bytes (three seeds) and with 4 KiB of random bytes in
    // the middle of main.mkv. FFmpeg's decoder concealed the damage and tracking reported
    // confident wrong poses; now damaged frames are lost with their reason. The sample's video
    // carries a CRC-32 per cluster, which would find every damaged frame; without it (as from
    // other recorders) only the JPEG checks can, and a few frames damaged only in coefficient
    // value bits are delivered and tracked.
    const std::string original =
        withoutMatroskaClusterChecksums(readFileBytes(sample() / "main.mkv"));
    for (int trial = 0; trial < 4; ++trial) {
        const fs::path s = copySample("bad_damaged_sample_" + std::to_string(trial));
        std::string bytes = original;
        std::mt19937 rng(uint32_t(trial + 1));
        if (trial < 3) {
            for (int k = 0; k < 200; ++k) bytes[rng() % bytes.size()] ^= char(1 + rng() % 255);
        } else {
            for (size_t i = bytes.size() / 2; i < bytes.size() / 2 + 4096; ++i)
                bytes[i] = char(rng());
        }
        std::ofstream(s / "main.mkv", std::ios::binary | std::ios::trunc) << bytes;
        const auto r =
            runMirage({"track", s.string(), "-o", (s.parent_path() / "poses.csv").string()});
        // Frames were lost: 2 when some were tracked, 1 when none was (never 0).
        EXPECT_EQ(r.exitCode, okFrames(r) > 0 ? 2 : 1) << r.output;
        EXPECT_EQ(wrongButOk(r), 0) << "trial " << trial << "\n" << r.output;
        if (trial == 3) {
            EXPECT_GE(okFrames(r), 30) << r.output;
        }
        EXPECT_EQ(r.output.find("(0 unreadable"), std::string::npos) << r.output;
    }
}

// The sample session with its main video as AVI (the same JPEGs; AVI has no checksum).
fs::path copySampleAsAvi(const std::string& name, const std::string& aviBytes) {
    const fs::path s = copySample(name);
    fs::remove(s / "main.mkv");
    std::ofstream(s / "main.avi", std::ios::binary) << aviBytes;
    std::string json = readFileBytes(s / "session.json");
    json.replace(json.find("\"main.mkv\""), 10, "\"main.avi\"");
    std::ofstream(s / "session.json", std::ios::trunc) << json;
    return s;
}

TEST(BadInput, DamagedAviSampleGivesNoWrongOkPose) {
    // FFmpeg decoded damaged MJPEG in AVI with concealment (or the previous frame's picture) and
    // tracking reported poses up to 32.6 deg / 17 cm off as ok. Now every AVI frame is read by
    // mirage's own chunk reader and strict JPEG decoder: damaged frames are lost with a reason.
    const std::string avi = mjpegAviBytes(matroskaJpegs(sample() / "main.mkv"), 640, 480, 12.0);
    const fs::path clean = copySampleAsAvi("bad_avi_clean", avi);
    auto r = runMirage({"track", clean.string(), "-o", (clean.parent_path() / "p.csv").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(okFrames(r), 36) << r.output;
    int lostTotal = 0;
    for (int trial = 0; trial < 8; ++trial) {
        std::string bytes = avi;
        std::mt19937 rng(uint32_t(trial + 1));
        const int flips = trial < 3 ? 200 : 6;  // heavy damage; then a few frames among intact
        for (int k = 0; k < flips; ++k) bytes[rng() % bytes.size()] ^= char(1 + rng() % 255);
        const fs::path s = copySampleAsAvi("bad_avi_damaged_" + std::to_string(trial), bytes);
        r = runMirage({"track", s.string(), "-o", (s.parent_path() / "poses.csv").string()});
        EXPECT_EQ(wrongButOk(r), 0) << "trial " << trial << "\n" << r.output;
        const int ok = okFrames(r);
        EXPECT_GE(ok, 0) << r.output;
        lostTotal += 36 - ok;
        if (ok < 36) {
            EXPECT_NE(r.exitCode, 0) << r.output;
        }
    }
    EXPECT_GT(lostTotal, 0);
}

TEST(BadInput, TrackWithNothingOrPartDoneExitsNonZeroWithTheReason) {
    auto track = [&](const fs::path& s) {
        return runMirage({"track", s.string(), "-o", (s.parent_path() / "poses.csv").string()});
    };
    // Every frame lost: the middle of every JPEG overwritten.
    {
        const fs::path s = copySample("bad_track_all_lost");
        std::string bytes = readFileBytes(s / "main.mkv");
        for (const MatroskaBlock& b : scanMatroska(s / "main.mkv").blocks)
            for (uint64_t i = b.offset + b.size / 2; i < b.offset + b.size / 2 + 64; ++i)
                bytes[size_t(i)] = char(0x5A);
        std::ofstream(s / "main.mkv", std::ios::binary | std::ios::trunc) << bytes;
        const auto r = track(s);
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_TRUE(has(r, "nothing tracked (0 of 36 frames tracked")) << r.output;
    }
    // A header-only frames.csv.
    {
        const fs::path s = copySample("bad_track_header_only");
        const std::string csv = readFileBytes(s / "frames.csv");
        std::ofstream(s / "frames.csv", std::ios::trunc) << csv.substr(0, csv.find('\n') + 1);
        const auto r = track(s);
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_TRUE(has(r, "no frame to track")) << r.output;
        EXPECT_FALSE(fs::exists(s.parent_path() / "poses.csv"));
    }
    // The environment video removed: the main camera is still tracked; the session is incomplete.
    {
        const fs::path s = copySample("bad_track_no_env");
        fs::remove(s / "env.mkv");
        const auto r = track(s);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_EQ(okFrames(r), 36) << r.output;
        EXPECT_TRUE(has(r, "env.mkv is missing")) << r.output;
    }
    // A truncated main video: what is there is tracked, the counts say how much.
    {
        const fs::path s = copySample("bad_track_truncated");
        const std::string bytes = readFileBytes(s / "main.mkv");
        std::ofstream(s / "main.mkv", std::ios::binary | std::ios::trunc)
            << bytes.substr(0, bytes.size() / 2);
        const auto r = track(s);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_TRUE(has(r, " of 36 frames tracked")) << r.output;
    }
    // A calibration for another image size: refused before anything is written.
    {
        const fs::path s = copySample("bad_track_calib_size");
        std::string yaml = readFileBytes(s / "main.yaml");
        yaml.replace(yaml.find("image_width: 640"), 16, "image_width: 800");
        std::ofstream(s / "main.yaml", std::ios::trunc) << yaml;
        const auto r = track(s);
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_TRUE(has(r, "main.yaml")) << r.output;
        EXPECT_TRUE(has(r, "800x480 images, but the frames are 640x480")) << r.output;
        EXPECT_FALSE(fs::exists(s.parent_path() / "poses.csv"));
    }
}

TEST(BadInput, GroundTruthBeyondRangeIsSkippedNeverPrintedAsNan) {
    // A ground-truth pose of 1e300 m made the summary print "inf m (-nan %)".
    const fs::path s = copySample("bad_gt_range");
    std::string csv = readFileBytes(s / "frames.csv");
    const size_t row3 = csv.find("\n3,") + 1;
    const size_t gtStart = csv.find(',', csv.find(',', csv.find(',', row3) + 1) + 1) + 1;
    csv.replace(gtStart, csv.find(',', gtStart) - gtStart, "1e300");
    std::ofstream(s / "frames.csv", std::ios::trunc) << csv;
    const auto r = runMirage({"track", s.string(), "-o", (s.parent_path() / "poses.csv").string()});
    EXPECT_TRUE(has(r, "gt_tx 1e300 m is beyond")) << r.output;
    EXPECT_FALSE(has(r, "nan")) << r.output;
    EXPECT_FALSE(has(r, "inf m")) << r.output;
    EXPECT_NE(wrongButOk(r), -1) << r.output;
}

// Starts `mirage args...` and returns its pid.
pid_t spawnMirage(const std::vector<std::string>& args, const fs::path& log) {
    std::vector<std::string> all = {MIRAGE_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = -1;
    EXPECT_EQ(posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&fa);
    return pid;
}

int countLines(const fs::path& p) {
    std::ifstream in(p);
    int n = 0;
    for (std::string l; std::getline(in, l);) ++n;
    return n;
}

TEST(BadInput, InterruptedTrackLeavesAConsistentCsvAndExitsNonZero) {
    for (int sig : {SIGINT, SIGTERM}) {
        const fs::path dir = outputDir("bad_track_signal_" + std::to_string(sig));
        const fs::path out = dir / "poses.csv";
        std::ofstream(out) << "previous\n";
        const pid_t pid =
            spawnMirage({"track", sample().string(), "-o", out.string()}, dir / "log.txt");
        // Wait until some frames are tracked (the temporary file grows), then interrupt.
        fs::path temp;
        for (int k = 0; k < 600 && temp.empty(); ++k) {
            for (const auto& e : fs::directory_iterator(dir))
                if (e.path().filename().string().find(".partial-") != std::string::npos &&
                    countLines(e.path()) > 3)
                    temp = e.path();
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        ASSERT_FALSE(temp.empty()) << "track never started writing";
        ::kill(pid, sig);
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly";
        EXPECT_EQ(WEXITSTATUS(status), 128 + sig) << readFileBytes(dir / "log.txt");
        // The CSV holds the header and whole rows of the frames done before the signal; the
        // temporary file is gone.
        const int lines = countLines(out);
        EXPECT_GE(lines, 4) << readFileBytes(out);
        EXPECT_LT(lines, 49);
        std::ifstream in(out);
        std::string line;
        std::getline(in, line);
        EXPECT_EQ(line.rfind("frame,t,state", 0), 0u);
        EXPECT_FALSE(fs::exists(temp));
    }
}

TEST(BadInput, InterruptedReplayKeepsAPlayableVideoAndExitsNonZero) {
    const fs::path dir = outputDir("bad_replay_signal");
    const fs::path out = dir / "out.mkv";
    const pid_t pid = spawnMirage({"replay", sample().string(), "--scene", scene(), "-o",
                                   out.string(), "--ground-truth", "--vpls", "16"},
                                  dir / "log.txt");
    fs::path temp;
    for (int k = 0; k < 3000 && temp.empty(); ++k) {
        for (const auto& e : fs::directory_iterator(dir))
            if (e.path().extension() == ".csv" &&
                e.path().filename().string().find(".partial-") != std::string::npos &&
                countLines(e.path()) > 2)
                temp = e.path();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_FALSE(temp.empty()) << "replay never wrote a frame: " << readFileBytes(dir / "log.txt");
    ::kill(pid, SIGTERM);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << readFileBytes(dir / "log.txt");
    const MatroskaScan scan = scanMatroska(out);
    EXPECT_FALSE(scan.truncated);
    EXPECT_GE(scan.completeFrames, 2);
    EXPECT_EQ(countLines(dir / "out.csv"), scan.completeFrames + 1);
    EXPECT_FALSE(fs::exists(temp));
}

TEST(BadInput, StoppedSynthLeavesNoHalfSessionInTheWay) {
    const fs::path dir = outputDir("bad_synth_stopped");
    const fs::path out = dir / "session";
    const std::vector<std::string> args = {"synth",    scene(),    "-o", out.string(), "--width",
                                           "64",       "--height", "48", "--spp",      "1",
                                           "--no-env", "--fps",    "4"};
    auto longRun = args;
    longRun.insert(longRun.end(), {"--seconds", "3600"});  // never done before the signal
    const pid_t pid = spawnMirage(longRun, dir / "log.txt");
    // Wait until frames are being written (into a temporary folder beside OUT), then stop it.
    bool writing = false;
    for (int k = 0; k < 3000 && !writing; ++k) {
        for (const auto& e : fs::directory_iterator(dir))
            if (e.path().filename().string().find("session.partial-") == 0 &&
                fs::exists(e.path() / "frames.csv") && countLines(e.path() / "frames.csv") > 2)
                writing = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_TRUE(writing) << readFileBytes(dir / "log.txt");
    ::kill(pid, SIGTERM);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    EXPECT_FALSE(fs::exists(out)) << "a half-written session was left at the output";
    // The rerun is not blocked.
    auto shortRun = args;
    shortRun.insert(shortRun.end(), {"--seconds", "1"});
    const auto r = runMirage(shortRun);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(fs::exists(out / "session.json"));
}

}  // namespace
}  // namespace mirage::test
