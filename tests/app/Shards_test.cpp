// Split runs joined by `mirage merge` equal the unsplit run bit for bit (docs/scale.md):
// `mirage synth` split by frames, `mirage render` split by rows. Tiny sizes keep it to seconds.
#include <gtest/gtest.h>

#include <cstdlib>

#include <fstream>
#include <iterator>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/Shards.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;
using test::runMirage;

std::string scene() {
    return (test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf").string();
}

// The scene the sample session was synthesised from (its real spot light lights the footage).
std::string sampleScene() {
    return (test::dataDir() / "scenes" / "tabletop" / "tabletop_backlit.gltf").string();
}

std::string bytesOf(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    EXPECT_TRUE(in) << p;
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every file of `a` equals the same file of `b`, byte for byte (creation times included: the
// tests fix them with SOURCE_DATE_EPOCH). Returns the number of files compared.
int expectSameTree(const fs::path& a, const fs::path& b) {
    int files = 0;
    for (const auto& e : fs::recursive_directory_iterator(a)) {
        if (!e.is_regular_file()) continue;
        const fs::path rel = fs::relative(e.path(), a);
        EXPECT_TRUE(fs::exists(b / rel)) << rel << " is missing from " << b;
        if (!fs::exists(b / rel)) continue;
        ++files;
        EXPECT_TRUE(bytesOf(e.path()) == bytesOf(b / rel)) << rel << " differs";
    }
    return files;
}

std::vector<std::string> synthArgs(const fs::path& out) {
    return {"synth",
            scene(),
            "-o",
            out.string(),
            "--width",
            "48",
            "--height",
            "36",
            "--fps",
            "5",
            "--seconds",
            "1",
            "--spp",
            "2",
            "--env-size",
            "32",
            "--noise",
            "0.01",
            "--ground-truth-composite",
            "--threads",
            "2"};
}

TEST(ShardedRuns, SynthShardsMergeToTheWholeSessionBitForBit) {
    // Creation times from the reproducible-builds clock, so that they are equal too; without it
    // the files differ by those times only (session.json, calibration YAML).
    ::setenv("SOURCE_DATE_EPOCH", "1764547200", 1);
    const fs::path dir = test::outputDir("shards_synth");
    fs::remove_all(dir);
    const fs::path whole = dir / "whole", split = dir / "split";
    auto r = runMirage(synthArgs(whole));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (int i : {2, 0, 1}) {  // any order, as a cluster runs them
        auto args = synthArgs(split);
        args.insert(args.end(), {"--shard", std::to_string(i) + "/3"});
        r = runMirage(args);
        ASSERT_EQ(r.exitCode, 0) << r.output;
    }
    EXPECT_FALSE(fs::exists(split)) << "a shard wrote the session itself";
    r = runMirage({"merge", split.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_FALSE(fs::exists(shardsFolder(split))) << "the shards were kept without --keep-shards";
    // main.mkv, env.mkv, frames.csv, calibration, board, ground truth: 5 frames x 2 + 6 files.
    EXPECT_GE(expectSameTree(whole, split), 16);
    EXPECT_EQ(expectSameTree(split, whole), expectSameTree(whole, split));
    ::unsetenv("SOURCE_DATE_EPOCH");
}

TEST(ShardedRuns, MissingOrForeignShardsAreNamedNotMerged) {
    const fs::path dir = test::outputDir("shards_synth_missing");
    fs::remove_all(dir);
    const fs::path split = dir / "split";
    auto args = synthArgs(split);
    args.insert(args.end(), {"--shard", "1/2"});
    ASSERT_EQ(runMirage(args).exitCode, 0);
    auto r = runMirage({"merge", split.string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("3 of 5 frames are missing (0, 2, 4)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--shard 0/2"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(split));
    // The other half with another seed is another run: refused, nothing written.
    args = synthArgs(split);
    args.insert(args.end(), {"--shard", "0/2", "--seed", "9"});
    ASSERT_EQ(runMirage(args).exitCode, 0);
    r = runMirage({"merge", split.string()});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("another run"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(split));
    // Rendering a finished shard again needs --force.
    r = runMirage(args);
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("already complete"), std::string::npos) << r.output;
}

TEST(ShardedRuns, RenderRowShardsMergeToTheWholeImageBitForBit) {
    const fs::path dir = test::outputDir("shards_render");
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const char* ext : {".exr", ".png"}) {
        const std::vector<std::string> base = {"render",  scene(),     "--camera",  "main",
                                               "--width", "40",        "--spp",     "3",
                                               "--mode",  "composite", "--threads", "2"};
        const fs::path whole = dir / (std::string("whole") + ext);
        const fs::path split = dir / (std::string("split") + ext);
        auto args = base;
        args.insert(args.end(), {"-o", whole.string()});
        auto r = runMirage(args);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        for (int i = 0; i < 3; ++i) {
            args = base;
            args.insert(args.end(), {"-o", split.string(), "--shard", std::to_string(i) + "/3"});
            r = runMirage(args);
            ASSERT_EQ(r.exitCode, 0) << r.output;
        }
        r = runMirage({"merge", split.string()});
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_TRUE(bytesOf(whole) == bytesOf(split)) << ext << ": merged image differs";
    }
    // A time budget cannot be split.
    auto r = runMirage({"render", scene(), "--camera", "main", "--seconds", "1", "-o",
                        (dir / "t.exr").string(), "--shard", "0/2"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("fixed --spp"), std::string::npos) << r.output;
}

// The rows of a bench CSV without its timing columns (those ending in "_ms"), which differ
// from run to run; everything else (configurations, frames, errors) must not.
std::vector<std::string> untimedRows(const fs::path& csv) {
    std::ifstream in(csv);
    std::vector<std::string> rows;
    std::vector<bool> keep;
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> cells;
        std::string cell;
        bool quoted = false;
        for (char c : line) {
            if (c == '"') quoted = !quoted;
            if (c == ',' && !quoted) {
                cells.push_back(cell);
                cell.clear();
            } else {
                cell += c;
            }
        }
        cells.push_back(cell);
        if (keep.empty())
            for (const auto& name : cells)
                keep.push_back(name.size() < 3 || name.substr(name.size() - 3) != "_ms");
        std::string row;
        for (size_t i = 0; i < cells.size() && i < keep.size(); ++i)
            if (keep[i]) row += cells[i] + ",";
        rows.push_back(row);
    }
    return rows;
}

TEST(ShardedRuns, BenchShardsMergeToTheWholeGridsRows) {
    const fs::path dir = test::outputDir("shards_bench");
    fs::remove_all(dir);
    const fs::path session = dir / "session";
    auto r = runMirage({"synth", scene(), "-o", session.string(), "--width", "64", "--height", "48",
                        "--fps", "2", "--seconds", "1", "--spp", "2", "--no-env",
                        "--ground-truth-composite", "--threads", "2"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::vector<std::string> base = {"bench", session.string(), "--quick"};
    auto args = base;
    args.insert(args.end(), {"-o", (dir / "whole").string()});
    r = runMirage(args);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (int i : {1, 0}) {
        args = base;
        args.insert(args.end(),
                    {"-o", (dir / "split").string(), "--shard", std::to_string(i) + "/2"});
        r = runMirage(args);
        ASSERT_EQ(r.exitCode, 0) << r.output;
    }
    r = runMirage({"merge", (dir / "split").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* file : {"bench.csv", "bench_frames.csv"}) {
        const auto whole = untimedRows(dir / "whole" / file);
        const auto split = untimedRows(dir / "split" / file);
        EXPECT_GE(whole.size(), 4u) << file;  // header, 2+ configurations, the footage row
        EXPECT_EQ(whole, split) << file;
    }
    std::ifstream md(dir / "split" / "bench.md");
    const std::string text{std::istreambuf_iterator<char>(md), std::istreambuf_iterator<char>()};
    EXPECT_NE(text.find("shard 1/2"), std::string::npos) << text;
}

// Replay parts are contiguous blocks, each rendering --warmup frames before its first: with a
// warm history the seam frame equals the unsplit replay's; without, it differs (the history is
// what the warm-up is for: docs/scale.md gives the seam's PSNR per warm-up length).
TEST(ShardedRuns, ReplayBlocksWithWarmupJoinSeamlessly) {
    const fs::path dir = test::outputDir("shards_replay");
    fs::remove_all(dir);
    const std::string session = (test::dataDir() / "sessions" / "sample").string();
    const std::vector<std::string> base = {"replay",   session, "--scene",       sampleScene(),
                                           "--frames", "10",    "--ground-truth"};
    auto args = base;
    args.insert(args.end(), {"-o", (dir / "whole").string()});
    auto r = runMirage(args);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* warmup : {"5", "0"}) {
        const fs::path split = dir / (std::string("split") + warmup);
        for (int i : {1, 0}) {
            args = base;
            args.insert(args.end(), {"-o", split.string(), "--shard", std::to_string(i) + "/2",
                                     "--warmup", warmup});
            r = runMirage(args);
            ASSERT_EQ(r.exitCode, 0) << r.output;
        }
        r = runMirage({"merge", split.string()});
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_EQ(untimedRows(split / "frames.csv").size(), 11u);  // header + 10 frames
        int differing = 0;
        for (int f = 0; f < 10; ++f) {
            const fs::path name = cv::format("frame_%06d.png", f);
            const cv::Mat a = cv::imread((dir / "whole" / name).string());
            const cv::Mat b = cv::imread((split / name).string());
            ASSERT_FALSE(a.empty() || b.empty()) << name;
            const bool same = cv::norm(a, b, cv::NORM_INF) == 0;
            if (f < 5) {
                EXPECT_TRUE(same) << name << ": the first block is the unsplit run's start";
            }
            differing += same ? 0 : 1;
        }
        if (std::string(warmup) == "5") {
            EXPECT_EQ(differing, 0) << "a warmed-up seam differs from the unsplit replay";
        } else {
            EXPECT_GT(differing, 0) << "a cold seam equals the unsplit replay: the warm-up test "
                                       "cannot tell";
        }
    }
}

TEST(ShardedRuns, SlurmScriptsRunOneShardPerTaskAndMergeAfterAll) {
    const fs::path dir = test::outputDir("shards_slurm_dry");
    fs::remove_all(dir);
    const fs::path out = dir / "gt";
    auto r = runMirage({"slurm", "--shards", "4", "--cpus", "3", "--time", "00:30:00", "--dry-run",
                        "--", "synth", scene(), "-o", out.string(), "--seconds", "2"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    std::ifstream tasks(dir / "gt.slurm" / "shards.sbatch"),
        merge(dir / "gt.slurm" / "merge.sbatch");
    const std::string t{std::istreambuf_iterator<char>(tasks), std::istreambuf_iterator<char>()};
    const std::string m{std::istreambuf_iterator<char>(merge), std::istreambuf_iterator<char>()};
    for (const char* want :
         {"#SBATCH --array=0-3", "#SBATCH --cpus-per-task=3", "#SBATCH --time=00:30:00",
          "#SBATCH --mem=", "--shard \"${SLURM_ARRAY_TASK_ID}/4\"",
          "--threads \"${SLURM_CPUS_PER_TASK:-1}\"", " synth "})
        EXPECT_NE(t.find(want), std::string::npos) << want << " not in:\n" << t;
    EXPECT_NE(m.find(" merge " + out.string()), std::string::npos) << m;
    EXPECT_NE(r.output.find("--dependency=afterok:"), std::string::npos) << r.output;
    // What cannot be split, or is split already, is refused before anything is submitted.
    r = runMirage({"slurm", "--shards", "2", "--dry-run", "--", "track", "s", "-o", "p.csv"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    r = runMirage({"slurm", "--shards", "2", "--dry-run", "--", "synth", scene(), "-o",
                   out.string(), "--shard", "0/2"});
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("leave --shard out"), std::string::npos) << r.output;
    // A session folder as the first argument (bench, replay): the estimate stays sane.
    r = runMirage({"slurm", "--shards", "2", "--dry-run", "--", "bench",
                   (test::dataDir() / "sessions" / "sample").string(), "-o", (dir / "b").string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("1024 MB each"), std::string::npos) << r.output;
    r = runMirage({"slurm", "--shards", "2", "--dry-run", "--", "synth", scene()});
    EXPECT_NE(r.output.find("needs -o OUT"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mirage
