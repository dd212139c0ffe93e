// Sessions: round trips (MKV and PNG sequences), crash-safety (a writer killed mid-way),
// truncated and corrupt sessions, the frame count check, and FFmpeg's view of our MKV files.
#include "core/session/Session.h"

#include <sys/wait.h>
#include <unistd.h>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/Error.h"
#include "core/camera/CalibrationFile.h"
#include "core/session/AtomicFile.h"
#include "core/session/MatroskaScanner.h"
#include "core/session/MatroskaWriter.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

// Deterministic 8-bit BGR (sRGB) content that differs clearly from frame to frame: a smooth
// gradient (JPEG-friendly) with a bright square whose position and colour depend on the index.
cv::Mat syntheticFrame(int index, int width, int height, int salt = 0) {
    cv::Mat img(height, width, CV_8UC3);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            img.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar(x * 255 / width), uchar(y * 255 / height),
                                                uchar((index * 37 + salt * 91) % 256));
    const int s = std::min(width, height) / 4;
    const int x0 = (index * 13) % (width - s), y0 = (index * 7) % (height - s);
    cv::rectangle(img, cv::Rect(x0, y0, s, s),
                  cv::Scalar(255 - (index * 20) % 200, 40, 200 - (index * 30) % 150), cv::FILLED);
    return img;
}

Pose groundTruth(int i) {
    Pose p;
    p.translation = {0.1 * i, -0.02 * i, 1.5 + 0.01 * i};
    p.rotation = glm::normalize(glm::angleAxis(0.05 * i, glm::normalize(glm::dvec3(0.2, 1, 0.1))));
    return p;
}

Session twoCameras() {
    Session meta;
    meta.cameras = {{"main", "", "main.yaml", "main"}, {"env", "", "", "environment"}};
    meta.board = "";
    return meta;
}

constexpr int kMainW = 160, kMainH = 120, kEnvW = 96, kEnvH = 96;

// Writes n frames of both cameras; frame i has ground truth when i % 3 != 1.
void writeSession(const fs::path& dir, int n, bool imageSequence) {
    SessionWriter::Options o;
    o.fps = 25;
    o.imageSequence = imageSequence;
    SessionWriter w(dir, twoCameras(), o);
    for (int i = 0; i < n; ++i) {
        std::optional<Pose> gt;
        if (i % 3 != 1) gt = groundTruth(i);
        w.append({syntheticFrame(i, kMainW, kMainH), syntheticFrame(i, kEnvW, kEnvH, 1)},
                 {1000.0 + i / 25.0, 1000.004 + i / 25.0}, gt);
    }
    EXPECT_EQ(w.framesWritten(), n);
    w.close();
}

std::vector<cv::Mat> readAll(FrameSource& src) {
    std::vector<cv::Mat> out;
    cv::Mat f;
    while (src.read(f)) out.push_back(f.clone());
    return out;
}

bool contains(const SessionReadReport& r, const std::string& text) {
    for (const auto& w : r.warnings)
        if (w.find(text) != std::string::npos) return true;
    return false;
}

std::string allWarnings(const SessionReadReport& r) {
    std::string s;
    for (const auto& w : r.warnings) s += "  " + w + "\n";
    return s;
}

// Each decoded frame must match its own original far better than the neighbouring frame
// (proves order and content; JPEG tolerance).
void expectFramesMatch(const std::vector<cv::Mat>& got, const std::vector<int>& indices, int w,
                       int h, int salt, double minPsnr) {
    ASSERT_EQ(got.size(), indices.size());
    for (size_t k = 0; k < got.size(); ++k) {
        ASSERT_EQ(got[k].size(), cv::Size(w, h));
        ASSERT_EQ(got[k].type(), CV_8UC3);
        const double own = test::psnr(got[k], syntheticFrame(indices[k], w, h, salt), 255);
        const double other = test::psnr(got[k], syntheticFrame(indices[k] + 1, w, h, salt), 255);
        EXPECT_GT(own, minPsnr) << "frame " << indices[k];
        EXPECT_LT(other, own - 8) << "frame " << indices[k] << " looks like its neighbour";
    }
}

TEST(Session, MkvRoundTrip) {
    const fs::path dir = test::outputDir("session_roundtrip_mkv");
    writeSession(dir, 12, false);
    EXPECT_TRUE(fs::exists(dir / "main.mkv"));
    EXPECT_TRUE(fs::exists(dir / "env.mkv"));

    SessionReadReport report;
    // main.yaml does not exist: a warning, the footage is still read.
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.warnings.size(), 1u) << allWarnings(report);
    EXPECT_TRUE(contains(report, "main.yaml"));
    EXPECT_EQ(report.framesListed, 12);
    EXPECT_EQ(report.framesReadable, 12);
    EXPECT_DOUBLE_EQ(s.fps, 25.0);
    ASSERT_EQ(s.cameras.size(), 2u);
    EXPECT_EQ(s.cameras[1].name, "env");
    EXPECT_EQ(s.cameras[1].role, "environment");
    EXPECT_EQ(s.cameras[0].video, "main.mkv");
    ASSERT_EQ(s.frames.size(), 12u);
    for (int i = 0; i < 12; ++i) {
        const FrameRecord& r = s.frames[size_t(i)];
        EXPECT_EQ(r.index, i);
        ASSERT_EQ(r.timestamps.size(), 2u);
        EXPECT_DOUBLE_EQ(r.timestamps[0], 1000.0 + i / 25.0);  // exact: shortest round-trip form
        EXPECT_DOUBLE_EQ(r.timestamps[1], 1000.004 + i / 25.0);
        ASSERT_EQ(r.groundTruth.has_value(), i % 3 != 1);
        if (r.groundTruth) {
            EXPECT_EQ(r.groundTruth->translation, groundTruth(i).translation);
            EXPECT_LT(rotationAngleBetween(r.groundTruth->rotation, groundTruth(i).rotation), 1e-7);
        }
    }

    auto main = openCameraFrames(s, "main");
    EXPECT_EQ(main->frameCount(), 12);
    const auto frames = readAll(*main);
    std::vector<int> idx(12);
    for (int i = 0; i < 12; ++i) idx[size_t(i)] = i;
    expectFramesMatch(frames, idx, kMainW, kMainH, 0, 28.0);
    ASSERT_TRUE(main->lastTimestamp().has_value());
    EXPECT_DOUBLE_EQ(*main->lastTimestamp(), 1000.0 + 11 / 25.0);
    auto env = openCameraFrames(s, "env");
    expectFramesMatch(readAll(*env), idx, kEnvW, kEnvH, 1, 28.0);
    EXPECT_THROW(openCameraFrames(s, "nope"), FileError);
    // Calibration through the session: missing file, no file named, then a real one.
    EXPECT_THROW(loadSessionCalibration(s, "main"), FileError);
    EXPECT_THROW(loadSessionCalibration(s, "env"), FileError);
    EXPECT_THROW(loadSessionCalibration(s, "nope"), FileError);
    fs::copy_file(test::testDataDir() / "calib" / "opencv_sample_style.yaml", dir / "main.yaml");
    EXPECT_EQ(loadSessionCalibration(s, "main").intrinsics.width, 640);

    // The plain-video path reads the same file, with FFmpeg's frame times (ms ticks).
    auto plain = openFrames(dir / "main.mkv");
    EXPECT_EQ(plain->frameCount(), 12);
    expectFramesMatch(readAll(*plain), idx, kMainW, kMainH, 0, 28.0);
    EXPECT_NEAR(*plain->lastTimestamp(), 11 / 25.0, 0.0015);
}

TEST(Session, ComparisonCatchesWrongFrames) {
    // The checks above can fail: a shuffled sequence is caught.
    std::vector<cv::Mat> frames = {syntheticFrame(1, kMainW, kMainH),
                                   syntheticFrame(0, kMainW, kMainH)};
    EXPECT_LT(test::psnr(frames[0], syntheticFrame(0, kMainW, kMainH), 255), 22.0);
}

TEST(Session, ImageSequenceRoundTripIsLossless) {
    const fs::path dir = test::outputDir("session_roundtrip_png");
    writeSession(dir, 5, true);
    EXPECT_TRUE(fs::exists(dir / "main" / "000004.png"));
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.framesReadable, 5);
    auto env = openCameraFrames(s, "env");
    const auto frames = readAll(*env);
    ASSERT_EQ(frames.size(), 5u);
    for (int i = 0; i < 5; ++i)
        EXPECT_TRUE(
            std::isinf(test::psnr(frames[size_t(i)], syntheticFrame(i, kEnvW, kEnvH, 1), 255)));

    // A deleted image drops its row (and only it).
    fs::remove(dir / "main" / "000002.png");
    const Session s2 = readSession(dir, &report);
    EXPECT_EQ(report.framesListed, 5);
    EXPECT_EQ(report.framesReadable, 4);
    EXPECT_TRUE(contains(report, "1 of 5 listed frames are not in main")) << allWarnings(report);
    auto main = openCameraFrames(s2, "main");
    expectFramesMatch(readAll(*main), {0, 1, 3, 4}, kMainW, kMainH, 0, 99.0);
}

TEST(Session, FsyncEachFrameWritesTheSameSession) {
    for (const bool sequence : {false, true}) {
        const fs::path dir =
            test::outputDir(std::string("session_fsync_") + (sequence ? "png" : "mkv"));
        SessionWriter::Options o;
        o.fsyncEachFrame = true;
        o.imageSequence = sequence;
        Session meta;
        meta.board = "";
        SessionWriter w(dir, meta, o);
        for (int i = 0; i < 3; ++i) w.append({syntheticFrame(i, kMainW, kMainH)}, {}, std::nullopt);
        w.close();
        SessionReadReport report;
        const Session s = readSession(dir, &report);
        EXPECT_TRUE(report.ok()) << allWarnings(report);
        expectFramesMatch(readAll(*openCameraFrames(s, "main")), {0, 1, 2}, kMainW, kMainH, 0,
                          sequence ? 99.0 : 28.0);
    }
}

TEST(Session, WriterNeverOverwritesASession) {
    const fs::path dir = test::outputDir("session_no_overwrite");
    writeSession(dir, 1, false);
    EXPECT_THROW(SessionWriter(dir, Session{}, {}), FileError);
}

TEST(Session, WriterRejectsBadInput) {
    const fs::path dir = test::outputDir("session_bad_input");
    SessionWriter w(dir, twoCameras(), {});
    EXPECT_THROW(w.append({syntheticFrame(0, 32, 32)}, {}, std::nullopt), Error);  // 1 of 2
    EXPECT_THROW(w.append({cv::Mat(32, 32, CV_32FC3), cv::Mat(8, 8, CV_8UC3)}, {}, std::nullopt),
                 Error);
    Pose nanPose;
    nanPose.translation.x = std::nan("");
    EXPECT_THROW(w.append({syntheticFrame(0, 32, 32), syntheticFrame(0, 32, 32)}, {}, nanPose),
                 Error);
    w.append({syntheticFrame(0, 32, 32), syntheticFrame(0, 32, 32)}, {}, std::nullopt);
    // A frame of another size cannot join the same video.
    EXPECT_THROW(w.append({syntheticFrame(1, 64, 32), syntheticFrame(1, 32, 32)}, {}, std::nullopt),
                 FileError);
}

// Child process: writes frames forever, reporting each completed append on `fd`. Never returns.
[[noreturn]] void writeUntilKilled(const fs::path& dir, int fd, int stopAfter) {
    try {
        SessionWriter::Options o;
        o.fps = 30;
        Session meta;
        meta.board = "";  // no board: a warning-free session
        SessionWriter w(dir, meta, o);
        for (int i = 0;; ++i) {
            if (stopAfter >= 0 && i == stopAfter) _exit(0);  // no close(), no destructors
            w.append({syntheticFrame(i, 192, 144)}, {i / 30.0}, groundTruth(i));
            const int done = i + 1;
            if (::write(fd, &done, sizeof done) != sizeof done) _exit(3);
        }
    } catch (...) {
        _exit(2);
    }
}

// Forks a writer, waits until it has completed `minFrames` frames (plus `extraMicros`), then
// SIGKILLs it (or lets it _exit after `stopAfter` frames). Returns the completed count seen.
int runAndKill(const fs::path& dir, int minFrames, int extraMicros, int stopAfter = -1) {
    int pipeFd[2];
    if (::pipe(pipeFd) != 0) return -1;
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(pipeFd[0]);
        writeUntilKilled(dir, pipeFd[1], stopAfter);
    }
    ::close(pipeFd[1]);
    int done = 0, v = 0;
    while (done < minFrames && ::read(pipeFd[0], &v, sizeof v) == sizeof v) done = v;
    if (stopAfter < 0) {
        ::usleep(useconds_t(extraMicros));
        ::kill(pid, SIGKILL);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    while (::read(pipeFd[0], &v, sizeof v) == sizeof v) done = v;  // reports sent before death
    ::close(pipeFd[0]);
    if (stopAfter >= 0)
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    else
        EXPECT_TRUE(WIFSIGNALED(status));
    return done;
}

void expectEveryRowDecodable(const fs::path& dir, int completed) {
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    SCOPED_TRACE(allWarnings(report));
    EXPECT_GE(report.framesReadable, completed);
    // At most the frame being written when the process died can be complete without its row.
    EXPECT_LE(report.framesReadable, completed + 1);
    EXPECT_EQ(report.framesReadable, report.framesListed);
    auto src = openCameraFrames(s, "main");
    const auto frames = readAll(*src);
    std::vector<int> idx;
    for (const auto& r : s.frames) idx.push_back(r.index);
    expectFramesMatch(frames, idx, 192, 144, 0, 28.0);
    for (const auto& r : s.frames) {
        ASSERT_TRUE(r.groundTruth.has_value());
        EXPECT_EQ(r.groundTruth->translation, groundTruth(r.index).translation);
    }
}

TEST(SessionCrashSafety, SigkillMidRecording) {
    // Different delays after the reported frame land the kill at different points of the next
    // frame's writes (JPEG encoding, cluster write, row write).
    const int delays[] = {0, 300, 1500, 4000};
    for (int trial = 0; trial < 4; ++trial) {
        const fs::path dir = test::outputDir("session_crash_" + std::to_string(trial));
        const int completed = runAndKill(dir, 6 + trial, delays[trial]);
        SCOPED_TRACE("trial " + std::to_string(trial) + ", completed " + std::to_string(completed));
        ASSERT_GE(completed, 6 + trial);
        expectEveryRowDecodable(dir, completed);
    }
}

TEST(SessionCrashSafety, EveryPrefixOfTheVideoIsReadable) {
    // The muxer only appends, so whatever a crash leaves is a prefix of the unclosed file.
    // Check every prefix: the scanner counts exactly the clusters that are complete, and
    // FFmpeg (through the frame source) decodes exactly those, each to the right image.
    const fs::path dir = test::outputDir("matroska_prefixes");
    std::vector<size_t> sizeAfter;  // file size after each completed frame
    std::string full;
    {
        MatroskaWriter w(dir / "full.mkv", 30, 90);
        for (int i = 0; i < 4; ++i) {
            w.append(syntheticFrame(i, 48, 32), i / 30.0);
            full = readFileBytes(dir / "full.mkv");
            sizeAfter.push_back(full.size());
        }
        std::ofstream(dir / "unclosed.mkv", std::ios::binary) << full;
    }  // close() patches sizes in full.mkv; unclosed.mkv is the crash state
    const fs::path cut = dir / "cut.mkv";
    int decodeChecks = 0;
    for (size_t len = 0; len <= full.size(); ++len) {
        int expected = 0;
        while (expected < 4 && sizeAfter[size_t(expected)] <= len) ++expected;
        MatroskaScan scan;
        try {
            std::istringstream prefix(full.substr(0, len));
            scan = scanMatroska(prefix, len, "prefix");
        } catch (const FileError&) {
            // Only a prefix shorter than the EBML header may be "not Matroska".
            EXPECT_LT(len, 40u);
            continue;
        }
        ASSERT_EQ(scan.completeFrames, expected) << "prefix of " << len << " bytes";
        // Cut inside a frame's cluster: reported as truncated; cut at a frame boundary: not.
        if (len >= sizeAfter[0]) {
            const bool atBoundary =
                std::find(sizeAfter.begin(), sizeAfter.end(), len) != sizeAfter.end();
            EXPECT_EQ(scan.truncated, !atBoundary) << "prefix of " << len;
        }
        // Decode at every frame boundary, just before and after it, and every 401 bytes.
        bool near = len % 401 == 0;
        for (size_t b : sizeAfter) near = near || (len + 1 >= b && len <= b + 1);
        if (!near || expected == 0) continue;
        ++decodeChecks;
        std::ofstream(cut, std::ios::binary | std::ios::trunc) << full.substr(0, len);
        auto src = openFrames(cut);
        const auto frames = readAll(*src);
        std::vector<int> idx;
        for (int i = 0; i < expected; ++i) idx.push_back(i);
        expectFramesMatch(frames, idx, 48, 32, 0, 26.0);
    }
    EXPECT_GT(decodeChecks, 10);
}

TEST(SessionCrashSafety, ExitWithoutClose) {
    const fs::path dir = test::outputDir("session_exit_without_close");
    const int completed = runAndKill(dir, 0, 0, 7);
    EXPECT_EQ(completed, 7);
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.framesReadable, 7) << allWarnings(report);
    EXPECT_TRUE(report.ok()) << allWarnings(report);  // unknown-size Segment is valid Matroska
    expectEveryRowDecodable(dir, 7);
}

TEST(SessionCrashSafety, KilledBeforeFirstFrame) {
    const fs::path dir = test::outputDir("session_killed_early");
    runAndKill(dir, 0, 0, 0);
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.framesReadable, 0);
    EXPECT_TRUE(s.frames.empty());
    EXPECT_TRUE(contains(report, "empty")) << allWarnings(report);
}

TEST(SessionCorrupt, VideoCutInTheMiddle) {
    const fs::path dir = test::outputDir("session_cut_video");
    writeSession(dir, 10, false);
    const auto size = fs::file_size(dir / "main.mkv");
    fs::resize_file(dir / "main.mkv", size * 55 / 100);
    const MatroskaScan scan = scanMatroska(dir / "main.mkv");
    EXPECT_TRUE(scan.truncated);
    EXPECT_GT(scan.completeFrames, 2);
    EXPECT_LT(scan.completeFrames, 10);

    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.framesListed, 10);
    EXPECT_EQ(report.framesReadable, scan.completeFrames);
    EXPECT_TRUE(contains(report, "ends in the middle")) << allWarnings(report);
    EXPECT_TRUE(contains(report, "rows are dropped")) << allWarnings(report);
    std::vector<int> idx;
    for (int i = 0; i < scan.completeFrames; ++i) idx.push_back(i);
    expectFramesMatch(readAll(*openCameraFrames(s, "main")), idx, kMainW, kMainH, 0, 28.0);
    // The plain-video reader stops at the last complete frame as well.
    EXPECT_EQ(readAll(*openFrames(dir / "main.mkv")).size(), size_t(scan.completeFrames));
}

void rewriteCsv(const fs::path& csv, const std::function<void(std::vector<std::string>&)>& edit) {
    std::vector<std::string> lines;
    {
        std::ifstream in(csv);
        for (std::string l; std::getline(in, l);) lines.push_back(l);
    }
    edit(lines);
    std::string text;
    for (const auto& l : lines) text += l + "\n";
    writeFileAtomically(csv, text);
}

TEST(SessionCorrupt, DeletedRowsSkipTheirFrames) {
    const fs::path dir = test::outputDir("session_deleted_rows");
    writeSession(dir, 8, false);
    // Rows are line 1 + index; delete frames 3 and 4 and the last one (7).
    rewriteCsv(dir / "frames.csv", [](auto& l) {
        l.erase(l.begin() + 8);
        l.erase(l.begin() + 4, l.begin() + 6);
    });
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.framesReadable, 5);
    // Frame count check: the video holds more frames than frames.csv lists.
    EXPECT_TRUE(contains(report, "holds 8 frames but frames.csv ends at frame 6"))
        << allWarnings(report);
    expectFramesMatch(readAll(*openCameraFrames(s, "main")), {0, 1, 2, 5, 6}, kMainW, kMainH, 0,
                      28.0);
    expectFramesMatch(readAll(*openCameraFrames(s, "env")), {0, 1, 2, 5, 6}, kEnvW, kEnvH, 1, 28.0);
}

TEST(SessionCorrupt, LargestFrameNumberIsDroppedWithoutOverflow) {
    // Found by session_fuzz under UBSan: a last row numbered INT_MAX overflowed "last + 1".
    const fs::path dir = test::outputDir("session_frame_int_max");
    writeSession(dir, 3, false);
    rewriteCsv(dir / "frames.csv", [](auto& l) {
        std::string row = l.back();
        l.push_back("2147483647" + row.substr(row.find(',')));
    });
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.framesListed, 4);
    EXPECT_EQ(report.framesReadable, 3) << allWarnings(report);
    EXPECT_TRUE(contains(report, "first: frame 2147483647")) << allWarnings(report);
}

TEST(SessionCorrupt, BadRowsAreReportedAndSkipped) {
    const fs::path dir = test::outputDir("session_bad_rows");
    writeSession(dir, 8, false);
    rewriteCsv(dir / "frames.csv", [](auto& l) {
        l[2] = "1,abc,1.0,,,,,,,";         // bad time
        l[3] = "2,1.0,1.0";                // too few fields
        l[4] = "3,1.0,1.0,0,0,0,2,0,0,0";  // quaternion norm 2
        l[5] = "# a comment line is fine";
        l.push_back("9,1.0,1.");  // cut-short last row
    });
    // Remove the final newline so that the last row looks like an interrupted write.
    std::string text = readFileBytes(dir / "frames.csv");
    text.pop_back();
    writeFileAtomically(dir / "frames.csv", text);

    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(report.framesListed, 4);  // frames 0, 5, 6, 7
    EXPECT_EQ(report.framesReadable, 4);
    EXPECT_TRUE(contains(report, "frames.csv line 3: t_main 'abc'")) << allWarnings(report);
    EXPECT_TRUE(contains(report, "line 4: has 3 fields")) << allWarnings(report);
    EXPECT_TRUE(contains(report, "norm 2")) << allWarnings(report);
    EXPECT_TRUE(contains(report, "cut short")) << allWarnings(report);
    expectFramesMatch(readAll(*openCameraFrames(s, "main")), {0, 5, 6, 7}, kMainW, kMainH, 0, 28.0);
}

TEST(SessionCorrupt, MissingFramesCsvFallsBackToTheVideo) {
    const fs::path dir = test::outputDir("session_no_csv");
    writeSession(dir, 4, false);
    fs::remove(dir / "frames.csv");
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_TRUE(contains(report, "frames.csv is missing")) << allWarnings(report);
    ASSERT_EQ(s.frames.size(), 4u);
    EXPECT_DOUBLE_EQ(s.frames[3].timestamps[0], 3 / 25.0);
    EXPECT_FALSE(s.frames[3].groundTruth.has_value());
}

TEST(SessionCorrupt, FramesCsvWithoutHeaderFallsBackToTheVideo) {
    const fs::path dir = test::outputDir("session_empty_csv");
    writeSession(dir, 3, false);
    std::ofstream(dir / "frames.csv", std::ios::trunc);  // crash before the header was written
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_TRUE(contains(report, "no header line")) << allWarnings(report);
    EXPECT_EQ(s.frames.size(), 3u);
}

TEST(SessionCorrupt, MissingVideoKeepsTheSessionReadable) {
    const fs::path dir = test::outputDir("session_no_env");
    writeSession(dir, 4, false);
    fs::remove(dir / "env.mkv");
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_TRUE(contains(report, "env.mkv")) << allWarnings(report);
    EXPECT_EQ(report.framesListed, 4);
    EXPECT_EQ(report.framesReadable, 0);
}

std::string readError(const fs::path& dir) {
    try {
        readSession(dir);
    } catch (const FileError& e) {
        return e.what();
    }
    ADD_FAILURE() << dir << " was read although it is not a valid session";
    return {};
}

TEST(SessionCorrupt, SessionJsonErrorsAreClear) {
    const fs::path dir = test::outputDir("session_bad_json");
    writeSession(dir, 2, false);
    const std::string good = readFileBytes(dir / "session.json");
    auto with = [&](const std::string& text) {
        writeFileAtomically(dir / "session.json", text);
        return readError(dir);
    };
    EXPECT_NE(with("{ \"format\": \"mirage-session\", garbage").find("not valid JSON"),
              std::string::npos);
    EXPECT_NE(with("[1, 2]").find("JSON object"), std::string::npos);
    // Found by session_fuzz: a number beyond a double made the JSON library throw out_of_range.
    std::string s = good;
    s.replace(s.find("\"fps\": "), 7, "\"fps\": 1e999, \"x\": ");
    EXPECT_NE(with(s).find("not valid JSON"), std::string::npos);
    s = good;
    s.replace(s.find("mirage-session"), 14, "something-else");
    EXPECT_NE(with(s).find("field 'format'"), std::string::npos);
    s = good;
    s.replace(s.find("\"version\": 1"), 12, "\"version\": 99");
    EXPECT_NE(with(s).find("newer"), std::string::npos);
    s = good;
    s.replace(s.find("\"video\": \"env.mkv\""), 18, "\"video\": 5");
    EXPECT_NE(with(s).find("cameras[1].video"), std::string::npos);
    s = good;
    s.replace(s.find("\"video\": \"env.mkv\""), 18, "\"video\": \"../env.mkv\"");
    EXPECT_NE(with(s).find("inside the session folder"), std::string::npos);
    EXPECT_NE(
        with("{\"format\": \"mirage-session\", \"version\": 1, \"cameras\": []}").find("cameras"),
        std::string::npos);
    fs::remove(dir / "session.json");
    EXPECT_NE(readError(dir).find("not a mirage session"), std::string::npos);
    EXPECT_NE(readError(dir / "nonexistent").find("not a folder"), std::string::npos);
}

TEST(SessionCorrupt, TwoMainCamerasAndOutsideFilesAreRefused) {
    const fs::path dir = test::outputDir("session_two_mains");
    writeSession(dir, 2, false);
    const std::string good = readFileBytes(dir / "session.json");
    auto with = [&](const std::string& from, const std::string& to) {
        std::string s = good;
        s.replace(s.find(from), from.size(), to);
        writeFileAtomically(dir / "session.json", s);
        return readError(dir);
    };
    // Taken silently before: the second "main" camera was read as an environment camera.
    std::string e = with("\"role\": \"environment\"", "\"role\": \"main\"");
    EXPECT_NE(e.find("cameras[1].role"), std::string::npos) << e;
    EXPECT_NE(e.find("a session has one"), std::string::npos) << e;
    // Files named by the session stay inside it, after normalisation too.
    for (const char* outside : {"/etc/passwd", "sub/../../x.mkv", "file:///etc/passwd"}) {
        e = with("\"video\": \"env.mkv\"", std::string("\"video\": \"") + outside + "\"");
        EXPECT_NE(e.find("cameras[1].video"), std::string::npos) << e;
        EXPECT_NE(e.find(outside), std::string::npos) << e;
    }
    e = with("\"video\": \"env.mkv\"", "\"video\": \"\"");
    EXPECT_NE(e.find("cameras[1].video"), std::string::npos) << e;
}

TEST(SessionCorrupt, TimestampsGoingBackwardsAreReportedAndSkipped) {
    const fs::path dir = test::outputDir("session_time_backwards");
    writeSession(dir, 6, false);
    // Row 4 (frame 3) gets a main-camera time before frame 2's: a spliced or damaged file.
    rewriteCsv(dir / "frames.csv", [](std::vector<std::string>& lines) {
        std::string& row = lines[4];
        const size_t comma = row.find(',');
        row = row.substr(0, comma) + ",999.5" + row.substr(row.find(',', comma + 1));
    });
    SessionReadReport report;
    const Session s = readSession(dir, &report);
    EXPECT_EQ(s.frames.size(), 5u);
    EXPECT_TRUE(contains(report, "frames.csv line 5: t_main 999.5 goes back in time"))
        << allWarnings(report);
}

TEST(SessionCorrupt, RandomDamageNeverCrashes) {
    // Flipped bytes, cut files and garbage rows: readers report and keep going, never crash,
    // never loop, never claim more frames than were written.
    const fs::path dir = test::outputDir("session_random_damage");
    writeSession(dir, 6, false);
    const std::string mkv = readFileBytes(dir / "main.mkv");
    const std::string csv = readFileBytes(dir / "frames.csv");
    cv::RNG rng(12345);
    for (int trial = 0; trial < 150; ++trial) {
        std::string damaged = mkv;
        const int flips = 1 + rng.uniform(0, 8);
        for (int k = 0; k < flips; ++k)
            damaged[size_t(rng.uniform(0, int(damaged.size())))] = char(rng.uniform(0, 256));
        if (trial % 3 == 0) damaged.resize(size_t(rng.uniform(0, int(damaged.size()))));
        std::ofstream(dir / "main.mkv", std::ios::binary) << damaged;  // no fsync: fast
        try {
            const MatroskaScan scan = scanMatroska(dir / "main.mkv");
            EXPECT_LE(scan.completeFrames, 6) << "trial " << trial;
        } catch (const FileError&) {
            // Damaged EBML header: "not a Matroska file" is the right answer.
        }
        std::string rows = csv;
        for (int k = 0; k < 3; ++k)
            rows[size_t(rng.uniform(0, int(rows.size())))] = "0,.-e\n#x9"[rng.uniform(0, 9)];
        std::ofstream(dir / "frames.csv", std::ios::binary) << rows;
        SessionReadReport report;
        const Session s = readSession(dir, &report);
        EXPECT_LE(report.framesReadable, 6);
        if (trial % 25 == 0) {
            // Decoding damaged JPEG data must not crash either (FFmpeg conceals errors).
            auto src = openCameraFrames(s, "main");
            cv::Mat f;
            int n = 0;
            while (src->read(f)) ++n;
            EXPECT_LE(n, report.framesReadable);
        }
    }
}

TEST(Matroska, ScannerCountsFfmpegWrittenFiles) {
    // A file from another muxer (FFmpeg through OpenCV) is scanned the same way.
    const fs::path dir = test::outputDir("matroska_ffmpeg");
    const fs::path path = dir / "ffmpeg.mkv";
    {
        cv::VideoWriter vw(path.string(), cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25, cv::Size(64, 48));
        if (!vw.isOpened()) GTEST_SKIP() << "OpenCV cannot write MKV through FFmpeg here";
        for (int i = 0; i < 9; ++i) vw.write(syntheticFrame(i, 64, 48));
    }
    const MatroskaScan scan = scanMatroska(path);
    EXPECT_EQ(scan.completeFrames, 9);
    EXPECT_FALSE(scan.truncated);
    EXPECT_EQ(scan.width, 64);
    EXPECT_EQ(scan.codecId, "V_MJPEG");
    EXPECT_THROW(scanMatroska(dir / "missing.mkv"), FileError);
    writeFileAtomically(dir / "text.mkv", "this is not matroska");
    EXPECT_THROW(scanMatroska(dir / "text.mkv"), FileError);
}

std::string run(const std::string& cmd) {
    std::string out;
    FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return out;
    char buf[256];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    ::pclose(p);
    return out;
}

TEST(Matroska, FfprobeReadsOurFiles) {
    if (std::system("ffprobe -version > /dev/null 2>&1") != 0) GTEST_SKIP() << "no ffprobe";
    const fs::path dir = test::outputDir("matroska_ffprobe");
    writeSession(dir, 6, false);
    const std::string probe =
        "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
        "stream=codec_name,width,height,nb_read_frames -of csv=p=0 ";
    EXPECT_EQ(run(probe + (dir / "main.mkv").string()), "mjpeg,160,120,6\n");
    // The duration patched in by close(): 6 frames at 25 fps = last frame at 0.2 s + 0.04 s.
    const std::string duration = run("ffprobe -v error -show_entries format=duration -of csv=p=0 " +
                                     (dir / "main.mkv").string());
    EXPECT_NEAR(std::atof(duration.c_str()), 0.24, 0.002) << duration;
    // FFmpeg decodes every frame without complaint (an error would be printed).
    EXPECT_EQ(run("ffmpeg -v error -i " + (dir / "env.mkv").string() + " -f null - 2>&1"), "");

    // A file from a killed writer: FFmpeg reads every completed frame.
    const fs::path crashed = test::outputDir("matroska_ffprobe_crash");
    const int completed = runAndKill(crashed, 5, 700);
    const int counted =
        std::atoi(run("ffprobe -v quiet -count_frames -select_streams v:0 -show_entries "
                      "stream=nb_read_frames -of csv=p=0 " +
                      (crashed / "main.mkv").string())
                      .c_str());
    EXPECT_GE(counted, completed);
}

}  // namespace
}  // namespace mirage
