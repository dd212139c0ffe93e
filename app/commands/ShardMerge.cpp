#include "app/commands/ShardMerge.h"

#include <fstream>
#include <memory>

#include <opencv2/imgcodecs.hpp>

#include <fmt/format.h>

#include "app/Command.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/image/ImageIO.h"
#include "core/session/MatroskaWriter.h"

namespace mirage::app {

namespace fs = std::filesystem;

namespace {

const char* const kBufferSuffixes[] = {"_Lr.exr", "_Lrv.exr", "_coverage.exr"};
const char* const kBufferFiles[] = {"Lr.exr", "Lrv.exr", "coverage.exr"};

// The rows `rows` of `full`, stacked.
cv::Mat takeRows(const cv::Mat& full, const std::vector<int>& rows) {
    cv::Mat out(int(rows.size()), full.cols, full.type());
    for (size_t i = 0; i < rows.size(); ++i) full.row(rows[i]).copyTo(out.row(int(i)));
    return out;
}

}  // namespace

void writeRenderShard(const fs::path& out, const RenderShard& rs) {
    const fs::path dir = shardFolder(out, rs.shard);
    StagedPath staged(dir);
    const fs::path& temp = staged.temp();
    fs::create_directories(temp);
    // EXR float keeps every value exactly, whatever the final format.
    writeLinearRgb(temp / "image.exr", takeRows(rs.image, rs.rows), 1.0f);
    for (size_t k = 0; k < rs.buffers.size(); ++k)
        writeLinearRgb(temp / kBufferFiles[k], takeRows(rs.buffers[k], rs.rows), 1.0f);
    ShardManifest m;
    m.command = "render";
    m.unit = "rows";
    m.shard = rs.shard;
    m.total = rs.image.rows;
    m.range = rs.range;
    m.items = rs.rows;
    m.fingerprint = rs.fingerprint;
    m.commandLine = commandLine();
    m.payload = {{"width", rs.image.cols},
                 {"height", rs.image.rows},
                 {"exposure", rs.exposure},
                 {"buffers", !rs.buffers.empty()}};
    writeShardManifest(temp, m);
    staged.commit();
    spdlog::info("wrote shard {}/{} ({} rows) to {}; when every shard is done: mirage merge {}",
                 rs.shard.index, rs.shard.count, rs.rows.size(), dir.string(), out.string());
}

void mergeRenderShards(const ShardSet& set, const fs::path& out, const fs::path& temp, bool force) {
    const ShardManifest& first = set.shards.front();
    const fs::path manifest = set.folders.front() / "shard.json";
    int width = 0, height = 0;
    float exposure = 1.0f;
    bool buffers = false;
    try {
        width = first.payload.at("width").get<int>();
        height = first.payload.at("height").get<int>();
        exposure = first.payload.at("exposure").get<float>();
        buffers = first.payload.at("buffers").get<bool>();
    } catch (const nlohmann::json::exception& e) {
        throw FileError(manifest.string(), std::string("payload is malformed: ") + e.what());
    }
    if (width < 1 || height != first.total)
        throw FileError(manifest.string(), "payload 'width'/'height' do not match 'total'");
    if (first.range.begin != 0 || first.range.end != height)
        throw Error(fmt::format(
            "mirage merge: the shards cover rows {}:{} of {}, not the whole image; an image needs "
            "every row (render the rest, or crop after merging)",
            first.range.begin, first.range.end, height));
    const size_t images = buffers ? 4 : 1;
    std::vector<cv::Mat> full(images);
    for (auto& m : full) m = cv::Mat::zeros(height, width, CV_32FC3);
    for (size_t s = 0; s < set.shards.size(); ++s) {
        const std::vector<int>& rows = set.shards[s].items;
        for (size_t k = 0; k < images; ++k) {
            const fs::path file = set.folders[s] / (k == 0 ? "image.exr" : kBufferFiles[k - 1]);
            const cv::Mat part = readLinearRgb(file);
            if (part.rows != int(rows.size()) || part.cols != width)
                throw FileError(file.string(),
                                fmt::format("is {}x{}, the manifest says {}x{}: rerun this shard",
                                            part.cols, part.rows, width, rows.size()));
            for (size_t i = 0; i < rows.size(); ++i) part.row(int(i)).copyTo(full[k].row(rows[i]));
        }
    }
    std::string ext = out.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    writeLinearRgb(temp, full[0], ext == ".png" ? exposure : 1.0f);
    if (buffers) {
        const OutputRule rule{{}, force, "mirage merge"};
        const fs::path stem = out.parent_path() / out.stem();
        for (size_t k = 1; k < images; ++k) {
            OutputFile f(stem.string() + kBufferSuffixes[k - 1], OutputOrigin::Derived, rule);
            writeLinearRgb(f.temp(), full[k], 1.0f);
            f.commit();
        }
    }
}

void writeBenchShard(const fs::path& out, const BenchShard& bs,
                     const std::function<void(const fs::path& dir)>& extraFiles) {
    const fs::path dir = shardFolder(out, bs.shard);
    StagedPath staged(dir);
    const fs::path& temp = staged.temp();
    fs::create_directories(temp);
    if (extraFiles) extraFiles(temp);
    nlohmann::json results = nlohmann::json::array();
    for (const auto& r : *bs.results) results.push_back(render::benchResultToJson(r));
    ShardManifest m;
    m.command = "bench";
    m.unit = "configurations";
    m.shard = bs.shard;
    m.total = bs.gridSize;
    m.items = bs.configurations;
    m.fingerprint = bs.fingerprint;
    m.commandLine = commandLine();
    m.payload = {{"results", results}, {"preamble", bs.preamble}, {"images", bs.images}};
    writeShardManifest(temp, m);
    staged.commit();
    spdlog::info(
        "wrote shard {}/{} ({} configurations) to {}; when every shard is done: mirage "
        "merge {}",
        bs.shard.index, bs.shard.count, bs.configurations.size(), dir.string(), out.string());
}

void mergeBenchShards(const ShardSet& set, const fs::path& temp) {
    std::vector<render::BenchResult> configurations(set.owner.size()), baselines;
    std::vector<bool> filled(set.owner.size(), false);
    std::string preamble, machines;
    for (size_t s = 0; s < set.shards.size(); ++s) {
        const ShardManifest& m = set.shards[s];
        const fs::path manifest = set.folders[s] / "shard.json";
        try {
            const nlohmann::json& results = m.payload.at("results");
            // The shard's configurations in its item order, then its footage-only rows.
            if (results.size() < m.items.size())
                throw FileError(manifest.string(), "holds fewer results than configurations");
            for (size_t i = 0; i < results.size(); ++i) {
                render::BenchResult r = render::benchResultFromJson(results[i]);
                if (i < m.items.size()) {
                    configurations[size_t(m.items[i])] = std::move(r);
                    filled[size_t(m.items[i])] = true;
                } else {
                    baselines.push_back(std::move(r));
                }
            }
            const std::string own = m.payload.at("preamble").get<std::string>();
            if (s == 0) preamble = own;
            // Each shard's machine line ("- machine: ...") goes into the merged header.
            const size_t at = own.find("- machine: ");
            const std::string line =
                at == std::string::npos ? "" : own.substr(at + 11, own.find('\n', at) - at - 11);
            machines += fmt::format("  - shard {}/{}: {}\n", m.shard.index, m.shard.count, line);
        } catch (const nlohmann::json::exception& e) {
            throw FileError(manifest.string(), std::string("payload is malformed: ") + e.what());
        }
        const fs::path images = set.folders[s] / "images";
        if (fs::is_directory(images)) {
            fs::create_directories(temp / "images");
            fs::copy(images, temp / "images", fs::copy_options::overwrite_existing);
        }
    }
    std::vector<render::BenchResult> all;
    const ShardManifest& first = set.shards.front();
    for (int i = first.range.begin; i < first.range.end; ++i) {
        MR_CHECK(filled[size_t(i)], "collectShards left a configuration out");
        all.push_back(std::move(configurations[size_t(i)]));
    }
    for (auto& b : baselines) all.push_back(std::move(b));
    preamble += fmt::format("- split: {} shards joined by `mirage merge`; each ran on\n{}",
                            set.shards.size(), machines);
    fs::create_directories(temp);
    render::writeBenchCsv((temp / "bench.csv").string(), all);
    render::writeBenchFramesCsv((temp / "bench_frames.csv").string(), all);
    render::writeBenchMarkdown((temp / "bench.md").string(), all, preamble);
}

void finishReplayShard(StagedPath& staged, const ReplayShard& rs) {
    ShardManifest m;
    m.command = "replay";
    m.unit = "frames";
    m.shard = rs.shard;
    m.total = rs.listed;
    m.range = rs.range;
    m.items = rs.frames;
    m.blocks = true;
    m.fingerprint = rs.fingerprint;
    m.commandLine = commandLine();
    m.payload = {{"video", rs.video},
                 {"fps", rs.fps},
                 {"jpeg_quality", rs.jpegQuality},
                 {"warmup", rs.warmup},
                 {"written", rs.written}};
    writeShardManifest(staged.temp(), m);
    staged.commit();
    const fs::path& dir = staged.finalPath();
    const fs::path out = rs.output;
    spdlog::info(
        "wrote shard {}/{} (frames {} to {}, {} warm-up frames before) to {}; when every "
        "shard is done: mirage merge {}",
        rs.shard.index, rs.shard.count, rs.frames.front(), rs.frames.back(), rs.warmup,
        dir.string(), out.string());
}

void mergeReplayShards(const ShardSet& set, const fs::path& out, const fs::path& temp, bool force) {
    const ShardManifest& first = set.shards.front();
    bool video = false;
    double fps = 30.0;
    int quality = 92;
    try {
        video = first.payload.at("video").get<bool>();
        fps = first.payload.at("fps").get<double>();
        quality = first.payload.at("jpeg_quality").get<int>();
    } catch (const nlohmann::json::exception& e) {
        throw FileError((set.folders.front() / "shard.json").string(),
                        std::string("payload is malformed: ") + e.what());
    }
    // The CSV: the first shard's header, then every shard's rows in order.
    std::string csv;
    std::unique_ptr<MatroskaWriter> writer;
    if (video)
        writer = std::make_unique<MatroskaWriter>(temp, fps, quality);
    else
        fs::create_directories(temp);
    for (size_t s = 0; s < set.shards.size(); ++s) {
        const fs::path csvPath = set.folders[s] / "frames.csv";
        std::ifstream in(csvPath);
        if (!in) throw FileError(csvPath.string(), "missing: rerun this shard");
        std::string header;
        std::getline(in, header);
        if (s == 0) csv += header + "\n";
        for (std::string row; std::getline(in, row);)
            if (!row.empty()) csv += row + "\n";
        std::vector<std::pair<int, double>> written;
        try {
            written =
                set.shards[s].payload.at("written").get<std::vector<std::pair<int, double>>>();
        } catch (const nlohmann::json::exception& e) {
            throw FileError((set.folders[s] / "shard.json").string(),
                            std::string("payload is malformed: ") + e.what());
        }
        for (const auto& [frame, t] : written) {
            const fs::path png = set.folders[s] / cv::format("frame_%06d.png", frame);
            if (video) {
                const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
                if (img.empty())
                    throw FileError(png.string(), "missing or unreadable: rerun this shard");
                writer->append(img, t);
            } else {
                fs::copy_file(png, temp / png.filename(), fs::copy_options::overwrite_existing);
            }
        }
    }
    if (writer) writer->close();
    const fs::path csvOut = video ? fs::path(out).replace_extension(".csv") : temp / "frames.csv";
    if (video) {
        OutputFile f(csvOut, OutputOrigin::Derived, OutputRule{{}, force, "mirage merge"});
        std::ofstream(f.temp()) << csv;
        f.commit();
    } else {
        std::ofstream(csvOut) << csv;
    }
}

}  // namespace mirage::app
