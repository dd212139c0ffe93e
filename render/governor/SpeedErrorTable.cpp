#include "render/governor/SpeedErrorTable.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "core/Csv.h"
#include "core/Error.h"

namespace mirage::render {

SpeedErrorTable::SpeedErrorTable(std::vector<SpeedErrorRow> rows) : rows_(std::move(rows)) {
    for (const SpeedErrorRow& r : rows_) {
        if (!(std::isfinite(r.frameMs) && r.frameMs > 0.0 && std::isfinite(r.psnrDb)))
            throw Error(
                fmt::format("speed-vs-error table: the row '{}' has no valid time ({}) or "
                            "error ({})",
                            describeQualitySetting(r.setting), r.frameMs, r.psnrDb));
        RendererOptions probe;
        applyQualitySetting(r.setting, probe);  // throws on an unknown knob or a bad value
    }
}

bool SpeedErrorTable::dominated(const SpeedErrorRow& a, const SpeedErrorRow& b) {
    return b.frameMs <= a.frameMs && b.psnrDb >= a.psnrDb &&
           (b.frameMs < a.frameMs || b.psnrDb > a.psnrDb);
}

std::vector<SpeedErrorRow> SpeedErrorTable::paretoFront() const {
    std::vector<SpeedErrorRow> front;
    for (size_t i = 0; i < rows_.size(); ++i) {
        bool beaten = false;
        for (size_t j = 0; j < rows_.size() && !beaten; ++j)
            beaten = j != i && dominated(rows_[i], rows_[j]);
        // Of rows equal in both, the first stands for all.
        for (const SpeedErrorRow& f : front)
            beaten = beaten || (f.frameMs == rows_[i].frameMs && f.psnrDb == rows_[i].psnrDb);
        if (!beaten) front.push_back(rows_[i]);
    }
    std::sort(front.begin(), front.end(),
              [](const SpeedErrorRow& a, const SpeedErrorRow& b) { return a.frameMs < b.frameMs; });
    return front;
}

SpeedErrorTable SpeedErrorTable::readBenchCsv(const std::string& path) {
    std::ifstream in(path);
    if (!in)
        throw Error(
            fmt::format("speed-vs-error table {}: cannot be read (write one with "
                        "`mirage bench SESSION -o DIR --knob ...`: DIR/bench.csv)",
                        path));
    std::string line;
    std::vector<std::string> header;
    while (std::getline(in, line))
        if (!line.empty() && line[0] != '#') {
            header = splitCsvLine(line);
            break;
        }
    auto column = [&](const std::string& name) {
        const auto it = std::find(header.begin(), header.end(), name);
        return it == header.end() ? -1 : int(it - header.begin());
    };
    int timeCol = column("wall_ms");
    if (timeCol < 0) timeCol = column("gpu_ms");
    const int errorCol = column("psnr_influenced_db");
    if (timeCol < 0 || errorCol < 0)
        throw Error(
            fmt::format("speed-vs-error table {}: no 'wall_ms' (or 'gpu_ms') and "
                        "'psnr_influenced_db' columns (is it a `mirage bench` bench.csv?)",
                        path));
    std::vector<std::pair<std::string, int>> knobColumns;
    for (const std::string& k : governedKnobNames())
        if (column(k) >= 0) knobColumns.push_back({k, column(k)});
    std::vector<SpeedErrorRow> rows;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty() || line[0] == '#') continue;
        const std::vector<std::string> f = splitCsvLine(line);
        const auto field = [&](int c) { return c < int(f.size()) ? f[size_t(c)] : std::string(); };
        if (field(timeCol).empty() || field(errorCol).empty()) continue;  // footage only
        SpeedErrorRow r;
        try {
            r.frameMs = std::stod(field(timeCol));
            r.psnrDb = std::stod(field(errorCol));
        } catch (const std::exception&) {
            throw Error(
                fmt::format("speed-vs-error table {}: data row {}: '{}' / '{}' is not a "
                            "number",
                            path, lineNo, field(timeCol), field(errorCol)));
        }
        for (const auto& [k, c] : knobColumns)
            if (!field(c).empty()) r.setting[k] = field(c);
        rows.push_back(std::move(r));
    }
    if (rows.empty())
        throw Error(fmt::format("speed-vs-error table {}: no row with a time and an error", path));
    try {
        return SpeedErrorTable(std::move(rows));
    } catch (const Error& e) {
        throw Error(fmt::format("speed-vs-error table {}: {}", path, e.what()));
    }
}

}  // namespace mirage::render
