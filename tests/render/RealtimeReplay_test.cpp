// `mirage replay` end to end: a small synthetic session (PNG frames, calibration, ground-truth
// poses) and a glTF scene written here; the command must write a playable MKV with one frame per
// input frame and a timing CSV, and pass footage through where the pose is missing.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <opencv2/core.hpp>

#include "core/Csv.h"
#include "core/camera/CalibrationFile.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"
#include "testscenes/RenderTestScenes.h"

namespace mirage {
namespace {

std::string base64(const std::string& in) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const unsigned v =
            (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
        out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
    }
    if (i + 1 == in.size()) {
        const unsigned v = (unsigned char)in[i] << 16;
        out += {t[v >> 18], t[(v >> 12) & 63], '=', '='};
    } else if (i + 2 == in.size()) {
        const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
        out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
    }
    return out;
}

// A glTF with a real floor (2 m square, y = 0), a virtual box and a real spot light above.
void writeScene(const std::filesystem::path& path) {
    std::vector<float> pos = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
    std::vector<float> nrm = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    std::vector<uint32_t> idx = {0, 2, 1, 0, 3, 2};
    // Box: 8 corners, flat normals not needed for the test (the loader keeps what it gets).
    Scene tmp;
    test::addBox(tmp, "b", {-0.15f, 0.0f, -0.15f}, {0.15f, 0.3f, 0.15f}, 0, Origin::Virtual);
    const Primitive& box = tmp.meshes[0].primitives[0];
    std::string bin;
    auto put = [&](const void* p, size_t n) { bin.append(static_cast<const char*>(p), n); };
    put(pos.data(), pos.size() * 4);
    put(nrm.data(), nrm.size() * 4);
    put(idx.data(), idx.size() * 4);
    const size_t boxPos = bin.size();
    put(box.positions.data(), box.positions.size() * 12);
    const size_t boxNrm = bin.size();
    put(box.normals.data(), box.normals.size() * 12);
    const size_t boxIdx = bin.size();
    put(box.indices.data(), box.indices.size() * 4);
    const size_t nb = box.positions.size();
    std::ostringstream j;
    j << R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_lights_punctual"],)"
      << R"("buffers":[{"byteLength":)" << bin.size()
      << R"(,"uri":"data:application/octet-stream;base64,)" << base64(bin) << R"("}],)"
      << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},)"
      << R"({"buffer":0,"byteOffset":48,"byteLength":48},{"buffer":0,"byteOffset":96,"byteLength":24},)"
      << R"({"buffer":0,"byteOffset":)" << boxPos << R"(,"byteLength":)" << nb * 12 << "},"
      << R"({"buffer":0,"byteOffset":)" << boxNrm << R"(,"byteLength":)" << nb * 12 << "},"
      << R"({"buffer":0,"byteOffset":)" << boxIdx << R"(,"byteLength":)" << box.indices.size() * 4
      << "}],"
      << R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,0,-1],"max":[1,0,1]},)"
      << R"({"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"},)"
      << R"({"bufferView":2,"componentType":5125,"count":6,"type":"SCALAR"},)"
      << R"({"bufferView":3,"componentType":5126,"count":)" << nb
      << R"(,"type":"VEC3","min":[-0.15,0,-0.15],"max":[0.15,0.3,0.15]},)"
      << R"({"bufferView":4,"componentType":5126,"count":)" << nb << R"(,"type":"VEC3"},)"
      << R"({"bufferView":5,"componentType":5125,"count":)" << box.indices.size()
      << R"(,"type":"SCALAR"}],)"
      << R"("materials":[{"pbrMetallicRoughness":{"baseColorFactor":[0.7,0.7,0.7,1],"metallicFactor":0,"roughnessFactor":1}},)"
      << R"({"pbrMetallicRoughness":{"baseColorFactor":[0.8,0.1,0.1,1],"metallicFactor":0,"roughnessFactor":0.6}}],)"
      << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1},"indices":2,"material":0}]},)"
      << R"({"primitives":[{"attributes":{"POSITION":3,"NORMAL":4},"indices":5,"material":1}]}],)"
      << R"("extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","intensity":6,"spot":{"innerConeAngle":0.6,"outerConeAngle":0.8}}]}},)"
      << R"("nodes":[{"name":"table","mesh":0,"extras":{"mirage":{"real":true}}},)"
      << R"({"name":"virtual box","mesh":1},)"
      << R"({"name":"lamp","translation":[0.3,1.5,0.2],"rotation":[-0.7071068,0,0,0.7071068],)"
      << R"("extensions":{"KHR_lights_punctual":{"light":0}},"extras":{"mirage":{"real":true}}}],)"
      << R"("scenes":[{"nodes":[0,1,2]}],"scene":0})";
    std::ofstream(path) << j.str();
}

TEST(RealtimeReplay, WritesPlayableVideoAndTimingCsv) {
    const auto dir = test::outputDir("realtime_replay");
    writeScene(dir / "scene.gltf");
    CameraCalibration calib;
    calib.intrinsics = test::smallCamera(160, 120, 130.0);
    calib.intrinsics.distortion = {0, 0, 0, 0, 0};  // (an empty list does not round-trip)
    saveCalibration(dir / "main.yaml", calib);
    {
        Session meta;
        meta.cameras.push_back({"main", "", "main.yaml", "main"});
        SessionWriter::Options opts;
        opts.imageSequence = true;
        opts.fps = 10;
        SessionWriter w(dir / "session", meta, opts);
        for (int i = 0; i < 4; ++i) {
            cv::Mat img(120, 160, CV_8UC3, cv::Scalar(60 + 20 * i, 90, 120));
            std::optional<Pose> gt;
            if (i != 2) gt = test::lookAtPose({0.05 * i, 1.4, 1.6}, {0, 0.1, 0});  // frame 2: lost
            w.append({img}, {0.1 * i}, gt);
        }
        w.close();
    }
    std::filesystem::copy_file(dir / "main.yaml", dir / "session" / "main.yaml");
    const auto out = dir / "out" / "replay.mkv";
    auto r = test::runMirage({"replay", (dir / "session").string(), "--scene",
                              (dir / "scene.gltf").string(), "-o", out.string(), "--vpls", "32"});
    ASSERT_EQ(r.exitCode, 0) << r.output;

    auto frames = openFrames(out);
    cv::Mat f;
    int n = 0;
    std::vector<cv::Mat> decoded;
    while (frames->read(f)) {
        decoded.push_back(f.clone());
        ++n;
    }
    EXPECT_EQ(n, 4);
    ASSERT_EQ(decoded.size(), 4u);
    // The lost frame passes through (JPEG-compressed): uniform colour as recorded.
    cv::Scalar mean = cv::mean(decoded[2]);
    EXPECT_NEAR(mean[0], 100, 3);
    EXPECT_NEAR(mean[1], 90, 3);
    // A tracked frame shows the virtual red box: more red than the footage anywhere near it.
    cv::Mat diff;
    cv::absdiff(decoded[1], cv::Mat(120, 160, CV_8UC3, cv::Scalar(80, 90, 120)), diff);
    EXPECT_GT(cv::countNonZero(diff.reshape(1) > 40), 100);

    std::ifstream csv(std::filesystem::path(out).replace_extension(".csv"));
    std::string header, line;
    ASSERT_TRUE(std::getline(csv, header));
    EXPECT_NE(header.find("gbuffer_ms"), std::string::npos);
    EXPECT_NE(header.find("decode_ms"), std::string::npos);
    EXPECT_NE(header.find("encode_ms"), std::string::npos);
    std::vector<std::string> rows;
    while (std::getline(csv, line)) rows.push_back(line);
    ASSERT_EQ(rows.size(), 4u);
    EXPECT_NE(rows[0].find("ground_truth"), std::string::npos);
    // GPU times are plausible on every frame (llvmpipe's first timer query once reported the
    // absolute clock; the renderer primes its queries).
    // Split with core/Csv.h: the reason column is quoted when it holds commas.
    const std::vector<std::string> columns = splitCsvLine(header);
    const auto gpuCol = std::find(columns.begin(), columns.end(), "gpu_ms") - columns.begin();
    ASSERT_LT(size_t(gpuCol), columns.size());
    for (const std::string& row : rows) {
        const std::vector<std::string> fields = splitCsvLine(row);
        ASSERT_EQ(fields.size(), columns.size()) << row;
        EXPECT_LT(std::stod(fields[size_t(gpuCol)]), 10000.0) << row;
    }
    EXPECT_NE(rows[2].find("lost"), std::string::npos);
    // The exposure gain of every rendered frame (estimated per frame by default,
    // docs/camera-matching.md); none for the lost frame, which was not rendered.
    const auto sourceCol =
        std::find(columns.begin(), columns.end(), "exposure_source") - columns.begin();
    const auto gainCol = std::find(columns.begin(), columns.end(), "exposure_g") - columns.begin();
    ASSERT_LT(size_t(sourceCol), columns.size());
    ASSERT_LT(size_t(gainCol), columns.size());
    for (size_t i = 0; i < rows.size(); ++i) {
        const std::vector<std::string> fields = splitCsvLine(rows[i]);
        const std::string& source = fields[size_t(sourceCol)];
        if (i == 2) {
            EXPECT_TRUE(source.empty()) << rows[i];
            continue;
        }
        EXPECT_TRUE(source == "prior" || source == "measured" || source == "step" ||
                    source == "held")
            << rows[i];
        const double g = std::stod(fields[size_t(gainCol)]);
        EXPECT_TRUE(std::isfinite(g) && g > 0.0) << rows[i];
    }
}

// Ctrl-C (SIGINT) mid-replay leaves a playable MKV holding every finished frame, and a CSV row
// per frame written.
TEST(RealtimeReplay, InterruptLeavesPlayableVideo) {
    const auto dir = test::outputDir("realtime_replay_sigint");
    writeScene(dir / "scene.gltf");
    CameraCalibration calib;
    calib.intrinsics = test::smallCamera(160, 120, 130.0);
    calib.intrinsics.distortion = {0, 0, 0, 0, 0};
    const int total = 300;
    {
        Session meta;
        meta.cameras.push_back({"main", "", "main.yaml", "main"});
        SessionWriter::Options opts;
        opts.imageSequence = true;
        SessionWriter w(dir / "session", meta, opts);
        cv::Mat img(120, 160, CV_8UC3, cv::Scalar(70, 90, 110));
        for (int i = 0; i < total; ++i)
            w.append({img}, {i / 30.0}, test::lookAtPose({0.002 * i, 1.4, 1.6}, {0, 0.1, 0}));
        w.close();
    }
    saveCalibration(dir / "session" / "main.yaml", calib);
    const auto out = dir / "replay.mkv";
    // Start the replay, wait until its CSV (written as replay.partial-PID.csv until the end,
    // core/OutputFile.h) holds a few frames (at most 120 s), then SIGINT it.
    const auto csvPath = std::filesystem::path(out).replace_extension(".csv");
    const std::string cmd =
        "'" + std::string(MIRAGE_BINARY) + "' replay '" + (dir / "session").string() +
        "' --scene '" + (dir / "scene.gltf").string() + "' -o '" + out.string() +
        "' --vpls 16 > '" + (dir / "log.txt").string() + "' 2>&1 & pid=$!; " +
        "for i in $(seq 1200); do f=$(ls '" + dir.string() +
        "'/replay.partial-*.csv 2>/dev/null | head -1); [ -n \"$f\" ] && [ $(wc -l < \"$f\") "
        "-ge 4 ] && break; sleep 0.1; done; kill -INT $pid; wait $pid";
    const int rc = std::system(cmd.c_str());
    ASSERT_NE(rc, -1);
    // Interrupted: the frames done are kept, and the exit status says it was interrupted.
    EXPECT_EQ(WEXITSTATUS(rc), 130);
    auto frames = openFrames(out);
    cv::Mat f;
    int n = 0;
    while (frames->read(f)) ++n;
    EXPECT_GE(n, 1);
    EXPECT_LT(n, total) << "replay finished before the interrupt; make the session longer";
    std::ifstream csv(csvPath);
    std::string line;
    int rows = -1;  // header
    while (std::getline(csv, line)) ++rows;
    EXPECT_GE(rows, n);
}

TEST(RealtimeReplay, BadArgumentsFailWithAMessage) {
    const auto dir = test::outputDir("realtime_replay_bad");
    auto r = test::runMirage({"replay", dir.string(), "--scene", (dir / "none.gltf").string(), "-o",
                              (dir / "o.mkv").string()});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.output.find("none.gltf"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mirage
