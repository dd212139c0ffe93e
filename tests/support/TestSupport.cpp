#include "tests/support/TestSupport.h"

#include <sys/wait.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include <opencv2/imgproc.hpp>

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

double psnr(const cv::Mat& a, const cv::Mat& b, double peak) {
    CV_Assert(a.size() == b.size() && a.type() == b.type());
    cv::Mat fa, fb;
    a.convertTo(fa, CV_64F);
    b.convertTo(fb, CV_64F);
    cv::Mat d = fa - fb;
    double mse = d.dot(d) / double(d.total() * d.channels());
    if (mse <= 0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(peak * peak / mse);
}

double ssim(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask) {
    CV_Assert(a.size() == b.size() && a.type() == b.type());
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    cv::Mat fa, fb;
    a.convertTo(fa, CV_64F, 1.0 / peak);
    b.convertTo(fb, CV_64F, 1.0 / peak);
    auto blur = [](const cv::Mat& m) {
        cv::Mat o;
        cv::GaussianBlur(m, o, cv::Size(11, 11), 1.5);
        return o;
    };
    cv::Mat muA = blur(fa), muB = blur(fb);
    cv::Mat muA2 = muA.mul(muA), muB2 = muB.mul(muB), muAB = muA.mul(muB);
    cv::Mat sA = blur(fa.mul(fa)) - muA2, sB = blur(fb.mul(fb)) - muB2,
            sAB = blur(fa.mul(fb)) - muAB;
    // Scalar::all: a plain double added to a multi-channel Mat goes to channel 0 only.
    const cv::Scalar k1 = cv::Scalar::all(c1), k2 = cv::Scalar::all(c2);
    cv::Mat num = (2 * muAB + k1).mul(2 * sAB + k2);
    cv::Mat den = (muA2 + muB2 + k1).mul(sA + sB + k2);
    cv::Mat map;
    cv::divide(num, den, map);
    cv::Scalar m = mask.empty() ? cv::mean(map) : cv::mean(map, mask);
    double sum = 0;
    for (int c = 0; c < map.channels(); ++c) sum += m[c];
    return sum / map.channels();
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

}  // namespace mirage::test
