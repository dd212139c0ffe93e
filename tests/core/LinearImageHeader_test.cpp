// The header screen of linear image files: files mirage writes pass with their size; damaged
// headers are refused with the field named, before any decoder allocates or loops on them.
#include "core/image/LinearImageHeader.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

cv::Mat smallImage() {
    cv::Mat m(6, 8, CV_32FC3);
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) m.at<cv::Vec3f>(y, x) = {x * 0.5f, y * 0.25f, 2.0f};
    return m;
}

std::string readBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

std::string written(const char* ext) {
    const fs::path p = test::outputDirForThisTest("linear_header") / (std::string("small") + ext);
    writeLinearRgb(p, smallImage());
    return readBytes(p);
}

void putU32(std::string& bytes, size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes[at + size_t(i)] = char((v >> (8 * i)) & 0xff);
}

// Offset of an EXR attribute's value: after "name\0type\0" and the 4-byte size.
size_t exrValue(const std::string& bytes, const std::string& name, const std::string& type) {
    const std::string key = name + '\0' + type + '\0';
    const size_t at = bytes.find(key);
    EXPECT_NE(at, std::string::npos) << name;
    return at + key.size() + 4;
}

// Runs the screen and returns its message ("" when it accepted the header).
std::string screenMessage(const std::string& bytes) {
    try {
        screenLinearImageHeader("damaged", bytes);
    } catch (const FileError& e) {
        return e.what();
    }
    return "";
}

TEST(LinearImageHeader, FilesMirageWritesPassWithTheirSize) {
    for (const char* ext : {".exr", ".pfm", ".hdr"}) {
        const LinearImageHeader h = screenLinearImageHeader("small", written(ext));
        EXPECT_NE(h.format, LinearImageFormat::Other) << ext;
        EXPECT_EQ(h.width, 8) << ext;
        EXPECT_EQ(h.height, 6) << ext;
        EXPECT_GE(h.channels, 3) << ext;
    }
    EXPECT_EQ(screenLinearImageHeader("x.png", "\x89PNG\r\n\x1a\n").format,
              LinearImageFormat::Other);
}

TEST(LinearImageHeader, DamagedExrChannelListIsNamed) {
    std::string exr = written(".exr");
    const size_t list = exrValue(exr, "channels", "chlist");
    const size_t firstType = exr.find('\0', list) + 1;  // after the first channel's name
    std::string badType = exr;
    putU32(badType, firstType, 7);
    EXPECT_NE(screenMessage(badType).find("pixel type 7"), std::string::npos)
        << screenMessage(badType);

    std::string subsampled = exr;
    putU32(subsampled, firstType + 8, 2);  // x sampling
    EXPECT_NE(screenMessage(subsampled).find("subsampled"), std::string::npos);

    std::string noEnd = exr;
    noEnd[list - 4] = char(0x7f);  // the list's size claims far more than the file holds
    noEnd[list - 3] = char(0x7f);
    EXPECT_NE(screenMessage(noEnd).find("claims"), std::string::npos) << screenMessage(noEnd);
}

TEST(LinearImageHeader, ExrWindowsBeyondTheLimitAreRefused) {
    std::string exr = written(".exr");
    const size_t window = exrValue(exr, "dataWindow", "box2i");
    putU32(exr, window + 8, 1u << 30);  // xMax
    const std::string message = screenMessage(exr);
    EXPECT_NE(message.find("dataWindow"), std::string::npos) << message;
    EXPECT_NE(message.find("beyond the limit"), std::string::npos) << message;

    std::string inverted = written(".exr");
    putU32(inverted, exrValue(inverted, "displayWindow", "box2i") + 12, uint32_t(-5));  // yMax
    EXPECT_NE(screenMessage(inverted).find("empty image"), std::string::npos);
}

TEST(LinearImageHeader, TruncatedOrIncompleteExrHeadersAreRefused) {
    const std::string exr = written(".exr");
    for (size_t keep : {size_t(6), size_t(20), size_t(60)})
        EXPECT_FALSE(screenMessage(exr.substr(0, keep)).empty()) << keep;
    std::string renamed = exr;  // a required attribute under another name
    const size_t at = renamed.find("compression");
    renamed.replace(at, 11, "compressiom");
    EXPECT_NE(screenMessage(renamed).find("'compression'"), std::string::npos);
    std::string unknown = exr;
    unknown[exrValue(unknown, "compression", "compression")] = char(42);
    EXPECT_NE(screenMessage(unknown).find("compression 42"), std::string::npos);
}

TEST(LinearImageHeader, PfmPromisingMorePixelsThanItHoldsIsRefused) {
    const std::string pfm = written(".pfm");
    const size_t headerEnd = pfm.find('\n', pfm.find('\n', 3) + 1) + 1;  // "PF\n8 6\n-1\n"
    const std::string big = "PF\n9000 9000\n-1\n" + pfm.substr(headerEnd);
    const std::string message = screenMessage(big);
    EXPECT_NE(message.find("truncated"), std::string::npos) << message;
    EXPECT_NE(screenMessage("PF\n8 x\n-1\n").find("height"), std::string::npos);
    EXPECT_NE(screenMessage("PF\n8 6\nnan\n").find("scale"), std::string::npos);
    EXPECT_NE(screenMessage(pfm.substr(0, pfm.size() - 4)).find("truncated"), std::string::npos);
    // Found by env_image_fuzz under ASan: OpenCV's PFM reader spent over 10 s on this header.
    const std::string found("Pf\n5120Y 100000 +X 1\xe9IG@\xc9?AE@^$\n@=1.", 36);
    EXPECT_NE(screenMessage(found).find("PFM header"), std::string::npos) << screenMessage(found);
}

TEST(LinearImageHeader, HdrResolutionIsChecked) {
    const std::string hdr = written(".hdr");
    const size_t blank = hdr.find("\n\n");
    ASSERT_NE(blank, std::string::npos);
    const std::string head = hdr.substr(0, blank + 2);
    EXPECT_NE(screenMessage(head + "-Y 100000 +X 100000\n").find("beyond the limit"),
              std::string::npos);
    EXPECT_NE(screenMessage(head + "-Y 6 +Y 8\n").find("resolution line"), std::string::npos);
    EXPECT_NE(screenMessage("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n").find("no end"),
              std::string::npos);
}

TEST(LinearImageHeader, ReaderRefusesDamagedHeaderBeforeDecoding) {
    std::string exr = written(".exr");
    putU32(exr, exrValue(exr, "dataWindow", "box2i") + 8, 1u << 30);
    const fs::path p = test::outputDirForThisTest("linear_header") / "damaged.exr";
    writeBytes(p, exr);
    try {
        readLinearRgb(p);
        FAIL() << "a damaged EXR header was decoded";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("dataWindow"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("damaged.exr"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mirage
