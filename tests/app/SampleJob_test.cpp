// The README's main job (scripts/sample-job.sh, which scripts/run-sample.sh runs) on the bundled
// sample session: it runs, tracks the camera, writes the composited video, and the video's first
// frame (the README picture, docs/images/replay-sample.png) shows the glass sphere's caustic on
// the real table.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/camera/CalibrationFile.h"
#include "core/scene/Scene.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

fs::path sampleSession() {
    return test::dataDir() / "sessions" / "sample";
}

// The scene the sample was synthesised from and the job composites (data/README.md).
fs::path backlitScene() {
    return test::dataDir() / "scenes" / "tabletop" / "tabletop_backlit.gltf";
}

test::CommandResult runSampleJob(const fs::path& out) {
    const fs::path script = test::dataDir().parent_path() / "scripts" / "sample-job.sh";
    const std::string cmd = "bash '" + script.string() + "' '" + MIRAGE_BINARY + "' '" +
                            test::dataDir().string() + "' '" + out.string() + "' 2>&1";
    test::CommandResult r;
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    const int status = pclose(p);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

// Where the ray from the scene's spot light through the glass sphere's centre meets the table
// top (y = 0, world metres): the centre of the sphere's focused caustic (the ball lens's axis
// towards the light), make_tabletop_backlit.py.
glm::dvec3 causticCentreOnTable(const Scene& scene) {
    glm::dvec3 light{0.0}, sphere{0.0};
    int lights = 0, spheres = 0;
    for (const LightInstance& l : scene.lightInstances())
        if (scene.lights[size_t(l.light)].type == Light::Type::Spot) light = l.position, ++lights;
    for (const Node& n : scene.nodes)
        if (n.name == "glass_sphere") sphere = glm::dvec3(n.world[3]), ++spheres;
    EXPECT_EQ(lights, 1);
    EXPECT_EQ(spheres, 1);
    const glm::dvec3 d = glm::normalize(sphere - light);
    return sphere + d * (sphere.y / -d.y);
}

// Mean 8-bit luminance (BT.601 gray of the BGR frame) over the pixels whose distance from
// `centre` lies in [r0, r1).
double meanGrayInRing(const cv::Mat& bgr, const glm::dvec2& centre, double r0, double r1) {
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    double sum = 0;
    int count = 0;
    for (int y = 0; y < gray.rows; ++y)
        for (int x = 0; x < gray.cols; ++x) {
            const double r = std::hypot(x - centre.x, y - centre.y);
            if (r < r0 || r >= r1) continue;
            sum += gray.at<uint8_t>(y, x);
            ++count;
        }
    return count ? sum / count : 0.0;
}

struct CausticContrast {
    double spot = 0;     // composite, mean gray within kSpotRadius of the caustic's centre
    double around = 0;   // composite, mean gray in the ring around it (flanks and shadow)
    double footage = 0;  // the footage there (no virtual sphere: no shadow, no caustic)
};

// Pixels (640x480 sample): the focused spot is ~6 px across at the sample's first pose; the
// ring holds the caustic's flanks and lies inside the sphere's shadow (~50 x 35 px).
constexpr double kSpotRadius = 3.0, kRingInner = 9.0, kRingOuter = 14.0;
// Floors set from measurement (docs/caustics.md, "The bundled sample").
constexpr int kMinTrackedFrames = 33;
// Measured: spot 253 (saturated), ring 174, footage 127; with tabletop.gltf's light 127 / 128 /
// 127.
constexpr double kSpotOverFootage = 1.6, kSpotOverRing = 1.25;

CausticContrast causticContrast(const cv::Mat& composite, const cv::Mat& footage,
                                const glm::dvec3& causticWorld) {
    Session s = readSession(sampleSession());
    const CameraCalibration cal = loadCalibration(s.path(s.camera("main")->calibration));
    EXPECT_TRUE(s.frames.at(0).groundTruth.has_value());
    const Pose T_camera_world = s.frames.at(0).groundTruth->inverse();
    const auto px = cal.intrinsics.project(T_camera_world * causticWorld);
    EXPECT_TRUE(px.has_value());
    if (!px) return {};
    CausticContrast c;
    c.spot = meanGrayInRing(composite, *px, 0.0, kSpotRadius);
    c.around = meanGrayInRing(composite, *px, kRingInner, kRingOuter);
    c.footage = meanGrayInRing(footage, *px, 0.0, kSpotRadius);
    return c;
}

cv::Mat firstVideoFrame(const fs::path& video) {
    cv::VideoCapture cap(video.string());
    cv::Mat frame;
    EXPECT_TRUE(cap.isOpened()) << video;
    EXPECT_TRUE(cap.read(frame)) << video;
    return frame;
}

TEST(SampleJob, RunsTheReadmeJobAndItsFirstFrameShowsTheGlassSpheresCaustic) {
    const fs::path out = test::outputDir("sample_job");
    const auto r = runSampleJob(out);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("sample job done"), std::string::npos) << r.output;

    const Session session = readSession(sampleSession());
    const size_t frames = session.frames.size();
    const test::CsvTable replay = test::readCsvTable(out / "replay.csv");
    EXPECT_EQ(replay.rows.size(), frames);
    const test::CsvTable poses = test::readCsvTable(out / "poses.csv");
    ASSERT_EQ(poses.rows.size(), frames);
    int tracked = 0;
    for (size_t i = 0; i < poses.rows.size(); ++i) tracked += poses.field(i, "state") == "ok";
    std::printf("sample job: %d of %zu frames tracked\n", tracked, frames);
    EXPECT_GE(tracked, kMinTrackedFrames);

    const cv::Mat composite = firstVideoFrame(out / "replay.mkv");
    const cv::Mat footage = test::sessionFrames(sampleSession()).at(0);
    ASSERT_EQ(composite.size(), footage.size());
    const CausticContrast c =
        causticContrast(composite, footage, causticCentreOnTable(loadScene(backlitScene())));
    std::printf("caustic (8-bit gray): spot %.1f, ring %.1f, footage %.1f\n", c.spot, c.around,
                c.footage);
    // The focused spot is brighter than the unshadowed table (the footage) and than its
    // surroundings.
    EXPECT_GT(c.spot, kSpotOverFootage * c.footage);
    EXPECT_GT(c.spot, kSpotOverRing * c.around);

    // Must-fail: the same frame composited with tabletop.gltf, whose spot shines from above the
    // camera's side, puts the sphere's caustic under the sphere: the check fails there.
    const auto hidden =
        test::runMirage({"replay", sampleSession().string(), "--scene",
                         (test::dataDir() / "scenes" / "tabletop" / "tabletop.gltf").string(),
                         "--frames", "1", "-o", (out / "hidden.mkv").string()});
    ASSERT_EQ(hidden.exitCode, 0) << hidden.output;
    const CausticContrast h = causticContrast(firstVideoFrame(out / "hidden.mkv"), footage,
                                              causticCentreOnTable(loadScene(backlitScene())));
    std::printf("tabletop.gltf's light (8-bit gray): spot %.1f, ring %.1f, footage %.1f\n", h.spot,
                h.around, h.footage);
    EXPECT_FALSE(h.spot > kSpotOverFootage * h.footage && h.spot > kSpotOverRing * h.around);
}

}  // namespace
}  // namespace mirage
