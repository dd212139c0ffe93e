// `mirage bench` output: the per-configuration and per-frame CSVs and the markdown table
// (render/evaluation/RealtimeBench.h). Pass columns follow the frame graph's order.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

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
    out << "# mirage bench: medians over frames of ms per pass (syncPasses: wall time between the "
           "glFinish before and after each pass; otherwise GL timer queries);"
           " errors pooled over frames, 8-bit sRGB vs the ground-truth composite\n";
    out << "config,baseline";
    for (const auto& k : knobs) out << "," << k;
    out << ",width,height,frames";
    for (const auto& p : passes) out << "," << p << "_ms";
    out << ",gpu_ms,wall_ms,psnr_frame_db,ssim_frame,psnr_influenced_db,ssim_influenced,"
           "influenced_px,psnr_edges_db,edge_px\n";
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
            << num(r.error.ssimInfluenced, 5) << "," << num(r.error.influencedPixels, 0) << ","
            << num(r.error.psnrEdges, 3) << "," << num(r.error.edgePixels, 0) << "\n";
    }
    if (!out) throw FileError(path, "write failed");
}

void writeBenchFramesCsv(const std::string& path, const std::vector<BenchResult>& results) {
    std::ofstream out = openOut(path);
    const auto passes = passNames(results);
    out << "config,frame";
    for (const auto& p : passes) out << "," << p << "_ms";
    out << ",gpu_ms,wall_ms,psnr_frame_db,ssim_frame,psnr_influenced_db,ssim_influenced,"
           "influenced_px,psnr_edges_db,edge_px\n";
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
                << num(f.error.influencedPixels, 0) << "," << num(f.error.psnrEdges, 3) << ","
                << num(f.error.edgePixels, 0) << "\n";
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
    out << " **GPU ms** | frames/s | wall ms | PSNR dB | SSIM | PSNR infl. dB | SSIM infl. | "
           "PSNR edges dB |\n|";
    for (size_t i = 0; i < knobs.size(); ++i) out << "---|";
    for (size_t i = 0; i < passes.size() + 8; ++i) out << "---:|";
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
            << num(r.error.psnrInfluenced, 2) << " | " << num(r.error.ssimInfluenced, 4) << " | "
            << num(r.error.psnrEdges, 2) << " |\n";
    }
    if (!out) throw FileError(path, "write failed");
}

namespace {

nlohmann::json number(double v) {
    if (std::isfinite(v)) return v;
    return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
}

double number(const nlohmann::json& j) {
    if (j.is_number()) return j.get<double>();
    const std::string s = j.get<std::string>();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    throw Error("bench result: '" + s + "' is not a number");
}

nlohmann::json errorJson(const CompositeError& e) {
    return {number(e.psnrFrame),      number(e.ssimFrame),        number(e.psnrInfluenced),
            number(e.ssimInfluenced), number(e.influencedPixels), number(e.psnrEdges),
            number(e.edgePixels)};
}

CompositeError errorFromJson(const nlohmann::json& j) {
    CompositeError e;
    e.psnrFrame = number(j.at(0));
    e.ssimFrame = number(j.at(1));
    e.psnrInfluenced = number(j.at(2));
    e.ssimInfluenced = number(j.at(3));
    e.influencedPixels = number(j.at(4));
    if (j.size() > 6) {  // results written before the edge figure have five entries
        e.psnrEdges = number(j.at(5));
        e.edgePixels = number(j.at(6));
    }
    return e;
}

nlohmann::json msJson(const std::map<std::string, double>& ms) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [name, v] : ms) j[name] = number(v);
    return j;
}

std::map<std::string, double> msFromJson(const nlohmann::json& j) {
    std::map<std::string, double> ms;
    for (const auto& [name, v] : j.items()) ms[name] = number(v);
    return ms;
}

}  // namespace

nlohmann::json benchResultToJson(const BenchResult& r) {
    nlohmann::json frames = nlohmann::json::array();
    for (const auto& f : r.frames)
        frames.push_back({{"index", f.index},
                          {"pass_ms", msJson(f.passMs)},
                          {"gpu_ms", number(f.gpuMs)},
                          {"wall_ms", number(f.wallMs)},
                          {"error", errorJson(f.error)}});
    return {{"knobs", r.config.knobs},
            {"width", r.config.width},
            {"height", r.config.height},
            {"baseline", r.baseline},
            {"pass_order", r.passOrder},
            {"passes", r.passes},
            {"median_pass_ms", msJson(r.medianPassMs)},
            {"median_gpu_ms", number(r.medianGpuMs)},
            {"median_wall_ms", number(r.medianWallMs)},
            {"error", errorJson(r.error)},
            {"frames", frames}};
}

BenchResult benchResultFromJson(const nlohmann::json& j) {
    BenchResult r;
    r.config.knobs = j.at("knobs").get<std::vector<std::pair<std::string, std::string>>>();
    r.config.width = j.at("width").get<int>();
    r.config.height = j.at("height").get<int>();
    r.baseline = j.at("baseline").get<bool>();
    r.passOrder = j.at("pass_order").get<std::vector<std::string>>();
    r.passes = j.at("passes").get<std::vector<std::string>>();
    r.medianPassMs = msFromJson(j.at("median_pass_ms"));
    r.medianGpuMs = number(j.at("median_gpu_ms"));
    r.medianWallMs = number(j.at("median_wall_ms"));
    r.error = errorFromJson(j.at("error"));
    for (const auto& f : j.at("frames")) {
        BenchFrameResult fr;
        fr.index = f.at("index").get<int>();
        fr.passMs = msFromJson(f.at("pass_ms"));
        fr.gpuMs = number(f.at("gpu_ms"));
        fr.wallMs = number(f.at("wall_ms"));
        fr.error = errorFromJson(f.at("error"));
        r.frames.push_back(std::move(fr));
    }
    return r;
}

}  // namespace mirage::render
