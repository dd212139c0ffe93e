// `mirage response BRACKET --calibration FILE`: the camera's response curve from an exposure
// bracket (calibration/ResponseFit.h; docs/camera-matching.md, "Camera response"). BRACKET is a
// folder with the pictures and `exposures.csv` (header `file,exposure_seconds`, one row per
// picture, file names relative to the folder). Prints the fit; --write stores it as `response`
// in the calibration file (the rest of the file is kept), where replay, live and bench read it.
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/NumberChecks.h"
#include "calibration/ResponseFit.h"
#include "core/ContainedPath.h"
#include "core/Csv.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/camera/CameraResponse.h"
#include "core/image/ImageIO.h"
#include "core/image/StrictJpeg.h"

namespace mirage::app {
namespace {

struct ResponseArgs {
    std::string bracket, calibration;
    int samples = 200;
    double smoothness = 10.0;
    bool write = false;
};

std::vector<calibration::BracketImage> readBracket(const std::filesystem::path& dir) {
    const std::filesystem::path list = dir / "exposures.csv";
    std::ifstream in(list);
    if (!in)
        throw FileError(list.string(),
                        "cannot be read; a bracket folder holds its pictures and "
                        "exposures.csv (file,exposure_seconds)");
    std::vector<calibration::BracketImage> out;
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        const std::vector<std::string> f = splitCsvLine(line);
        if (lineNo == 1) {
            if (f.size() != 2 || f[0] != "file" || f[1] != "exposure_seconds")
                throw FileError(list.string(), "line 1: expected the header file,exposure_seconds");
            continue;
        }
        if (f.size() != 2)
            throw FileError(list.string(), fmt::format("line {}: expected 2 fields", lineNo));
        double t = 0;
        try {
            size_t used = 0;
            t = std::stod(f[1], &used);
            if (used != f[1].size()) throw std::invalid_argument(f[1]);
        } catch (const std::exception&) {
            throw FileError(
                list.string(),
                fmt::format("line {}: exposure_seconds '{}' is not a number", lineNo, f[1]));
        }
        if (!(std::isfinite(t) && t > 0 && t < 1e4))
            throw FileError(
                list.string(),
                fmt::format("line {}: exposure_seconds {} is not in (0, 1e4)", lineNo, f[1]));
        const std::filesystem::path file =
            resolveContained(dir, f[0], fmt::format("{} line {}", list.string(), lineNo), "file");
        std::string problem;
        cv::Mat img = readImageStrict(file, &problem);
        if (img.empty())
            throw FileError(file.string(),
                            problem.empty() ? "cannot be read as an image" : problem);
        if (img.type() != CV_8UC3) throw FileError(file.string(), "not an 8-bit colour picture");
        out.push_back({img, t, f[0]});
    }
    return out;
}

void runResponse(const ResponseArgs& a) {
    const auto bracket = readBracket(a.bracket);
    if (!a.calibration.empty()) (void)loadCalibration(a.calibration);  // a calibration file
    const calibration::ResponseFit fit =
        calibration::fitCameraResponse(bracket, a.samples, float(a.smoothness));
    // How far the camera is from the sRGB assumption, over the trusted codes.
    const CameraResponse srgb = CameraResponse::srgb();
    double worst = 0;
    int worstCode = 0;
    for (int ch = 0; ch < 3; ++ch)
        for (int c = 16; c <= 239; ++c) {
            const double d =
                std::abs(std::log(double(fit.response.linear(ch, c)) / double(srgb.linear(ch, c))));
            if (d > worst) worst = d, worstCode = c;
        }
    std::printf(
        "camera response from %zu pictures: equivalent gamma %.3f; bracket agreement (RMS spread "
        "of ln radiance) %.3f over %d samples; against sRGB: up to %.0f %% apart (code %d)\n",
        bracket.size(), fit.equivalentGamma, fit.logRadianceSpread, fit.samplesUsed,
        100.0 * (std::exp(worst) - 1.0), worstCode);
    if (fit.logRadianceSpread > 0.15)
        spdlog::warn(
            "response: the pictures disagree with one curve (spread {:.3f}): did the "
            "scene or the camera move, or the exposure times not hold?",
            fit.logRadianceSpread);
    if (a.write) {
        if (a.calibration.empty())
            throw Error("mirage response: --write needs --calibration FILE to write into");
        saveCameraResponse(a.calibration, fit.response);
        spdlog::info("response: written into {}", a.calibration);
    }
}

const CommandRegistrar reg("response", [](CLI::App& parent) {
    auto a = std::make_shared<ResponseArgs>();
    auto* cmd = parent.add_subcommand(
        "response",
        "Fit the camera's response curve from an exposure bracket (Debevec & Malik) and store it "
        "in its calibration file");
    cmd->add_option("bracket", a->bracket,
                    "Folder with the pictures of a still scene and exposures.csv "
                    "(file,exposure_seconds)")
        ->required()
        ->check(CLI::ExistingDirectory);
    cmd->add_option("--calibration", a->calibration,
                    "The camera's calibration YAML (the response is stored there with --write)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--samples", a->samples, "Pixels sampled by the fit")
        ->capture_default_str()
        ->check(wholeIn(16, 100000));
    cmd->add_option("--smoothness", a->smoothness, "Weight of the curve's smoothness term")
        ->capture_default_str()
        ->check(finiteIn(0.01, 1000));
    cmd->add_flag("--write", a->write, "Store the response in --calibration's file");
    cmd->callback([a] { runResponse(*a); });
});

}  // namespace
}  // namespace mirage::app
