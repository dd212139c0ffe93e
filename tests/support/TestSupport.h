#pragma once
// Shared helpers for mirage tests: where data lives, where outputs go, image comparison with
// tolerances (never bytes), and running the `mirage` binary for end-to-end tests.
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mirage::test {

std::filesystem::path dataDir();      // the project's data/ (MIRAGE_DATA_DIR)
std::filesystem::path testDataDir();  // tests/data/
// A fresh (emptied) folder under the build's test output directory.
std::filesystem::path outputDir(const std::string& name);
// outputDir(prefix + "_" + the running test's suite.name). ctest runs each test in its own
// process, in parallel: a folder shared by several tests (a lazily made fixture, say) would be
// emptied by one while another still reads it, so such fixtures use this instead.
std::filesystem::path outputDirForThisTest(const std::string& prefix);

// PSNR (dB) and mean SSIM of two images of equal size and type, over all pixels or where
// mask != 0 (CV_8U): core/image/ImageCompare.h's, the figures the benchmark reports too.
// `peak` is the signal's maximum (1 for linear float, 255 for 8-bit). PSNR is +inf if identical.
double psnr(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask = cv::Mat());
// Mean Rec. 709 luminance of a linear RGB (channel order R, G, B) image over `mask`.
double meanLuminance(const cv::Mat& linearRgb, const cv::Mat& mask = cv::Mat());
double ssim(const cv::Mat& a, const cv::Mat& b, double peak, const cv::Mat& mask = cv::Mat());
// Mean |a - b| over the pixels (all, or where mask != 0) and the first three channels, in the
// images' units (8-bit codes, linear radiance). Equal size and type.
double meanAbsDiff(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask = cv::Mat());
// The q-quantile (0..1) of the per-pixel absolute difference (max over channels).
double percentileAbsDiff(const cv::Mat& a, const cv::Mat& b, double q);
// PSNR (dB, 8-bit peak) of the part of two composites' difference that their footage's difference
// does not explain: r = (replay - live) - (recorded - original), per pixel and channel. For a
// recording replayed: where the virtual objects change nothing the composite is the footage, so
// r = 0 there by construction; what is left is the rendering's response to the re-encoded
// footage (through alpha = CI / L_r and the video seen in the glass) and any difference in the
// rendering itself. +inf-like (1e9) when nothing is left.
double unexplainedDb(const cv::Mat& live, const cv::Mat& replay, const cv::Mat& original,
                     const cv::Mat& recorded);
// A CSV with a header (quoted fields may hold commas), looked up by column name: a test fails
// when the file cannot be read, a row has another number of fields, or a column is missing.
struct CsvTable {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    std::string field(size_t row, const std::string& name) const;
};
CsvTable readCsvTable(const std::filesystem::path& path);
// Every frame of a session's camera (8-bit BGR), decoded in order.
std::vector<cv::Mat> sessionFrames(const std::filesystem::path& session,
                                   const std::string& camera = "main");

// A Matroska file's bytes with every cluster's leading CRC-32 element (ID 0xBF, size 4) moved
// out of the way: the cluster's other children move up by its 6 bytes and an EBML Void of the
// same 6 bytes ends the cluster, so every size and the file's length stay. mirage's recordings
// carry the checksum, other recorders' files do not: there only the JPEG checks can find damage.
std::string withoutMatroskaClusterChecksums(std::string bytes);

// An AVI (RIFF) file holding `jpegs` as one MJPEG video stream, laid out as FFmpeg's AVI muxer
// lays it out (hdrl with avih/strl/strh/strf, a movi list of '00dc' chunks, an idx1 index with
// offsets relative to 'movi'), without the index if `withIndex` is false (a recording cut before
// it was written). The JPEG bytes are copied unchanged.
std::string mjpegAviBytes(const std::vector<std::string>& jpegs, int width, int height, double fps,
                          bool withIndex = true);
// The JPEG of every frame of a Matroska MJPEG file, in order (bytes as stored).
std::vector<std::string> matroskaJpegs(const std::filesystem::path& mkv);

struct CommandResult {
    int exitCode = -1;
    std::string output;  // stdout and stderr together
};
// Runs the built `mirage` binary with the given arguments (shell-quoted here).
CommandResult runMirage(const std::vector<std::string>& args);

}  // namespace mirage::test
