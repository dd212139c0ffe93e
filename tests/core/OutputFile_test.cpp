// Output safety (core/OutputFile.h): an output is never an input, an unnamed existing file is
// never replaced without --force, and a failed write leaves the previous file as it was.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "core/Error.h"
#include "core/OutputFile.h"
#include "core/session/AtomicFile.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

void writeText(const fs::path& p, const std::string& text) {
    std::ofstream(p) << text;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(OutputFile, RefusesAnInputThroughLinks) {
    const fs::path dir = test::outputDir("output_file_links");
    writeText(dir / "video.mkv", "footage");
    fs::create_symlink(dir / "video.mkv", dir / "link.mkv");
    fs::create_hard_link(dir / "video.mkv", dir / "hard.mkv");
    const OutputRule rule{{dir / "video.mkv"}, false, "mirage test"};
    for (const char* name : {"video.mkv", "link.mkv", "hard.mkv"}) {
        const std::string e =
            errorOf([&] { OutputFile out(dir / name, OutputOrigin::Named, rule); });
        EXPECT_NE(e.find("is the input"), std::string::npos) << name << ": " << e;
    }
    // Also through a path with ".." and a relative spelling.
    const std::string e =
        errorOf([&] { checkOutput(dir / "sub" / ".." / "video.mkv", OutputOrigin::Named, rule); });
    EXPECT_EQ(e, "") << "sub/ does not exist, so the path cannot be the input";
    fs::create_directories(dir / "sub");
    EXPECT_NE(errorOf([&] {
                  checkOutput(dir / "sub" / ".." / "video.mkv", OutputOrigin::Named, rule);
              }).find("is the input"),
              std::string::npos);
    EXPECT_EQ(readFileBytes(dir / "video.mkv"), "footage");
    EXPECT_FALSE(fs::exists(dir / ("video.partial-" + std::to_string(::getpid()) + ".mkv")));
}

TEST(OutputFile, RefusesAFolderHoldingAnInput) {
    const fs::path dir = test::outputDir("output_file_folder");
    writeText(dir / "frames.csv", "truth");
    const OutputRule rule{{dir, dir / "frames.csv"}, false, "mirage replay"};
    EXPECT_NE(
        errorOf([&] { checkOutput(dir, OutputOrigin::Named, rule, true); }).find("is the input"),
        std::string::npos);
    const OutputRule rule2{{dir / "frames.csv"}, false, "mirage replay"};
    EXPECT_NE(errorOf([&] {
                  checkOutput(dir, OutputOrigin::Named, rule2, true);
              }).find("holds the input"),
              std::string::npos);
}

TEST(OutputFile, DerivedFileNeedsForce) {
    const fs::path dir = test::outputDir("output_file_derived");
    writeText(dir / "out.csv", "old");
    OutputRule rule{{}, false, "mirage replay"};
    const std::string e =
        errorOf([&] { OutputFile f(dir / "out.csv", OutputOrigin::Derived, rule); });
    EXPECT_NE(e.find("--force"), std::string::npos) << e;
    EXPECT_EQ(readFileBytes(dir / "out.csv"), "old");
    // Named by the user: replaced (on commit). Derived with --force: replaced too.
    EXPECT_EQ(errorOf([&] { OutputFile f(dir / "out.csv", OutputOrigin::Named, rule); }), "");
    rule.force = true;
    OutputFile f(dir / "out.csv", OutputOrigin::Derived, rule);
    writeText(f.temp(), "new");
    EXPECT_EQ(readFileBytes(dir / "out.csv"), "old");  // untouched until commit
    f.commit();
    EXPECT_EQ(readFileBytes(dir / "out.csv"), "new");
}

TEST(OutputFile, AbandonedOutputLeavesThePreviousFile) {
    const fs::path dir = test::outputDir("output_file_abandon");
    writeText(dir / "poses.csv", "previous run");
    fs::path temp;
    {
        OutputFile f(dir / "poses.csv", OutputOrigin::Named, OutputRule{});
        temp = f.temp();
        writeText(temp, "half");
        // No commit: an error or a crash before the end.
    }
    EXPECT_FALSE(fs::exists(temp));
    EXPECT_EQ(readFileBytes(dir / "poses.csv"), "previous run");
}

TEST(OutputFile, CreatesParentFoldersAndFailsEarlyWhenItCannot) {
    const fs::path dir = test::outputDir("output_file_parents");
    OutputFile f(dir / "a" / "b" / "x.png", OutputOrigin::Named, OutputRule{});
    EXPECT_TRUE(fs::is_directory(dir / "a" / "b"));
    EXPECT_TRUE(fs::exists(f.temp()));  // reserved before any work
    writeText(dir / "file", "");
    const std::string e =
        errorOf([&] { OutputFile g(dir / "file" / "x.png", OutputOrigin::Named, OutputRule{}); });
    EXPECT_NE(e.find("cannot create the output folder"), std::string::npos) << e;
}

TEST(OutputFile, DiskFullIsReportedNotSwallowed) {
    // /dev/full fails every write with ENOSPC, as a full disk does.
    std::ofstream s("/dev/full");
    ASSERT_TRUE(s.is_open());
    for (int i = 0; i < 100000; ++i) s << "frame,t,state\n";  // more than the stream's buffer
    const std::string e = errorOf([&] { closeChecked(s, "/dev/full"); });
    EXPECT_NE(e.find("disk full"), std::string::npos) << e;
}

}  // namespace
}  // namespace mirage
