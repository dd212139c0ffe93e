// Output safety (core/OutputFile.h): an output is never an input, an unnamed existing file is
// never replaced without --force, and a failed write leaves the previous file as it was.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <thread>

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

TEST(OutputFile, ADeviceOrSocketIsRefusedNeverReplaced) {
    for (const char* dev : {"/dev/null", "/dev/full"}) {
        const std::string e = errorOf([&] {
            OutputFile f(dev, OutputOrigin::Named, OutputRule{{}, true, "test"});
        });
        EXPECT_NE(e.find("is a character device"), std::string::npos) << e;
        EXPECT_TRUE(fs::is_character_file(dev));
    }
    const fs::path dir = test::outputDir("output_file_device");
    writeText(dir / "file", "x");
    // A file where a folder is meant, a FIFO where a folder is meant.
    EXPECT_NE(errorOf([&] { outputTarget(dir / "file", "test", true); }).find("is a file"),
              std::string::npos);
    ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0644), 0);
    EXPECT_NE(errorOf([&] { outputTarget(dir / "fifo", "test", true); }).find("FIFO"),
              std::string::npos);
    EXPECT_EQ(outputTarget(dir / "fifo", "test"), OutputTarget::WriteThrough);
    EXPECT_EQ(outputTarget(dir / "new", "test"), OutputTarget::New);
    EXPECT_EQ(outputTarget(dir / "file", "test"), OutputTarget::RegularFile);
    EXPECT_EQ(outputTarget(dir, "test", true), OutputTarget::Folder);
}

TEST(OutputFile, AFifoIsWrittenThroughAndStaysAFifo) {
    const fs::path dir = test::outputDir("output_file_fifo");
    const fs::path fifo = dir / "out.csv";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
    std::string received;
    std::thread reader([&] {
        std::ifstream in(fifo, std::ios::binary);
        received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    });
    {
        OutputFile out(fifo, OutputOrigin::Named, OutputRule{{}, false, "test"});
        EXPECT_TRUE(out.writesThrough());
        EXPECT_NE(out.temp().parent_path(), dir) << "no temporary beside a FIFO";
        writeText(out.temp(), "frame,t\n0,0\n");
        out.commit();
        EXPECT_FALSE(fs::exists(out.temp()));
    }
    reader.join();
    EXPECT_EQ(received, "frame,t\n0,0\n");
    EXPECT_TRUE(fs::is_fifo(fifo));
}

TEST(OutputFile, StandardOutputRedirectedToAFileIsAppendedNotReplaced) {
    // /proc/self/fd/N reaches the file a shell redirected: renaming over the link would leave
    // the file untouched and replace the link; the bytes must go into the file.
    const fs::path dir = test::outputDir("output_file_fd");
    writeText(dir / "redirected.csv", "before\n");
    const int fd = ::open((dir / "redirected.csv").c_str(), O_WRONLY | O_APPEND);
    ASSERT_GE(fd, 0);
    const fs::path link = "/proc/self/fd/" + std::to_string(fd);
    {
        OutputFile out(link, OutputOrigin::Named, OutputRule{{}, false, "test"});
        EXPECT_TRUE(out.writesThrough());
        writeText(out.temp(), "after\n");
        out.commit();
    }
    ::close(fd);
    EXPECT_EQ(readFileBytes(dir / "redirected.csv"), "before\nafter\n");
}

TEST(OutputFile, ASignalRemovesTheTemporaries) {
    const fs::path dir = test::outputDir("output_file_signal");
    for (int sig : {SIGINT, SIGTERM}) {
        const pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            std::signal(sig, SIG_DFL);
            OutputFile f(dir / "image.png", OutputOrigin::Named, OutputRule{});
            writeText(f.temp(), "half an image");
            StagedPath staged(dir / "session");
            fs::create_directories(staged.temp() / "frames");
            writeText(staged.temp() / "frames" / "000001.png", "x");
            ::raise(sig);
            ::_exit(0);  // not reached: the signal ends the process
        }
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status;
        for (const auto& e : fs::directory_iterator(dir))
            ADD_FAILURE() << "left behind: " << e.path();
    }
}

TEST(OutputFile, TemporariesOfADeadProcessAreRemovedByTheNextWriter) {
    const fs::path dir = test::outputDir("output_file_stale");
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) ::_exit(0);
    ::waitpid(pid, nullptr, 0);  // `pid` now names no process
    const std::string stale = "image.partial-" + std::to_string(pid) + ".png";
    writeText(dir / stale, "left by kill -9");
    writeText(dir / "image.partial-1.png", "pid 1 runs: not ours to remove");
    writeText(dir / ("other.partial-" + std::to_string(pid) + ".png"), "another output's");
    OutputFile f(dir / "image.png", OutputOrigin::Named, OutputRule{});
    EXPECT_FALSE(fs::exists(dir / stale));
    EXPECT_TRUE(fs::exists(dir / "image.partial-1.png"));
    EXPECT_TRUE(fs::exists(dir / ("other.partial-" + std::to_string(pid) + ".png")));
    EXPECT_TRUE(isPartialOutputName(dir / stale));
    EXPECT_FALSE(isPartialOutputName(dir / "image.png"));
}

}  // namespace
}  // namespace mirage
