#include "render/raytrace/GroundTruthComposite.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "core/session/AtomicFile.h"

namespace mirage::render {
namespace {

namespace fs = std::filesystem;

// The folder names must stay inside the session folder (as every session path does).
void checkRelative(const fs::path& file, const std::string& field, const std::string& value) {
    const fs::path p(value);
    bool escapes = value.empty() || p.is_absolute();
    for (const auto& part : p)
        if (part == "..") escapes = true;
    if (escapes)
        throw FileError(file.string(), "field '" + field +
                                           "' must be a non-empty relative folder inside the "
                                           "session (no absolute path, no '..'): '" +
                                           value + "'");
}

fs::path framePath(const fs::path& dir, const std::string& folder, int frameIndex) {
    return dir / folder / cv::format("%06d.png", frameIndex);
}

cv::Mat readPng(const fs::path& path, int flags) {
    cv::Mat m = cv::imread(path.string(), flags);
    if (m.empty()) throw FileError(path.string(), "cannot decode the ground-truth image");
    return m;
}

}  // namespace

std::optional<GroundTruthInfo> readGroundTruthInfo(const fs::path& sessionDir) {
    const fs::path file = sessionDir / kGroundTruthFile;
    if (!fs::exists(file)) return std::nullopt;
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(readFileBytes(file));
    } catch (const nlohmann::json::exception& e) {
        throw FileError(file.string(), std::string("not valid JSON: ") + e.what());
    }
    if (!j.is_object() || j.value("format", "") != kGroundTruthFormat)
        throw FileError(file.string(),
                        std::string("'format' must be \"") + kGroundTruthFormat + "\"");
    GroundTruthInfo info;
    try {
        const int version = j.at("version").get<int>();
        if (version > kGroundTruthVersion)
            throw FileError(file.string(), "version " + std::to_string(version) +
                                               " is newer than this mirage reads (" +
                                               std::to_string(kGroundTruthVersion) +
                                               "); update mirage");
        info.compositeFolder = j.value("composite", info.compositeFolder);
        info.influenceFolder = j.value("influence", info.influenceFolder);
        info.scene = j.value("scene", std::string());
        info.influenceThreshold = j.value("influence_threshold", info.influenceThreshold);
        info.samplesPerPixel = j.value("spp", 0);
        info.seed = j.value("seed", uint64_t(0));
    } catch (const nlohmann::json::exception& e) {
        throw FileError(file.string(), std::string("a field has the wrong type or 'version' is "
                                                   "missing: ") +
                                           e.what());
    }
    checkRelative(file, "composite", info.compositeFolder);
    checkRelative(file, "influence", info.influenceFolder);
    return info;
}

void writeGroundTruthInfo(const fs::path& sessionDir, const GroundTruthInfo& info) {
    nlohmann::json j;
    j["format"] = kGroundTruthFormat;
    j["version"] = kGroundTruthVersion;
    j["composite"] = info.compositeFolder;
    j["influence"] = info.influenceFolder;
    j["scene"] = info.scene;
    j["influence_threshold"] = info.influenceThreshold;
    j["spp"] = info.samplesPerPixel;
    j["seed"] = info.seed;
    j["encoding"] =
        "composite: 8-bit BGR PNG, sRGB; influence: 8-bit grey PNG, 255 virtual, 128 changed, "
        "0 untouched";
    writeFileAtomically(sessionDir / kGroundTruthFile, j.dump(2) + "\n");
}

fs::path groundTruthCompositePath(const fs::path& sessionDir, const GroundTruthInfo& info,
                                  int frameIndex) {
    return framePath(sessionDir, info.compositeFolder, frameIndex);
}

fs::path groundTruthInfluencePath(const fs::path& sessionDir, const GroundTruthInfo& info,
                                  int frameIndex) {
    return framePath(sessionDir, info.influenceFolder, frameIndex);
}

std::optional<GroundTruthFrame> readGroundTruthFrame(const fs::path& sessionDir,
                                                     const GroundTruthInfo& info, int frameIndex) {
    const fs::path c = groundTruthCompositePath(sessionDir, info, frameIndex);
    const fs::path m = groundTruthInfluencePath(sessionDir, info, frameIndex);
    if (!fs::exists(c) || !fs::exists(m)) return std::nullopt;
    GroundTruthFrame f;
    f.compositeSrgb = readPng(c, cv::IMREAD_COLOR);
    f.influence = readPng(m, cv::IMREAD_GRAYSCALE);
    if (f.compositeSrgb.size() != f.influence.size())
        throw FileError(m.string(), "size differs from its composite " + c.string());
    return f;
}

void writeGroundTruthFrame(const fs::path& sessionDir, const GroundTruthInfo& info, int frameIndex,
                           const GroundTruthFrame& frame) {
    MR_CHECK(frame.compositeSrgb.type() == CV_8UC3, "ground-truth composite must be 8-bit BGR");
    MR_CHECK(frame.influence.type() == CV_8U, "influence mask must be 8-bit grey");
    fs::create_directories(sessionDir / info.compositeFolder);
    fs::create_directories(sessionDir / info.influenceFolder);
    writeBgr8(groundTruthCompositePath(sessionDir, info, frameIndex), frame.compositeSrgb);
    writeBgr8(groundTruthInfluencePath(sessionDir, info, frameIndex), frame.influence);
}

cv::Mat influenceMask(const cv::Mat& realOnly, const cv::Mat& realAndVirtual,
                      const cv::Mat& virtualCoverage, double gain, double threshold) {
    MR_CHECK(realOnly.type() == CV_32FC3 && realAndVirtual.type() == CV_32FC3 &&
                 realOnly.size() == realAndVirtual.size(),
             "influenceMask: L_r and L_rv must be linear RGB float of equal size");
    MR_CHECK(virtualCoverage.empty() ||
                 (virtualCoverage.type() == CV_32F && virtualCoverage.size() == realOnly.size()),
             "influenceMask: coverage must be CV_32F of the images' size");
    cv::Mat diff;
    cv::absdiff(realAndVirtual, realOnly, diff);
    diff = diff.reshape(1, int(diff.total()));
    cv::Mat maxDiff;
    cv::reduce(diff, maxDiff, 1, cv::REDUCE_MAX);
    maxDiff = maxDiff.reshape(1, realOnly.rows) * gain;
    // Averaged over 5x5 pixels before the threshold: a path that bounces off a virtual object
    // makes L_rv and L_r differ by Monte Carlo noise in isolated pixels all over the image; the
    // average keeps coherent changes (a shadow, bounced light) and drops that speckle.
    cv::Mat smoothDiff;
    cv::boxFilter(maxDiff, smoothDiff, -1, cv::Size(5, 5), cv::Point(-1, -1), true,
                  cv::BORDER_REPLICATE);
    cv::Mat mask(realOnly.size(), CV_8U, cv::Scalar(kInfluenceNone));
    mask.setTo(kInfluenceChanged, smoothDiff > threshold);
    // NaN never compares greater, so a broken render cannot mark pixels "untouched" silently:
    // non-finite differences count as changed.
    mask.setTo(kInfluenceChanged, maxDiff != maxDiff);
    if (!virtualCoverage.empty()) mask.setTo(kInfluenceVirtual, virtualCoverage > 0.0f);
    return mask;
}

}  // namespace mirage::render
