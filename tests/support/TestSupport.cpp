#include "tests/support/TestSupport.h"
#include "tests/support/RenderMasks.h"

#include <sys/wait.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/Csv.h"
#include "core/image/ImageCompare.h"
#include "core/session/AtomicFile.h"
#include "core/session/MatroskaScanner.h"
#include "core/session/Session.h"

namespace mirage::test {

std::filesystem::path dataDir() {
    return MIRAGE_DATA_DIR;
}
std::filesystem::path testDataDir() {
    return MIRAGE_TEST_DATA_DIR;
}

std::filesystem::path outputDir(const std::string& name) {
    auto p = std::filesystem::path(MIRAGE_TEST_OUTPUT_DIR) / name;
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    return p;
}

std::filesystem::path outputDirForThisTest(const std::string& prefix) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    if (!info) return outputDir(prefix);
    return outputDir(prefix + "_" + info->test_suite_name() + "." + info->name());
}

double meanLuminance(const cv::Mat& linearRgb, const cv::Mat& mask) {
    const cv::Scalar m = cv::mean(linearRgb, mask);
    return 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2];
}

double psnr(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask) {
    return mirage::psnr(a, b, peak, mask);
}

double ssim(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask) {
    return mirage::ssim(a, b, peak, mask);
}

double meanAbsDiff(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
    CV_Assert(a.size() == b.size() && a.type() == b.type() && a.channels() >= 3);
    cv::Mat d;
    cv::absdiff(a, b, d);
    const cv::Scalar m = cv::mean(d, mask);
    return (m[0] + m[1] + m[2]) / 3.0;
}

double percentileAbsDiff(const cv::Mat& a, const cv::Mat& b, double q) {
    CV_Assert(a.size() == b.size() && a.type() == b.type());
    cv::Mat fa, fb, d;
    a.convertTo(fa, CV_64F);
    b.convertTo(fb, CV_64F);
    cv::absdiff(fa, fb, d);
    d = d.reshape(1, int(d.total()));
    cv::Mat perPixel;
    cv::reduce(d, perPixel, 1, cv::REDUCE_MAX);
    std::vector<double> v(perPixel.begin<double>(), perPixel.end<double>());
    if (v.empty()) return 0;
    size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
    std::nth_element(v.begin(), v.begin() + long(k), v.end());
    return v[k];
}

namespace {

void putLe32(std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out += char((v >> (8 * i)) & 0xFF);
}
void putLe16(std::string& out, uint16_t v) {
    out += char(v & 0xFF);
    out += char(v >> 8);
}
// A chunk: FourCC, little-endian size, payload, a pad byte to an even size.
std::string riffChunk(const char* id, const std::string& payload) {
    std::string c(id, 4);
    putLe32(c, uint32_t(payload.size()));
    c += payload;
    if (payload.size() % 2) c += '\0';
    return c;
}
std::string riffList(const char* type, const std::string& children) {
    return riffChunk("LIST", std::string(type, 4) + children);
}

}  // namespace

std::string mjpegAviBytes(const std::vector<std::string>& jpegs, int width, int height, double fps,
                          bool withIndex) {
    const uint32_t rate = uint32_t(std::lround(fps * 1000)), scale = 1000;
    size_t largest = 0;
    for (const auto& j : jpegs) largest = std::max(largest, j.size());
    std::string avih;
    for (uint32_t v :
         {uint32_t(1e6 / fps), 0u, 0u, 0x10u /*AVIF_HASINDEX*/, uint32_t(jpegs.size()), 0u, 1u,
          uint32_t(largest), uint32_t(width), uint32_t(height), 0u, 0u, 0u, 0u})
        putLe32(avih, v);
    std::string strh = "vidsMJPG";
    for (uint32_t v :
         {0u, 0u, 0u, scale, rate, 0u, uint32_t(jpegs.size()), uint32_t(largest), ~0u, 0u})
        putLe32(strh, v);
    putLe16(strh, 0);
    putLe16(strh, 0);
    putLe16(strh, uint16_t(width));
    putLe16(strh, uint16_t(height));
    std::string strf;  // BITMAPINFOHEADER
    putLe32(strf, 40);
    putLe32(strf, uint32_t(width));
    putLe32(strf, uint32_t(height));
    putLe16(strf, 1);
    putLe16(strf, 24);
    strf += "MJPG";
    putLe32(strf, uint32_t(width * height * 3));
    for (int i = 0; i < 4; ++i) putLe32(strf, 0);
    const std::string hdrl =
        riffList("hdrl", riffChunk("avih", avih) +
                             riffList("strl", riffChunk("strh", strh) + riffChunk("strf", strf)));
    std::string movi = "movi", idx1;
    for (const auto& j : jpegs) {
        idx1 += "00dc";
        putLe32(idx1, 0x10);                   // AVIIF_KEYFRAME
        putLe32(idx1, uint32_t(movi.size()));  // from the 'movi' FourCC
        putLe32(idx1, uint32_t(j.size()));
        movi += riffChunk("00dc", j);
    }
    std::string body = "AVI " + hdrl + riffChunk("LIST", movi);
    if (withIndex) body += riffChunk("idx1", idx1);
    return riffChunk("RIFF", body);
}

std::vector<std::string> matroskaJpegs(const std::filesystem::path& mkv) {
    const MatroskaScan scan = scanMatroska(mkv);
    const std::string bytes = readFileBytes(mkv);
    std::vector<std::string> jpegs;
    for (const MatroskaBlock& b : scan.blocks)
        jpegs.push_back(bytes.substr(size_t(b.offset), size_t(b.size)));
    return jpegs;
}

std::string withoutMatroskaClusterChecksums(std::string bytes) {
    const auto vint = [&](size_t at, size_t& length) -> uint64_t {
        const auto first = uint8_t(bytes[at]);
        length = 1;
        while (length <= 8 && !(first & (0x80 >> (length - 1)))) ++length;
        uint64_t v = first & (0xFF >> length);
        for (size_t k = 1; k < length; ++k) v = (v << 8) | uint8_t(bytes[at + k]);
        return v;
    };
    const std::string clusterId("\x1F\x43\xB6\x75", 4), crc("\xBF\x84", 2);
    for (size_t at = bytes.find(clusterId); at != std::string::npos;
         at = bytes.find(clusterId, at + 4)) {
        if (at + 13 > bytes.size()) break;  // the ID, the longest size, a child's ID and size
        size_t sizeLength = 0;
        const uint64_t size = vint(at + 4, sizeLength);
        const size_t data = at + 4 + sizeLength;
        if (bytes.compare(data, 2, crc) != 0 || data + size > bytes.size() || size < 6) continue;
        bytes.erase(data, 6);
        bytes.insert(data + size - 6, std::string("\xEC\x84\0\0\0\0", 6));
    }
    return bytes;
}

CommandResult runMirage(const std::vector<std::string>& args) {
    std::string cmd = std::string("'") + MIRAGE_BINARY + "'";
    for (const auto& a : args) {
        std::string q;
        for (char c : a) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
        cmd += " '" + q + "'";
    }
    cmd += " 2>&1";
    CommandResult r;
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf{};
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
    int status = pclose(p);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

double unexplainedDb(const cv::Mat& live, const cv::Mat& replay, const cv::Mat& original,
                     const cv::Mat& recorded) {
    cv::Mat a, b, c, d;
    live.convertTo(a, CV_32F);
    replay.convertTo(b, CV_32F);
    original.convertTo(c, CV_32F);
    recorded.convertTo(d, CV_32F);
    const cv::Mat r = (b - a) - (d - c);
    const cv::Scalar m = cv::mean(r.mul(r));
    const double mse = (m[0] + m[1] + m[2]) / 3;
    return mse <= 0 ? 1e9 : 10 * std::log10(255.0 * 255.0 / mse);
}

std::vector<cv::Mat> sessionFrames(const std::filesystem::path& session,
                                   const std::string& camera) {
    const Session s = readSession(session);
    auto src = openCameraFrames(s, camera);
    std::vector<cv::Mat> out;
    cv::Mat bgr;
    while (src->read(bgr)) out.push_back(bgr.clone());
    return out;
}

std::string CsvTable::field(size_t row, const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << "no column " << name;
    if (it == header.end() || row >= rows.size()) return {};
    return rows[row][size_t(it - header.begin())];
}

CsvTable readCsvTable(const std::filesystem::path& path) {
    CsvTable t;
    std::ifstream in(path);
    EXPECT_TRUE(in.good()) << path;
    std::string line;
    if (std::getline(in, line)) t.header = splitCsvLine(line);
    while (std::getline(in, line))
        if (!line.empty()) {
            t.rows.push_back(splitCsvLine(line));
            EXPECT_EQ(t.rows.back().size(), t.header.size()) << line;
        }
    return t;
}

cv::Mat changedPixels(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    std::vector<cv::Mat> ch;
    cv::split(diff, ch);
    cv::Mat sum = ch[0].clone();
    for (size_t c = 1; c < ch.size(); ++c) sum += ch[c];
    return sum > 1e-6f;
}

cv::Mat boxSilhouette(const CameraIntrinsics& camera, const Pose& T_world_camera,
                      const glm::vec3& lo, const glm::vec3& hi) {
    cv::Mat mask(camera.height, camera.width, CV_8U, cv::Scalar(0));
    std::vector<cv::Point> pts;
    const Pose T_camera_world = T_world_camera.inverse();
    for (float x : {lo.x, hi.x})
        for (float y : {lo.y, hi.y})
            for (float z : {lo.z, hi.z}) {
                const glm::dvec3 c = T_camera_world * glm::dvec3(x, y, z);
                pts.emplace_back(int(std::lround(camera.fx * c.x / c.z + camera.cx)),
                                 int(std::lround(camera.fy * c.y / c.z + camera.cy)));
            }
    std::vector<cv::Point> hull;
    cv::convexHull(pts, hull);
    cv::fillConvexPoly(mask, hull, cv::Scalar(255));
    cv::dilate(mask, mask, cv::Mat::ones(3, 3, CV_8U));
    return mask;
}

}  // namespace mirage::test
