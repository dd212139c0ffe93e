// Fault injection: writes that fail part-way, as on a full disk. A child process gets a small
// RLIMIT_FSIZE (writes beyond it fail with EFBIG, the same path as ENOSPC; SIGXFSZ ignored) and
// records a session or runs a command; what was written before must stay readable, the previous
// output must be left as it was, and the message must say that writing failed.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/session/AtomicFile.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

void limitFileSize(rlim_t bytes) {
    ::signal(SIGXFSZ, SIG_IGN);
    rlimit r{bytes, bytes};
    ::setrlimit(RLIMIT_FSIZE, &r);
}

// A distinct, smooth frame per index (JPEG keeps it well).
cv::Mat frame(int i) {
    cv::Mat m(48, 64, CV_8UC3, cv::Scalar((i * 37) % 256, 90, 200 - i % 150));
    cv::rectangle(m, cv::Rect(i % 48, 8, 16, 24), cv::Scalar(255, 255, 255), cv::FILLED);
    return m;
}

TEST(DiskFull, RecordingKeepsEveryFrameWrittenBeforeTheDiskFilled) {
    const fs::path dir = test::outputDir("disk_full_recording") / "session";
    const fs::path message = dir.parent_path() / "message.txt";
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        limitFileSize(40'000);  // the video reaches it after some frames
        int code = 2;
        try {
            Session meta;
            meta.cameras = {{"main", "", "", "main"}};
            SessionWriter w(dir, meta, {});
            for (int i = 0; i < 200; ++i) w.append({frame(i)}, {i / 30.0}, std::nullopt);
        } catch (const Error& e) {
            std::ofstream(message) << e.what();
            code = 1;
        }
        ::_exit(code);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << "the write failure was not reported";
    const std::string what = readFileBytes(message);
    EXPECT_NE(what.find("disk full"), std::string::npos) << what;
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_GE(report.framesReadable, 3);
    auto src = openCameraFrames(s, "main");
    cv::Mat f;
    int n = 0;
    while (src->read(f)) {
        ASSERT_FALSE(f.empty()) << "frame " << n << ": " << src->lastProblem();
        EXPECT_GT(test::psnr(f, frame(s.frames[size_t(n)].index), 255), 20) << n;
        ++n;
    }
    EXPECT_EQ(n, report.framesReadable);
}

TEST(DiskFull, TrackLeavesThePreviousOutputAndSaysWhy) {
    const fs::path dir = test::outputDir("disk_full_track");
    const fs::path out = dir / "poses.csv";
    std::ofstream(out) << "previous poses\n";
    // The output goes through a pipe: a log file would hit the size limit as well.
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        limitFileSize(3000);  // the poses CSV of the sample's 48 frames is ~15 KB
        ::close(fds[0]);
        ::dup2(fds[1], 1);
        ::dup2(fds[1], 2);
        const std::string session = (test::dataDir() / "sessions" / "sample").string();
        ::execl(MIRAGE_BINARY, MIRAGE_BINARY, "track", session.c_str(), "-o", out.c_str(),
                static_cast<char*>(nullptr));
        ::_exit(127);
    }
    ::close(fds[1]);
    std::string output;
    char buf[4096];
    for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) output.append(buf, size_t(n));
    ::close(fds[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << output;
    EXPECT_NE(output.find("disk full"), std::string::npos) << output;
    EXPECT_EQ(readFileBytes(out), "previous poses\n");
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos)
            << "temporary file left: " << e.path();
}

}  // namespace
}  // namespace mirage
