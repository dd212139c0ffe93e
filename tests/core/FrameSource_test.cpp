// Frame sources outside a session: a list of image files, folders and videos as one stream
// (calibration inputs), its video sampling, frame names and errors.
#include "core/session/FrameSource.h"

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/Error.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

// A frame whose mean grey level encodes its index (survives JPEG coding).
cv::Mat frameOf(int index) {
    return cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(20 + 20 * index));
}
int indexOf(const cv::Mat& bgr) {
    return int(std::lround((cv::mean(bgr)[0] - 20) / 20));
}

// A folder with: a.png (index 9), images/frame_2.png and images/frame_10.png (indices 2, 10:
// numeric, not name, order), and video.mkv, a 10-frame MJPEG recording (indices 0..9).
fs::path makeInputs(const std::string& name) {
    const fs::path dir = test::outputDir(name);
    cv::imwrite((dir / "a.png").string(), frameOf(9));
    fs::create_directories(dir / "images");
    cv::imwrite((dir / "images" / "frame_10.png").string(), frameOf(10));
    cv::imwrite((dir / "images" / "frame_2.png").string(), frameOf(2));
    Session meta;
    meta.cameras = {{"main", "", "", "main"}};
    SessionWriter::Options o;
    o.fps = 10;
    SessionWriter w(dir / "session", meta, o);
    for (int i = 0; i < 10; ++i) w.append({frameOf(i)}, {i / 10.0}, std::nullopt);
    w.close();
    fs::copy_file(dir / "session" / "main.mkv", dir / "video.mkv",
                  fs::copy_options::overwrite_existing);
    return dir;
}

struct Read {
    std::vector<std::string> names;
    std::vector<int> indices;
    std::vector<bool> timed;
};

Read readAll(FrameSource& s) {
    Read r;
    cv::Mat bgr;
    while (s.read(bgr)) {
        EXPECT_EQ(bgr.type(), CV_8UC3);
        r.names.push_back(s.lastName());
        r.indices.push_back(indexOf(bgr));
        r.timed.push_back(s.lastTimestamp().has_value());
    }
    return r;
}

TEST(FrameList, ImagesFoldersAndASampledVideoAsOneStream) {
    const fs::path dir = makeInputs("framelist_stream");
    FrameListOptions o;
    o.videoStep = 4;
    auto s = openFrameList(
        {(dir / "a.png").string(), (dir / "images").string(), (dir / "video.mkv").string()}, o);
    EXPECT_EQ(s->frameCount(), -1);  // a video's sampled count is not known before reading
    const Read r = readAll(*s);
    EXPECT_EQ(r.names, (std::vector<std::string>{"a.png", "frame_2.png", "frame_10.png",
                                                 "video.mkv#0", "video.mkv#4", "video.mkv#8"}));
    EXPECT_EQ(r.indices, (std::vector<int>{9, 2, 10, 0, 4, 8}));
    EXPECT_EQ(r.timed, (std::vector<bool>{false, false, false, true, true, true}));
}

TEST(FrameList, VideoStepFollowsMaxVideoFramesOrAllFrames) {
    const fs::path dir = makeInputs("framelist_step");
    const std::vector<std::string> video = {(dir / "video.mkv").string()};
    FrameListOptions o;
    o.maxVideoFrames = 4;  // 10 frames: every 3rd
    EXPECT_EQ(readAll(*openFrameList(video, o)).indices, (std::vector<int>{0, 3, 6, 9}));
    o.allVideoFrames = true;
    o.videoStep = 5;  // overridden
    EXPECT_EQ(readAll(*openFrameList(video, o)).indices.size(), 10u);
}

TEST(FrameList, ImagesOnlyKnowTheirCount) {
    const fs::path dir = makeInputs("framelist_count");
    auto s = openFrameList({(dir / "images").string(), (dir / "a.png").string()}, {});
    EXPECT_EQ(s->frameCount(), 3);
    EXPECT_EQ(readAll(*s).indices, (std::vector<int>{2, 10, 9}));
}

TEST(FrameList, BadInputsAreNamed) {
    const fs::path dir = makeInputs("framelist_errors");
    EXPECT_THROW(openFrameList({}, {}), Error);
    const auto message = [](const std::vector<std::string>& in) {
        try {
            openFrameList(in, {});
        } catch (const FileError& e) {
            return std::string(e.what());
        }
        return std::string("no FileError");
    };
    std::ofstream((dir / "notes.txt").string()) << "text";
    fs::create_directories(dir / "empty");
    EXPECT_NE(message({(dir / "missing.png").string()}).find("does not exist"), std::string::npos);
    EXPECT_NE(message({(dir / "notes.txt").string()}).find("neither an image"), std::string::npos);
    EXPECT_NE(message({(dir / "empty").string()}).find("no images"), std::string::npos);
    // A file named like an image that is not one fails when it is read, naming the file.
    std::ofstream((dir / "broken.png").string()) << "not a png";
    auto s = openFrameList({(dir / "broken.png").string()}, {});
    cv::Mat bgr;
    try {
        s->read(bgr);
        ADD_FAILURE() << "no FileError for broken.png";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("broken.png"), std::string::npos) << e.what();
    }
}

TEST(FrameSource, VideoAndFolderFramesAreNamed) {
    const fs::path dir = makeInputs("framesource_names");
    EXPECT_EQ(readAll(*openFrames(dir / "images")).names,
              (std::vector<std::string>{"frame_2.png", "frame_10.png"}));
    const Read v = readAll(*openFrames(dir / "video.mkv"));
    ASSERT_EQ(v.names.size(), 10u);
    EXPECT_EQ(v.names[7], "video.mkv#7");
    const Read c = readAll(*openCameraFrames(readSession(dir / "session"), "main"));
    ASSERT_EQ(c.names.size(), 10u);
    EXPECT_EQ(c.names[3], "main.mkv#3");
}

}  // namespace
}  // namespace mirage
