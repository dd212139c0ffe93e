// `mirage bench` output: the per-configuration and per-frame CSVs and the markdown table
// (render/evaluation/RealtimeBench.h). Pass columns follow the frame graph's order.
#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/evaluation/RealtimeBench.h"

namespace mirage::render {
namespace {

std::string num(double v, int decimals) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return fmt::format("{:.{}f}", v, decimals);
}

std::vector<std::string> knobNames(const std::vector<BenchResult>& results) {
    std::vector<std::string> names;
    for (const auto& k : benchKnobs()) names.push_back(k.name);
    for (const auto& r : results)
        for (const auto& [n, v] : r.config.knobs)
            if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    return names;
}

// The passes that ran in any result, in the frame graph's order (Renderer::passNames).
std::vector<std::string> passNames(const std::vector<BenchResult>& results) {
    std::vector<std::string> order, names;
    for (const auto& r : results)
        if (!r.passOrder.empty()) order = r.passOrder;
    for (const std::string& p : order)
        for (const auto& r : results)
            if (std::find(r.passes.begin(), r.passes.end(), p) != r.passes.end()) {
                names.push_back(p);
                break;
            }
    return names;
}

std::string knobValue(const BenchConfig& c, const std::string& name) {
    for (const auto& [n, v] : c.knobs)
        if (n == name) return v;
    return "";
}

std::ofstream openOut(const std::string& path) {
    std::ofstream out(path);
    if (!out) throw FileError(path, "cannot create the file (does the folder exist?)");
    return out;
}

}  // namespace

void writeBenchCsv(const std::string& path, const std::vector<BenchResult>& results) {
    std::ofstream out = openOut(path);
    const auto knobs = knobNames(results);
    const auto passes = passNames(results);
    out << "# mirage bench: medians over frames of GPU ms per pass (GL timer queries, syncPasses);"
           " errors pooled over frames, 8-bit sRGB vs the ground-truth composite\n";
    out << "config,baseline";
    for (const auto& k : knobs) out << "," << k;
    out << ",width,height,frames";
    for (const auto& p : passes) out << "," << p << "_ms";
    out << ",gpu_ms,wall_ms,psnr_frame_db,ssim_frame,psnr_influenced_db,ssim_influenced,"
           "influenced_px\n";
    for (const auto& r : results) {
        out << '"' << (r.baseline ? "footage (no virtual objects)" : r.config.label()) << '"' << ","
            << (r.baseline ? 1 : 0);
        for (const auto& k : knobs) out << "," << knobValue(r.config, k);
        out << "," << r.config.width << "," << r.config.height << "," << r.frames.size();
        for (const auto& p : passes) {
            const auto it = r.medianPassMs.find(p);
            out << "," << (it == r.medianPassMs.end() ? "" : num(it->second, 3));
        }
        out << "," << (r.baseline ? "" : num(r.medianGpuMs, 3)) << ","
            << (r.baseline ? "" : num(r.medianWallMs, 3)) << "," << num(r.error.psnrFrame, 3) << ","
            << num(r.error.ssimFrame, 5) << "," << num(r.error.psnrInfluenced, 3) << ","
            << num(r.error.ssimInfluenced, 5) << "," << num(r.error.influencedPixels, 0) << "\n";
    }
    if (!out) throw FileError(path, "write failed");
}

void writeBenchFramesCsv(const std::string& path, const std::vector<BenchResult>& results) {
    std::ofstream out = openOut(path);
    const auto passes = passNames(results);
    out << "config,frame";
    for (const auto& p : passes) out << "," << p << "_ms";
    out << ",gpu_ms,wall_ms,psnr_frame_db,ssim_frame,psnr_influenced_db,ssim_influenced,"
           "influenced_px\n";
    for (const auto& r : results)
        for (const auto& f : r.frames) {
            out << '"' << (r.baseline ? "footage (no virtual objects)" : r.config.label()) << '"'
                << "," << f.index;
            for (const auto& p : passes) {
                const auto it = f.passMs.find(p);
                out << "," << (it == f.passMs.end() ? "" : num(it->second, 3));
            }
            out << "," << num(f.gpuMs, 3) << "," << num(f.wallMs, 3) << ","
                << num(f.error.psnrFrame, 3) << "," << num(f.error.ssimFrame, 5) << ","
                << num(f.error.psnrInfluenced, 3) << "," << num(f.error.ssimInfluenced, 5) << ","
                << num(f.error.influencedPixels, 0) << "\n";
        }
    if (!out) throw FileError(path, "write failed");
}

void writeBenchMarkdown(const std::string& path, const std::vector<BenchResult>& results,
                        const std::string& preamble) {
    std::ofstream out = openOut(path);
    const auto knobs = knobNames(results);
    const auto passes = passNames(results);
    out << preamble << "\n";
    out << "|";
    for (const auto& k : knobs) out << " " << k << " |";
    for (const auto& p : passes) out << " " << p << " |";
    out << " **GPU ms** | frames/s | wall ms | PSNR dB | SSIM | PSNR infl. dB | SSIM infl. |\n|";
    for (size_t i = 0; i < knobs.size(); ++i) out << "---|";
    for (size_t i = 0; i < passes.size() + 7; ++i) out << "---:|";
    out << "\n";
    for (const auto& r : results) {
        out << "|";
        for (size_t i = 0; i < knobs.size(); ++i) {
            std::string v = knobValue(r.config, knobs[i]);
            if (r.baseline && i + 1 == knobs.size()) v = "footage only";
            out << " " << (v.empty() ? "–" : v) << " |";
        }
        for (const auto& p : passes) {
            const auto it = r.medianPassMs.find(p);
            out << " " << (it == r.medianPassMs.end() ? "–" : num(it->second, 1)) << " |";
        }
        if (r.baseline)
            out << " – | – | – |";
        else
            out << " **" << num(r.medianGpuMs, 1) << "** | "
                << num(r.medianGpuMs > 0 ? 1000.0 / r.medianGpuMs : 0.0, 1) << " | "
                << num(r.medianWallMs, 1) << " |";
        out << " " << num(r.error.psnrFrame, 2) << " | " << num(r.error.ssimFrame, 4) << " | "
            << num(r.error.psnrInfluenced, 2) << " | " << num(r.error.ssimInfluenced, 4) << " |\n";
    }
    if (!out) throw FileError(path, "write failed");
}

}  // namespace mirage::render
