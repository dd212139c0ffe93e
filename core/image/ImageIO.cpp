#include "core/image/ImageIO.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <mutex>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/LinearImageHeader.h"

namespace mirage {

namespace {
// OpenCV 4.6 refuses EXR unless OPENCV_IO_ENABLE_OPENEXR is set before its first EXR call (it
// reads the variable once). We set it for this process only, before any imread/imwrite.
void enableExr() {
    static std::once_flag once;
    std::call_once(once, [] { setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0); });
}

std::string lowerExt(const std::filesystem::path& p) {
    std::string e = p.extension().string();
    for (auto& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

void atomicWrite(const std::filesystem::path& path, const cv::Mat& img,
                 const std::vector<int>& params) {
    enableExr();
    auto tmp = path;
    tmp += ".tmp" + path.extension().string();  // keep the extension: OpenCV picks by it
    bool ok = false;
    try {
        ok = cv::imwrite(tmp.string(), img, params);
    } catch (const cv::Exception& e) {
        throw FileError(path.string(), std::string("cannot write image: ") + e.what());
    }
    if (!ok) throw FileError(path.string(), "cannot write image (is the folder writable?)");
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec)
        throw FileError(path.string(), "cannot move finished image into place: " + ec.message());
}
}  // namespace

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linearToSrgb(float l) {
    return l <= 0.0031308f ? l * 12.92f : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f;
}

cv::Mat linearRgbToSrgbBgr8(const cv::Mat& linearRgb, float exposure) {
    MR_CHECK(linearRgb.type() == CV_32FC3, "expected a linear RGB float image");
    // 4096-entry table over [0,1]: the sRGB curve is smooth, so the table's error is < 0.5 LSB.
    static const std::vector<unsigned char> lut = [] {
        std::vector<unsigned char> t(4097);
        for (int i = 0; i <= 4096; ++i)
            t[size_t(i)] = (unsigned char)std::lround(255.0f * linearToSrgb(float(i) / 4096.0f));
        return t;
    }();
    cv::Mat out(linearRgb.size(), CV_8UC3);
    for (int y = 0; y < linearRgb.rows; ++y) {
        const auto* src = linearRgb.ptr<cv::Vec3f>(y);
        auto* dst = out.ptr<cv::Vec3b>(y);
        for (int x = 0; x < linearRgb.cols; ++x)
            for (int c = 0; c < 3; ++c) {
                float v = src[x][c] * exposure;
                if (!(v > 0.0f)) v = 0.0f;  // also maps NaN to 0
                if (v > 1.0f) v = 1.0f;
                dst[x][2 - c] = lut[size_t(v * 4096.0f + 0.5f)];
            }
    }
    return out;
}

cv::Mat srgbBgr8ToLinearRgb(const cv::Mat& bgr8) {
    MR_CHECK(bgr8.type() == CV_8UC3, "expected an 8-bit BGR image");
    static const std::vector<float> lut = [] {
        std::vector<float> t(256);
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
        return t;
    }();
    cv::Mat out(bgr8.size(), CV_32FC3);
    for (int y = 0; y < bgr8.rows; ++y) {
        const auto* src = bgr8.ptr<cv::Vec3b>(y);
        auto* dst = out.ptr<cv::Vec3f>(y);
        for (int x = 0; x < bgr8.cols; ++x)
            for (int c = 0; c < 3; ++c) dst[x][c] = lut[src[x][2 - c]];
    }
    return out;
}

cv::Mat readLinearRgb(const std::filesystem::path& path) {
    enableExr();
    if (!std::filesystem::exists(path)) throw FileError(path.string(), "no such file");
    {
        // The decoders trust their headers: screen them first (LinearImageHeader.h).
        std::ifstream in(path, std::ios::binary);
        if (!in) throw FileError(path.string(), "cannot open for reading");
        const std::string bytes{std::istreambuf_iterator<char>(in),
                                std::istreambuf_iterator<char>()};
        screenLinearImageHeader(path, bytes);
    }
    cv::Mat img;
    try {
        img = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception& e) {
        throw FileError(path.string(), std::string("cannot decode image: ") + e.what());
    }
    if (img.empty()) throw FileError(path.string(), "cannot decode image (unsupported or corrupt)");
    if (img.channels() == 4) cv::cvtColor(img, img, cv::COLOR_BGRA2BGR);
    if (img.channels() == 1) cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
    if (img.depth() == CV_32F || img.depth() == CV_16F || img.depth() == CV_64F) {
        img.convertTo(img, CV_32F);
        cv::cvtColor(img, img, cv::COLOR_BGR2RGB);
        // Radiance is finite: one NaN or infinity spreads through every sum that touches it
        // (an environment map's integral, a merged shard).
        for (int y = 0; y < img.rows; ++y) {
            const auto* row = img.ptr<cv::Vec3f>(y);
            for (int x = 0; x < img.cols; ++x)
                for (int c = 0; c < 3; ++c)
                    if (!std::isfinite(row[x][c]))
                        throw FileError(path.string(),
                                        "pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                            ") channel " + "RGB"[c] + " is " +
                                            (std::isnan(row[x][c]) ? "NaN" : "infinite") +
                                            "; linear images must hold finite values");
        }
        return img;
    }
    if (img.depth() == CV_16U) {  // 16-bit PNG: sRGB-encoded like 8-bit
        cv::Mat f;
        img.convertTo(f, CV_32F, 1.0 / 65535.0);
        cv::Mat out(f.size(), CV_32FC3);
        for (int y = 0; y < f.rows; ++y)
            for (int x = 0; x < f.cols; ++x)
                for (int c = 0; c < 3; ++c)
                    out.at<cv::Vec3f>(y, x)[c] = srgbToLinear(f.at<cv::Vec3f>(y, x)[2 - c]);
        return out;
    }
    if (img.depth() != CV_8U)
        throw FileError(path.string(),
                        "unsupported pixel depth (use 8/16-bit PNG, EXR, PFM or HDR)");
    return srgbBgr8ToLinearRgb(img);
}

void writeLinearRgb(const std::filesystem::path& path, const cv::Mat& linearRgb, float exposure) {
    MR_CHECK(linearRgb.type() == CV_32FC3, "expected a linear RGB float image");
    const std::string ext = lowerExt(path);
    if (ext == ".exr" || ext == ".pfm" || ext == ".hdr") {
        cv::Mat bgr;
        cv::cvtColor(linearRgb * exposure, bgr, cv::COLOR_RGB2BGR);
        std::vector<int> params;
        if (ext == ".exr") params = {cv::IMWRITE_EXR_TYPE, cv::IMWRITE_EXR_TYPE_FLOAT};
        atomicWrite(path, bgr, params);
        return;
    }
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") {
        atomicWrite(path, linearRgbToSrgbBgr8(linearRgb, exposure), {});
        return;
    }
    throw FileError(path.string(), "unknown image extension '" + ext +
                                       "' (use .exr, .pfm or .hdr for linear, .png or .jpg)");
}

void writeBgr8(const std::filesystem::path& path, const cv::Mat& bgr8) {
    MR_CHECK(bgr8.depth() == CV_8U, "expected an 8-bit image");
    atomicWrite(path, bgr8, {});
}

}  // namespace mirage
