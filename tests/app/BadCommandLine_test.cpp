// Bad command lines and interrupted runs, one test per problem found by trying mirage as a new
// user would: special files as outputs, numbers out of range, help and checks that disagreed,
// messages that named the wrong option or an internal buffer, silent acceptances, leftovers
// after Ctrl-C, and merges that missed damaged shards.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <functional>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "render/raytrace/SyntheticFootage.h"
#include "tests/support/TestSupport.h"

extern char** environ;

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

std::string scene() {
    return (dataDir() / "scenes" / "tabletop" / "tabletop.gltf").string();
}

bool has(const CommandResult& r, const std::string& text) {
    return r.output.find(text) != std::string::npos;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool isCharDevice(const fs::path& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

bool isFifo(const fs::path& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISFIFO(st.st_mode);
}

// A character device to write to: a copy of /dev/full's node when running as root (so that a
// command that replaced it would replace only the copy), else /dev/full itself.
fs::path fullDevice(const fs::path& dir) {
    struct stat st {};
    if (::geteuid() == 0 && ::stat("/dev/full", &st) == 0 &&
        ::mknod((dir / "full.png").c_str(), S_IFCHR | 0666, st.st_rdev) == 0)
        return dir / "full.png";
    return "/dev/full";
}

// Reads everything written into a FIFO until the writer closes it.
class FifoReader {
public:
    explicit FifoReader(const fs::path& fifo)
        : thread_([this, fifo] {
              const int fd = ::open(fifo.c_str(), O_RDONLY);
              char buf[65536];
              for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) bytes_.append(buf, size_t(n));
              ::close(fd);
          }) {}
    // Waits for the writer to finish; gives up (and unblocks the reader) after a few seconds.
    std::string bytes(const fs::path& fifo) {
        const int w = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // ends a reader left waiting
        if (w >= 0) ::close(w);
        thread_.join();
        return bytes_;
    }

private:
    std::string bytes_;
    std::thread thread_;
};

TEST(BadCommandLine, ADeviceAsOutputIsRefusedAndStaysADevice) {
    const fs::path dir = outputDir("badcli_device");
    const fs::path dev = fullDevice(dir);
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"board", "-o", dev.string(), "--json",
                                   (dir / "b.json").string()},
          std::vector<std::string>{"board", "-o", (dir / "b.png").string(), "--json", dev.string()},
          std::vector<std::string>{"render", scene(), "--camera", "main", "-o", dev.string(),
                                   "--width", "8", "--height", "6", "--spp", "1"},
          std::vector<std::string>{"synth", scene(), "-o", dev.string(), "--width", "8", "--height",
                                   "6", "--spp", "1", "--fps", "1", "--seconds", "1", "--no-env",
                                   "--force"}}) {
        const auto r = runMirage(args);
        EXPECT_EQ(r.exitCode, 1) << args[0] << "\n" << r.output;
        EXPECT_TRUE(has(r, "character device")) << r.output;
        EXPECT_TRUE(isCharDevice(dev)) << args[0] << " replaced the device node";
    }
    EXPECT_FALSE(fs::exists(dir / "b.png"));
}

TEST(BadCommandLine, AFifoOutputIsWrittenThroughAndStaysAFifo) {
    const fs::path dir = outputDir("badcli_fifo");
    const fs::path fifo = dir / "board.png";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
    FifoReader reader(fifo);
    const auto r = runMirage({"board", "-o", fifo.string(), "--rows", "1", "--cols", "1", "--dpi",
                              "30", "--json", (dir / "b.json").string()});
    const std::string bytes = reader.bytes(fifo);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(isFifo(fifo)) << "the FIFO was replaced by a file";
    ASSERT_GE(bytes.size(), 8u);
    EXPECT_EQ(bytes.substr(1, 3), "PNG");
    // A folder output cannot be a FIFO.
    const auto s = runMirage({"synth", scene(), "-o", fifo.string(), "--no-env"});
    EXPECT_EQ(s.exitCode, 1) << s.output;
    EXPECT_TRUE(has(s, "FIFO")) << s.output;
    EXPECT_TRUE(isFifo(fifo));
}

TEST(BadCommandLine, CsvToStandardOutputIsWrittenThrough) {
    // runMirage reads the command's standard output through a pipe: -o /dev/stdout is that pipe.
    const fs::path dir = outputDir("badcli_stdout");
    fs::create_directories(dir / "one");
    ASSERT_TRUE(cv::imwrite((dir / "one" / "000000.png").string(),
                            sessionFrames(dataDir() / "sessions" / "sample").front()));
    const std::string sample = (dataDir() / "sessions" / "sample").string();
    const auto r =
        runMirage({"track", "--video", (dir / "one").string(), "--calib", sample + "/main.yaml",
                   "--board", sample + "/board.json", "-o", "/dev/stdout"});
    EXPECT_TRUE(has(r, "frame,t,state")) << r.output;
    EXPECT_TRUE(fs::is_symlink("/dev/stdout") || isCharDevice("/dev/stdout"))
        << "/dev/stdout was replaced";
}

TEST(BadCommandLine, BoardNumbersAreRangeChecked) {
    const fs::path dir = outputDir("badcli_board");
    for (const auto& [option, value] :
         std::vector<std::pair<std::string, std::string>>{{"--gap", "inf"},
                                                          {"--margin", "inf"},
                                                          {"--tag-size", "nan"},
                                                          {"--tag-size", "1e300"},
                                                          {"--gap", "-1"},
                                                          {"--rows", "1000000"},
                                                          {"--first-id", "-5"}}) {
        const auto r = runMirage({"board", "-o", (dir / "b.png").string(), option, value});
        EXPECT_EQ(r.exitCode, 1) << option << " " << value << "\n" << r.output;
        EXPECT_TRUE(has(r, option)) << r.output;
        EXPECT_FALSE(fs::exists(dir / "b.png")) << option << " " << value;
        EXPECT_FALSE(fs::exists(dir / "b.json")) << option << " " << value;
    }
    // A sheet too large for a PNG at the resolution asked for.
    const auto r = runMirage({"board", "-o", (dir / "b.png").string(), "--tag-size", "0.1", "--gap",
                              "0.03", "--margin", "0.02", "--dpi", "4800"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "--dpi")) << r.output;
}

TEST(BadCommandLine, HelpStatesTheRangesTheChecksUse) {
    const auto help = runMirage({"synth", "--help"});
    ASSERT_EQ(help.exitCode, 0);
    EXPECT_TRUE(has(help, "in " + raytrace::kPinholeHfovDeg.text())) << help.output;
    EXPECT_TRUE(has(help, "in " + raytrace::kFisheyeFovDeg.text())) << help.output;
    // Values the help calls fine are accepted by the check, values outside are refused before
    // the scene is loaded, with the same range in the message.
    const fs::path dir = outputDir("badcli_synth_help");
    for (const auto& [option, value] : std::vector<std::pair<std::string, std::string>>{
             {"--hfov", "179"}, {"--hfov", "0.5"}, {"--env-fov", "300"}, {"--env-fov", "5"}}) {
        const auto r = runMirage({"synth", scene(), "-o", (dir / "s").string(), option, value});
        EXPECT_EQ(r.exitCode, 1) << option << " " << value << "\n" << r.output;
        const std::string range =
            option == "--hfov" ? raytrace::kPinholeHfovDeg.text() : raytrace::kFisheyeFovDeg.text();
        EXPECT_TRUE(has(r, range)) << r.output;
        EXPECT_FALSE(fs::exists(dir / "s"));
    }
}

TEST(BadCommandLine, RenderRowsErrorsNameRows) {
    const fs::path dir = outputDir("badcli_rows");
    for (const std::string rows : {"5:2", "0:100000"}) {
        const auto r =
            runMirage({"render", scene(), "--camera", "main", "-o", (dir / "r.png").string(),
                       "--width", "8", "--height", "6", "--spp", "1", "--rows", rows});
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_TRUE(has(r, "--rows")) << r.output;
        EXPECT_FALSE(has(r, "--frames")) << r.output;
    }
}

TEST(BadCommandLine, ASceneWithoutMeshesSaysSo) {
    const fs::path dir = outputDir("badcli_no_mesh");
    // A camera and a virtual light, no mesh.
    std::ofstream(dir / "empty.gltf") << R"({"asset": {"version": "2.0"},
 "extensionsUsed": ["KHR_lights_punctual"],
 "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1}]}},
 "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
 "nodes": [{"name": "cam", "camera": 0, "translation": [0, 0, 1]},
           {"name": "lamp", "extensions": {"KHR_lights_punctual": {"light": 0}},
            "extras": {"mirage": {"origin": "virtual"}}}],
 "scenes": [{"nodes": [0, 1]}], "scene": 0})";
    const auto r = runMirage(
        {"info", "--passes", (dir / "empty.gltf").string(), "--width", "32", "--height", "24"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "no mesh")) << r.output;
    // replay said "buffer CompositeSrgb was not produced this frame".
    const auto replay = runMirage({"replay", (dataDir() / "sessions" / "sample").string(),
                                   "--scene", (dir / "empty.gltf").string(), "-o",
                                   (dir / "out.mkv").string(), "--frames", "1"});
    EXPECT_EQ(replay.exitCode, 1) << replay.output;
    EXPECT_TRUE(has(replay, "empty.gltf")) << replay.output;
    EXPECT_TRUE(has(replay, "no mesh")) << replay.output;
    EXPECT_FALSE(has(replay, "CompositeSrgb")) << replay.output;
}

TEST(BadCommandLine, CalibrateNeverReadsItsOwnPartialOutput) {
    const fs::path dir = outputDir("badcli_calib_partial");
    auto r = runMirage(
        {"calibrate", "--write-synthetic", (dir / "views").string(), "--synthetic-views", "6"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    // The report is written into the input folder under a temporary name while the views are
    // read: the listing must not take it for a view.
    r = runMirage({"calibrate", "--batch", (dir / "views").string(), "--board",
                   "chessboard:9x6:0.025", "-o", (dir / "cal.yaml").string(), "--report",
                   (dir / "views" / "report.png").string()});
    EXPECT_NE(r.exitCode, 1) << r.output;
    EXPECT_FALSE(has(r, "report.partial")) << r.output;
}

TEST(BadCommandLine, AHugeImageIsRefusedFromItsHeader) {
    const fs::path dir = outputDir("badcli_huge_png");
    // A PNG header claiming 16000 x 16000 pixels (no pixel data follows).
    std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\x3e\x80\0\0\x3e\x80\x08\x02\0\0\0", 29);
    png += std::string(4, '\0');
    std::ofstream(dir / "huge.png", std::ios::binary) << png;
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = runMirage({"render", scene(), "--camera", "main", "-o", (dir / "r.png").string(),
                              "--mode", "composite", "--camera-image", (dir / "huge.png").string(),
                              "--width", "8", "--height", "6"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "16000 x 16000")) << r.output;
    EXPECT_TRUE(has(r, "at most")) << "the limit is stated: " << r.output;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 30);
}

TEST(BadCommandLine, SilentAcceptancesAreRefused) {
    const fs::path dir = outputDir("badcli_silent");
    const std::vector<std::vector<std::string>> cases = {
        {"calibrate", "--write-synthetic", (dir / "syn").string(), "--synthetic-views", "0"},
        {"calibrate", "--batch", (dir / "x").string(), "--board", "chessboard:9x6:0.025", "-o",
         (dir / "c.yaml").string(), "--video-step", "0"},
        {"render", scene(), "--camera", "main", "-o", (dir / "r.png").string(), "--seed", "-1"},
        {"synth", scene(), "-o", (dir / "s").string(), "--seed", "-1"},
        {"synth", scene(), "-o", (dir / "s").string(), "--shard", ""},
        {"render", scene(), "--camera", "main", "-o", (dir / "r.png").string(), "--shard", ""},
        {"slurm", "--shards", "2", "--dry-run", "--time", "banana", "--", "render", scene(),
         "--camera", "main", "-o", (dir / "r.png").string()},
        {"slurm", "--shards", "2", "--dry-run", "--partition", "a\nb", "--", "render", scene(),
         "--camera", "main", "-o", (dir / "r.png").string()},
    };
    for (const auto& args : cases) {
        const auto r = runMirage(args);
        std::string line;
        for (const auto& a : args) line += a + " ";
        EXPECT_EQ(r.exitCode, 1) << line << "\n" << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "syn"));
    EXPECT_FALSE(fs::exists(dir / "s"));
    EXPECT_FALSE(fs::exists(dir / "r.png"));
    EXPECT_FALSE(fs::exists(dir / "r.png.slurm"));
    // Slurm's own time formats pass.
    for (const char* t : {"90", "30:00", "04:00:00", "2-12", "1-00:30:00"}) {
        const auto r =
            runMirage({"slurm", "--shards", "2", "--dry-run", "--time", t, "--", "render", scene(),
                       "--camera", "main", "-o", (dir / "ok.png").string()});
        EXPECT_EQ(r.exitCode, 0) << t << "\n" << r.output;
    }
}

pid_t spawnMirage(const std::vector<std::string>& args, const fs::path& log) {
    std::vector<std::string> all = {MIRAGE_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    // SIGINT and SIGTERM at their default action in the child, even when this test runs from a
    // shell that ignores SIGINT for background jobs (an ignored signal survives exec).
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
    pid_t pid = -1;
    EXPECT_EQ(posix_spawn(&pid, argv[0], &fa, &attr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&attr);
    return pid;
}

// Names in `dir` holding ".partial-".
std::vector<std::string> partials(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().find(".partial-") != std::string::npos)
            names.push_back(e.path().filename().string());
    return names;
}

// Waits (up to `seconds`) until `ready` holds.
bool waitFor(const std::function<bool()>& ready, double seconds) {
    const auto t0 = std::chrono::steady_clock::now();
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds) {
        if (ready()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
}

TEST(BadCommandLine, InterruptedRenderLeavesNothing) {
    const fs::path dir = outputDir("badcli_render_sigint");
    const pid_t pid =
        spawnMirage({"render", scene(), "--camera", "main", "-o", (dir / "r.png").string(),
                     "--width", "64", "--height", "48", "--spp", "100000"},
                    dir / "log.txt");
    // The render has started once its output's temporary exists.
    if (!waitFor([&] { return !partials(dir).empty(); }, 60)) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, nullptr, 0);
        FAIL() << "no partial output within 60 s: " << slurp(dir / "log.txt");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ::kill(pid, SIGINT);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    EXPECT_EQ(partials(dir), std::vector<std::string>{}) << "a partial file was left";
    EXPECT_FALSE(fs::exists(dir / "r.png"));
}

TEST(BadCommandLine, InterruptedSynthLeavesNothingAndTheRerunWorks) {
    const fs::path dir = outputDir("badcli_synth_sigint");
    const fs::path out = dir / "session";
    const std::vector<std::string> args = {"synth",    scene(),    "-o", out.string(), "--width",
                                           "32",       "--height", "24", "--spp",      "1",
                                           "--no-env", "--fps",    "4"};
    // An hour of footage (14,400 frames): minutes of work even on a fast machine, so the signal
    // always arrives mid-run (60 s, 240 frames, finished within the 0.5 s wait on CI).
    auto longRun = args;
    longRun.insert(longRun.end(), {"--seconds", "3600"});
    const pid_t pid = spawnMirage(longRun, dir / "log.txt");
    ASSERT_TRUE(waitFor([&] { return !partials(dir).empty(); }, 60)) << slurp(dir / "log.txt");
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, WNOHANG), 0) << "synth ended before the signal was sent";
    ::kill(pid, SIGINT);
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    EXPECT_EQ(partials(dir), std::vector<std::string>{}) << "a partial folder was left";
    EXPECT_FALSE(fs::exists(out));
    auto shortRun = args;
    shortRun.insert(shortRun.end(), {"--seconds", "0.5"});
    const auto r = runMirage(shortRun);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(fs::exists(out / "session.json"));
}

TEST(BadCommandLine, APartialLeftBySigkillIsRemovedByTheNextRun) {
    const fs::path dir = outputDir("badcli_sigkill");
    const pid_t pid =
        spawnMirage({"render", scene(), "--camera", "main", "-o", (dir / "r.png").string(),
                     "--width", "64", "--height", "48", "--spp", "100000"},
                    dir / "log.txt");
    ASSERT_TRUE(waitFor([&] { return !partials(dir).empty(); }, 60));
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    ASSERT_EQ(partials(dir).size(), 1u);  // SIGKILL cannot be caught
    const auto r = runMirage({"render", scene(), "--camera", "main", "-o", (dir / "r.png").string(),
                              "--width", "8", "--height", "6", "--spp", "1"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(partials(dir), std::vector<std::string>{});
}

// A synthetic session in two shards (PNG frames), not merged yet.
fs::path twoShards(const std::string& name) {
    const fs::path dir = outputDir(name);
    const fs::path out = dir / "s";
    for (const char* shard : {"0/2", "1/2"}) {
        const auto r = runMirage({"synth", scene(), "-o", out.string(), "--width", "16", "--height",
                                  "12", "--spp", "1", "--fps", "4", "--seconds", "1", "--no-env",
                                  "--image-sequence", "--shard", shard});
        EXPECT_EQ(r.exitCode, 0) << r.output;
    }
    return out;
}

TEST(BadCommandLine, MergeFindsADeletedCsvRow) {
    // A replay in two shards of one frame each (PNG frames and a CSV per shard).
    const fs::path out = outputDir("badcli_merge_row") / "r";
    for (const char* shard : {"0/2", "1/2"}) {
        const auto r = runMirage({"replay", (dataDir() / "sessions" / "sample").string(), "--scene",
                                  scene(), "-o", out.string(), "--frames", "2", "--warmup", "0",
                                  "--vpls", "16", "--shard", shard});
        ASSERT_EQ(r.exitCode, 0) << r.output;
    }
    const fs::path csv = fs::path(out.string() + ".shards") / "1-of-2" / "frames.csv";
    ASSERT_TRUE(fs::exists(csv));
    std::ifstream in(csv);
    std::string header;
    std::getline(in, header);  // the header only: the row of frame 1 deleted
    in.close();
    std::ofstream(csv, std::ios::trunc) << header << "\n";
    const auto r = runMirage({"merge", out.string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "1-of-2")) << r.output;
    EXPECT_TRUE(has(r, "row of frame 1")) << r.output;
    EXPECT_FALSE(fs::exists(out));
}

TEST(BadCommandLine, MergeFindsAFrameSwappedBetweenShards) {
    const fs::path out = twoShards("badcli_merge_swap");
    const fs::path shards = out.string() + ".shards";
    // Frame 1's PNG (shard 1) put in place of frame 0's (shard 0).
    auto firstPng = [](const fs::path& dir) {
        std::vector<fs::path> pngs;
        for (const auto& e : fs::recursive_directory_iterator(dir))
            if (e.path().extension() == ".png") pngs.push_back(e.path());
        std::sort(pngs.begin(), pngs.end());
        return pngs.empty() ? fs::path() : pngs.front();
    };
    const fs::path a = firstPng(shards / "0-of-2"), b = firstPng(shards / "1-of-2");
    ASSERT_FALSE(a.empty());
    ASSERT_FALSE(b.empty());
    fs::copy_file(b, a, fs::copy_options::overwrite_existing);
    const auto r = runMirage({"merge", out.string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(has(r, "0-of-2")) << r.output;
    EXPECT_TRUE(has(r, "frame 0")) << r.output;
    EXPECT_FALSE(fs::exists(out));
    // Intact shards still merge.
    const fs::path good = twoShards("badcli_merge_good");
    const auto ok = runMirage({"merge", good.string()});
    EXPECT_EQ(ok.exitCode, 0) << ok.output;
}

}  // namespace
}  // namespace mirage::test
