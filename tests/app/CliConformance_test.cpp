// Every option of every command, taken from CLI11's own list (`mirage --list-options`), fed the
// values a careless user or a broken script gives: numbers NaN, inf, -1, 0 and 1e300; paths a
// folder, a FIFO, a character device (a copy of /dev/full's node when running as root, else
// /dev/full itself) and a path under a missing folder. Each run must be refused before work
// (exit 1 with a message) or succeed meaningfully (exit 0 from a tiny job); never exit 0 with NaN,
// inf or 1e300 taken, never a crash, never a hang, and the FIFO and the device stay what they are.
//
// Accepted values run a tiny job: every command's base invocation below works on a one-frame,
// 32 x 24 synthetic session, an 8 x 6 render or a one-tag board, so an accepted value finishes in
// seconds. New commands and options are covered automatically; a command without a base
// invocation fails the test.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "tests/support/TestSupport.h"

extern char** environ;

namespace mirage::test {
namespace {

namespace fs = std::filesystem;

struct CliOption {
    std::string command, name, kind, type, validators;
    int values = 1;  // values per use (3 for --env-white-balance R,G,B)
};

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::stringstream in(s);
    for (std::string part; std::getline(in, part, sep);) out.push_back(part);
    if (!s.empty() && s.back() == sep) out.emplace_back();
    return out;
}

std::vector<CliOption> listOptions() {
    const CommandResult r = runMirage({"--list-options"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    std::vector<CliOption> options;
    std::stringstream in(r.output);
    for (std::string line; std::getline(in, line);) {
        const auto f = split(line, '\t');
        if (f.size() < 6) continue;
        CliOption o;
        o.command = f[0];
        // "-o,--output": use the long name.
        o.name = split(f[1], ',').back();
        o.kind = f[2];
        o.type = f[3];
        // A list option (INPUT...) takes one value here; a fixed count (R,G,B) takes them all.
        const int values = std::atoi(f[4].c_str());
        o.values = values >= 1 && values <= 16 ? values : 1;
        o.validators = f[5];
        options.push_back(o);
    }
    return options;
}

bool isNumeric(const CliOption& o) {
    const std::string t = o.type.substr(0, o.type.find(':'));
    return t == "INT" || t == "UINT" || t == "FLOAT" || t == "NUMBER";
}

struct RunResult {
    int exitCode = -1;  // -1: killed by a signal or timed out
    bool timedOut = false;
    std::string output;
};

// Keeps a FIFO serviced while a command runs: what the command writes into it is read and
// dropped, and a command that opens it for reading gets end-of-file (a writer that opens and
// closes it at once) instead of waiting for ever.
class FifoPartner {
public:
    explicit FifoPartner(fs::path fifo) : fifo_(std::move(fifo)) {
        reader_ = ::open(fifo_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
        thread_ = std::thread([this] {
            char buf[65536];
            while (!stop_) {
                while (::read(reader_, buf, sizeof buf) > 0) bytes_ += 1;
                const int w = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
                if (w >= 0) ::close(w);
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
        });
    }
    ~FifoPartner() {
        stop_ = true;
        thread_.join();
        ::close(reader_);
    }

private:
    fs::path fifo_;
    int reader_ = -1;
    std::atomic<bool> stop_{false};
    std::atomic<long> bytes_{0};
    std::thread thread_;
};

// Runs mirage with a time limit (seconds); stdout and stderr go to `log`.
RunResult runLimited(const std::vector<std::string>& args, double seconds, const fs::path& log) {
    std::vector<std::string> all = {MIRAGE_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    pid_t pid = -1;
    RunResult r;
    if (posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) return r;
    posix_spawn_file_actions_destroy(&fa);
    const auto start = std::chrono::steady_clock::now();
    int status = 0;
    for (;;) {
        if (::waitpid(pid, &status, WNOHANG) == pid) break;
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
            seconds) {
            ::kill(pid, SIGKILL);
            ::waitpid(pid, &status, 0);
            r.timedOut = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (!r.timedOut && WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    std::ifstream in(log);
    r.output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return r;
}

// One command's tiny, valid invocation: positional values in CLI11's order, then options.
struct BaseInvocation {
    std::vector<std::pair<std::string, std::string>> args;  // name -> value ("" for a flag)
};

std::vector<std::string> assemble(const BaseInvocation& base, const std::vector<CliOption>& opts,
                                  const std::string& command, const std::string& name,
                                  const std::vector<std::string>& values) {
    std::vector<std::string> out = {command};
    bool replaced = false;
    std::vector<std::string> tail;
    for (const CliOption& o : opts) {
        if (o.command != command || o.kind != "positional") continue;
        for (const auto& [n, v] : base.args)
            if (n == o.name) {
                if (n == name) {
                    out.insert(out.end(), values.begin(), values.end());
                    replaced = true;
                } else {
                    out.push_back(v);
                }
            }
    }
    for (const auto& [n, v] : base.args) {
        bool positional = false;
        for (const CliOption& o : opts)
            if (o.command == command && o.name == n && o.kind == "positional") positional = true;
        if (positional || n == name || n == "--") continue;
        out.push_back(n);
        if (!v.empty()) out.push_back(v);
    }
    if (!replaced && !name.empty()) {
        for (const CliOption& o : opts)
            if (o.command == command && o.name == name && o.kind == "positional") {
                out.insert(out.end(), values.begin(), values.end());
                replaced = true;
            }
        if (!replaced) {
            out.push_back(name);
            out.insert(out.end(), values.begin(), values.end());
        }
    }
    // `mirage slurm` ends with the command it splits, after "--".
    for (const auto& [n, v] : base.args)
        if (n == "--") {
            out.push_back("--");
            for (const std::string& w : split(v, ' ')) out.push_back(w);
        }
    return out;
}

class CliConformance : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        // A folder per process: ctest runs each test of this suite as its own process, two at a
        // time, and each sets the suite up (a shared folder would be emptied under the other).
        dir_ = outputDir("cli_conformance_" + std::to_string(::getpid()));
        // A one-frame synthetic session with ground truth and an environment camera: replay,
        // bench, live, track and env-radiometry on it take a second or two.
        const std::string scene = (dataDir() / "scenes" / "tabletop" / "tabletop.gltf").string();
        const auto r = runMirage({"synth", scene, "-o", (dir_ / "session").string(), "--width",
                                  "32", "--height", "24", "--fps", "1", "--seconds", "1", "--spp",
                                  "1", "--env-size", "16", "--ground-truth-composite"});
        ASSERT_EQ(r.exitCode, 0) << r.output;
        // One frame of the sample as an image folder (track --video).
        fs::create_directories(dir_ / "one_frame");
        const auto frames = sessionFrames(dataDir() / "sessions" / "sample");
        ASSERT_FALSE(frames.empty());
        ASSERT_TRUE(cv::imwrite((dir_ / "one_frame" / "000000.png").string(), frames.front()));
        // An exposure bracket (response): four pictures of a still ramp over three decades of
        // light, each twice the exposure of the one before, from a gamma-2.2 camera.
        fs::create_directories(dir_ / "bracket");
        std::ofstream exposures(dir_ / "bracket" / "exposures.csv");
        exposures << "file,exposure_seconds\n";
        for (int i = 0; i < 4; ++i) {
            cv::Mat img(48, 64, CV_8UC3);
            for (int p = 0; p < img.rows * img.cols; ++p) {
                const double light = std::pow(10.0, -3.0 + 3.0 * p / (img.rows * img.cols - 1));
                const double v = 255.0 * std::pow(std::min(1.0, light * (1 << i)), 1.0 / 2.2);
                img.at<cv::Vec3b>(p / img.cols, p % img.cols) = cv::Vec3b::all(uint8_t(v));
            }
            const std::string name = "b" + std::to_string(i) + ".png";
            ASSERT_TRUE(cv::imwrite((dir_ / "bracket" / name).string(), img));
            exposures << name << "," << (1 << i) << "\n";
        }
        // One shard of a tiny render, kept by every merge (--keep-shards).
        const auto shard =
            runMirage({"render", scene, "--camera", "main", "-o", (dir_ / "merged.png").string(),
                       "--width", "8", "--height", "6", "--spp", "1", "--shard", "0/1"});
        ASSERT_EQ(shard.exitCode, 0) << shard.output;
    }

    static std::map<std::string, BaseInvocation> bases(const fs::path& out) {
        const std::string scene = (dataDir() / "scenes" / "tabletop" / "tabletop.gltf").string();
        const std::string session = (dir_ / "session").string();
        const std::string sample = (dataDir() / "sessions" / "sample").string();
        return {
            {"board",
             {{{"--output", (out / "b.png").string()},
               {"--rows", "1"},
               {"--cols", "1"},
               {"--dpi", "30"}}}},
            {"render",
             {{{"scene", scene},
               {"--camera", "main"},
               {"--output", (out / "r.png").string()},
               {"--width", "8"},
               {"--height", "6"},
               {"--spp", "1"}}}},
            {"synth",
             {{{"scene", scene},
               {"--output", (out / "s").string()},
               {"--width", "8"},
               {"--height", "6"},
               {"--spp", "1"},
               {"--fps", "1"},
               {"--seconds", "1"},
               {"--no-env", ""}}}},
            {"track",
             {{{"--video", (dir_ / "one_frame").string()},
               {"--calib", sample + "/main.yaml"},
               {"--board", sample + "/board.json"},
               {"--output", (out / "p.csv").string()}}}},
            {"replay",
             {{{"session", session},
               {"--scene", scene},
               {"--output", (out / "r.mkv").string()},
               {"--frames", "1"}}}},
            {"live",
             {{{"--camera", session},
               {"--scene", scene},
               {"--headless", ""},
               {"--frames", "1"},
               {"--output", (out / "live").string()}}}},
            {"bench",
             {{{"session", session},
               {"--scene", scene},
               {"--output", (out / "b").string()},
               {"--quick", ""},
               {"--frames", "1"}}}},
            {"env-radiometry", {{{"session", session}, {"--scene", scene}, {"--frames", "1"}}}},
            {"proxies",
             {{{"session", sample},
               {"--scene", scene},
               {"--output", (out / "p.gltf").string()},
               {"--ground-truth", ""},
               {"--max-frames", "12"}}}},
            {"calibrate",
             {{{"--write-synthetic", (out / "syn").string()}, {"--synthetic-views", "3"}}}},
            {"info", {{}}},
            {"response", {{{"bracket", (dir_ / "bracket").string()}}}},
            {"merge",
             {{{"output", (dir_ / "merged.png").string()},
               {"--keep-shards", ""},
               {"--force", ""}}}},
            {"slurm",
             {{{"--shards", "2"},
               {"--dry-run", ""},
               {"--", "render " + scene + " --camera main -o " + (out / "x.png").string()}}}},
        };
    }

    // Commands whose accepted numbers would start a GL renderer for every value (a few seconds
    // each): their numeric cases run this invocation instead, which fails in the command's own
    // checks right after parsing with `marker` in its message. A value refused by the option's
    // check never reaches them; a value accepted is not run (the parse-level refusal of NaN, inf
    // and 1e300 is what is checked there; the tiny jobs of the other commands check the rest).
    struct Probe {
        std::string option, value, marker;
    };
    static std::map<std::string, Probe> probes(const fs::path& out) {
        return {
            {"replay", {"--output", (out / "r.mp4").string(), ".mkv"}},
            {"live", {"--output", (out / "live.mp4").string(), ".mkv"}},
            {"bench", {"--scene", (out / "missing.gltf").string(), "scene not found"}},
            {"env-radiometry", {"session", (out / "not_a_session").string(), "session.json"}},
            {"proxies", {"session", (out / "not_a_session").string(), "session.json"}},
        };
    }

    static fs::path dir_;
};
fs::path CliConformance::dir_;

// The special files the path cases use; each must still be what it was after every run.
struct SpecialFiles {
    fs::path folder, fifo, device, missingParent;
    dev_t deviceNumber = 0;

    explicit SpecialFiles(const fs::path& dir) {
        folder = dir / "a_folder";
        fs::create_directories(folder);
        fifo = dir / "a_fifo";
        EXPECT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
        struct stat st {};
        EXPECT_EQ(::stat("/dev/full", &st), 0);
        deviceNumber = st.st_rdev;
        device = "/dev/full";
        // As root, a copy of the node: if a command replaced it, only the copy would be lost.
        if (::geteuid() == 0 &&
            ::mknod((dir / "full_copy.png").c_str(), S_IFCHR | 0666, st.st_rdev) == 0)
            device = dir / "full_copy.png";
        missingParent = dir / "no" / "such" / "folder" / "out.png";
    }

    // Empty when all is well, else what changed.
    std::string damage() const {
        struct stat st {};
        if (::stat(fifo.c_str(), &st) != 0 || !S_ISFIFO(st.st_mode)) return "the FIFO was replaced";
        if (::stat(device.c_str(), &st) != 0 || !S_ISCHR(st.st_mode) || st.st_rdev != deviceNumber)
            return "the character device was replaced";
        if (!fs::is_directory(folder)) return "the folder was replaced";
        return "";
    }
};

// Whether an exit-0 run logged a non-finite value: "nan", "inf" as a number.
bool printsNonFinite(const std::string& out) {
    for (const char* s : {" nan", " -nan", " inf ", "(nan", "(-nan", "=nan", "=inf"})
        if (out.find(s) != std::string::npos) return true;
    return false;
}

TEST_F(CliConformance, EveryNumericOptionUsesTheNumberCheck) {
    const auto options = listOptions();
    ASSERT_GT(options.size(), 50u);
    for (const CliOption& o : options)
        if (isNumeric(o)) {
            EXPECT_NE(o.validators.find("number-range"), std::string::npos)
                << "mirage " << o.command << " " << o.name << " (" << o.type
                << ") has no range check (app/NumberChecks.h)";
        }
}

TEST_F(CliConformance, EveryCommandHasABaseInvocation) {
    const auto known = bases(dir_);
    for (const CliOption& o : listOptions())
        EXPECT_TRUE(known.count(o.command))
            << "add a tiny base invocation for `mirage " << o.command << "` to this test";
}

TEST_F(CliConformance, BaseInvocationsSucceed) {
    for (const auto& [command, base] : bases(outputDir("cli_conformance_base"))) {
        const fs::path log = outputDir("cli_conformance_base_log") / "log.txt";
        const RunResult r = runLimited(assemble(base, listOptions(), command, "", {}), 60, log);
        EXPECT_FALSE(r.timedOut) << command;
        if (command == "env-radiometry") {
            // The one-frame session's main camera sees only the modelled table, so no direction
            // is seen by both cameras: the base is the command's meaningful refusal (exit 1 with
            // what to film), which its numeric and path cases then run through.
            EXPECT_EQ(r.exitCode, 1) << r.output;
            EXPECT_NE(r.output.find("no estimate from"), std::string::npos) << r.output;
            continue;
        }
        EXPECT_EQ(r.exitCode, 0) << command << "\n" << r.output;
    }
}

TEST_F(CliConformance, NumbersAreRefusedOrMeaningful) {
    const auto options = listOptions();
    for (const CliOption& o : options) {
        if (!isNumeric(o)) continue;
        for (const std::string value : {"nan", "inf", "-1", "0", "1e300"}) {
            const fs::path out = outputDir("cli_conformance_num");
            const std::vector<std::string> values(size_t(o.values), value);
            BaseInvocation base = bases(out).at(o.command);
            const auto probe = probes(out);
            const bool probed = probe.count(o.command) > 0;
            if (probed) {
                fs::create_directories(out / "not_a_session");
                for (auto& [n, v] : base.args)
                    if (n == probe.at(o.command).option) v = probe.at(o.command).value;
            }
            const auto args = assemble(base, options, o.command, o.name, values);
            const RunResult r = runLimited(args, 60, out.parent_path() / "cli_conformance_num.log");
            const std::string what = "mirage " + o.command + " " + o.name + " " + value;
            const bool reachedProbe =
                probed && r.output.find(probe.at(o.command).marker) != std::string::npos;
            ASSERT_FALSE(r.timedOut) << what << ": still running after 60 s";
            EXPECT_TRUE(r.exitCode == 0 || r.exitCode == 1)
                << what << " exit " << r.exitCode << "\n"
                << r.output;
            const bool mustRefuse = value == "nan" || value == "inf" || value == "1e300";
            if (mustRefuse) {
                EXPECT_EQ(r.exitCode, 1) << what << " was accepted:\n" << r.output;
                EXPECT_FALSE(reachedProbe) << what << " passed the option's check:\n" << r.output;
                EXPECT_NE(r.output.find(value), std::string::npos)
                    << what << ": the message does not name the value\n"
                    << r.output;
            } else if (r.exitCode == 0) {
                EXPECT_FALSE(printsNonFinite(r.output)) << what << "\n" << r.output;
            } else {
                // Refused with a reason: the option's own check names the option and its
                // range at parsing; a later refusal is an error line.
                const bool saysWhy = r.output.find(o.name + ":") != std::string::npos ||
                                     r.output.find("error") != std::string::npos;
                EXPECT_TRUE(saysWhy) << what << ": refused without saying why\n" << r.output;
            }
        }
    }
}

TEST_F(CliConformance, PathsAreRefusedOrMeaningful) {
    const auto options = listOptions();
    const fs::path dir = outputDir("cli_conformance_paths");
    const SpecialFiles special(dir);
    const FifoPartner partner(special.fifo);
    for (const CliOption& o : options) {
        const std::string t = o.type.substr(0, o.type.find(':'));
        if (o.kind == "flag" || isNumeric(o) || t != "TEXT") continue;
        if (o.command == "slurm" && o.name == "command") continue;  // the command after "--"
        // The device goes to outputs (options with the output-path check) only: as an input,
        // /dev/full reads as endless zeros, which no reader can tell from a huge file in time.
        std::vector<fs::path> values = {special.folder, special.fifo, special.missingParent};
        if (o.validators.find("output-path") != std::string::npos) values.push_back(special.device);
        for (const fs::path& value : values) {
            const fs::path out = outputDir("cli_conformance_path_run");
            const auto args =
                assemble(bases(out).at(o.command), options, o.command, o.name, {value.string()});
            const RunResult r = runLimited(args, 60, dir / "run.log");
            const std::string what = "mirage " + o.command + " " + o.name + " " + value.string();
            ASSERT_FALSE(r.timedOut) << what << ": still running after 60 s\n" << r.output;
            EXPECT_TRUE(r.exitCode == 0 || r.exitCode == 1)
                << what << " exit " << r.exitCode << "\n"
                << r.output;
            if (r.exitCode == 1) {
                // Refused with a reason: the option's own check names the option at parsing; a
                // later refusal is an error line.
                const bool saysWhy = r.output.find(o.name + ":") != std::string::npos ||
                                     r.output.find("rror") != std::string::npos;
                EXPECT_TRUE(saysWhy) << what << ": refused without saying why\n" << r.output;
            }
            ASSERT_EQ(special.damage(), "") << what << "\n" << r.output;
        }
    }
}

}  // namespace
}  // namespace mirage::test
