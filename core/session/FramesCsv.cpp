#include "core/session/FramesCsv.h"

#include <array>
#include <charconv>
#include <cmath>
#include <map>

#include "core/Error.h"
#include "core/session/AtomicFile.h"
#include "core/session/PosesCsv.h"

namespace mirage {

namespace {

const std::array<const char*, 7> kGtColumns = {"gt_tx", "gt_ty", "gt_tz", "gt_qw",
                                               "gt_qx", "gt_qy", "gt_qz"};
constexpr int kMaxRowWarnings = 20;

std::string trim(std::string_view s) {
    size_t a = 0, b = s.size();
    while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
    while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r')) --b;
    return std::string(s.substr(a, b - a));
}

std::vector<std::string> split(std::string_view line) {
    std::vector<std::string> out;
    size_t start = 0;
    for (size_t i = 0; i <= line.size(); ++i) {
        if (i == line.size() || line[i] == ',') {
            out.push_back(trim(line.substr(start, i - start)));
            start = i + 1;
        }
    }
    return out;
}

bool parseDouble(const std::string& s, double& v) {
    if (s.empty()) return false;
    const char* end = s.data() + s.size();
    const auto [p, ec] = std::from_chars(s.data(), end, v);
    return ec == std::errc() && p == end && std::isfinite(v);
}

bool parseInt(const std::string& s, int& v) {
    if (s.empty()) return false;
    const char* end = s.data() + s.size();
    const auto [p, ec] = std::from_chars(s.data(), end, v);
    return ec == std::errc() && p == end;
}

void appendDouble(std::string& out, double v) {
    char buf[32];
    const auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, ec == std::errc() ? p : buf);
}

}  // namespace

std::vector<FrameRecord> readFramesCsv(const std::filesystem::path& path, double fps,
                                       const std::vector<std::string>& cameraNames,
                                       std::vector<std::string>& warnings) {
    const std::string file = path.filename().string();
    const std::string text = readFileBytes(path);
    const bool endsWithNewline = !text.empty() && text.back() == '\n';

    std::vector<std::string> lines;
    for (size_t start = 0; start < text.size();) {
        size_t nl = text.find('\n', start);
        if (nl == std::string::npos) nl = text.size();
        lines.push_back(text.substr(start, nl - start));
        start = nl + 1;
    }

    // Header: the first line that is neither empty nor a comment.
    size_t li = 0;
    while (li < lines.size() && (trim(lines[li]).empty() || trim(lines[li])[0] == '#')) ++li;
    if (li == lines.size())
        throw FileError(path.string(), "no header line (expected 'frame,t_main,...')");
    const std::vector<std::string> header = split(lines[li]);
    std::map<std::string, int> column;
    for (size_t i = 0; i < header.size(); ++i) column.emplace(header[i], int(i));
    auto col = [&](const std::string& name) {
        const auto it = column.find(name);
        return it == column.end() ? -1 : it->second;
    };
    const int frameCol = col("frame");
    if (frameCol < 0)
        throw FileError(path.string(),
                        "header has no 'frame' column (header: '" + trim(lines[li]) + "')");
    std::vector<int> timeCols;
    for (size_t c = 0; c < cameraNames.size(); ++c) {
        int tc = col("t_" + cameraNames[c]);
        if (tc < 0 && c == 0) tc = col("t");
        if (tc < 0)
            warnings.push_back(file + ": no column t_" + cameraNames[c] +
                               "; its frame times are taken as frame / fps");
        timeCols.push_back(tc);
    }
    std::array<int, 7> gtCols{};
    int gtFound = 0;
    for (size_t i = 0; i < kGtColumns.size(); ++i) {
        gtCols[i] = col(kGtColumns[i]);
        gtFound += gtCols[i] >= 0;
    }
    if (gtFound != 0 && gtFound != 7)
        warnings.push_back(file + ": only " + std::to_string(gtFound) +
                           " of the 7 gt_* columns; ground truth ignored");
    const bool hasGt = gtFound == 7;

    std::vector<FrameRecord> rows;
    int badRows = 0;
    auto bad = [&](size_t lineIndex, const std::string& why) {
        if (++badRows <= kMaxRowWarnings)
            warnings.push_back(file + " line " + std::to_string(lineIndex + 1) + ": " + why +
                               "; row skipped");
    };
    for (++li; li < lines.size(); ++li) {
        const std::string line = trim(lines[li]);
        if (line.empty() || line[0] == '#') continue;
        const bool lastUnterminated = li + 1 == lines.size() && !endsWithNewline;
        const std::vector<std::string> f = split(line);
        if (f.size() != header.size()) {
            bad(li, lastUnterminated ? "last row is cut short (the recording was interrupted)"
                                     : "has " + std::to_string(f.size()) + " fields, header has " +
                                           std::to_string(header.size()));
            continue;
        }
        FrameRecord r;
        if (!parseInt(f[size_t(frameCol)], r.index) || r.index < 0) {
            bad(li, "frame '" + f[size_t(frameCol)] + "' is not a non-negative integer");
            continue;
        }
        if (!rows.empty() && r.index <= rows.back().index) {
            bad(li, "frame " + std::to_string(r.index) + " does not follow frame " +
                        std::to_string(rows.back().index));
            continue;
        }
        bool ok = true;
        for (size_t c = 0; c < timeCols.size() && ok; ++c) {
            double t = r.index / fps;
            if (timeCols[c] >= 0 && !parseDouble(f[size_t(timeCols[c])], t)) {
                bad(li, "t_" + cameraNames[c] + " '" + f[size_t(timeCols[c])] +
                            "' is not a finite number");
                ok = false;
            }
            r.timestamps.push_back(t);
        }
        if (!ok) continue;
        if (hasGt) {
            int empty = 0;
            for (int gc : gtCols) empty += f[size_t(gc)].empty();
            if (empty == 7) {
                // No ground truth for this frame.
            } else {
                std::array<double, 7> g{};
                for (size_t i = 0; i < 7 && ok; ++i) {
                    if (!parseDouble(f[size_t(gtCols[i])], g[i])) {
                        bad(li, std::string(kGtColumns[i]) + " '" + f[size_t(gtCols[i])] +
                                    "' is not a finite number");
                        ok = false;
                    }
                }
                for (size_t i = 0; i < 3 && ok; ++i)
                    if (std::abs(g[i]) > kMaxPoseMetres) {
                        bad(li, std::string(kGtColumns[i]) + " " + f[size_t(gtCols[i])] +
                                    " m is beyond +-100 km (translations are metres)");
                        ok = false;
                    }
                if (!ok) continue;
                const double norm =
                    std::sqrt(g[3] * g[3] + g[4] * g[4] + g[5] * g[5] + g[6] * g[6]);
                // Written values are unit to ~1e-16; 1e-3 allows hand-edited files with fewer
                // digits and still catches a swapped or missing component.
                if (std::abs(norm - 1.0) > 1e-3) {
                    bad(li, "ground-truth quaternion has norm " + std::to_string(norm) +
                                " (expected 1; order is qw,qx,qy,qz)");
                    continue;
                }
                Pose p;
                p.translation = {g[0], g[1], g[2]};
                p.rotation = glm::dquat(g[3] / norm, g[4] / norm, g[5] / norm, g[6] / norm);
                r.groundTruth = p;
            }
        }
        // A camera clock never runs backwards: such a row is a damaged or spliced file.
        for (size_t c = 0; c < timeCols.size() && ok && !rows.empty(); ++c)
            if (timeCols[c] >= 0 && r.timestamps[c] < rows.back().timestamps[c]) {
                bad(li, "t_" + cameraNames[c] + " " + f[size_t(timeCols[c])] +
                            " goes back in time (frame " + std::to_string(rows.back().index) +
                            " was at " + std::to_string(rows.back().timestamps[c]) + " s)");
                ok = false;
            }
        if (!ok) continue;
        rows.push_back(std::move(r));
    }
    if (badRows > kMaxRowWarnings)
        warnings.push_back(file + ": " + std::to_string(badRows - kMaxRowWarnings) +
                           " more bad rows skipped");
    return rows;
}

std::string framesCsvHeader(const std::vector<std::string>& cameraNames) {
    std::string h = "frame";
    for (const auto& n : cameraNames) h += ",t_" + n;
    for (const char* g : kGtColumns) h += std::string(",") + g;
    return h + "\n";
}

std::string framesCsvRow(const FrameRecord& r) {
    std::string s = std::to_string(r.index);
    for (double t : r.timestamps) {
        s += ',';
        appendDouble(s, t);
    }
    if (r.groundTruth) {
        const Pose& p = *r.groundTruth;
        for (double v : {p.translation.x, p.translation.y, p.translation.z, p.rotation.w,
                         p.rotation.x, p.rotation.y, p.rotation.z}) {
            s += ',';
            appendDouble(s, v);
        }
    } else {
        s += ",,,,,,,";
    }
    return s + "\n";
}

}  // namespace mirage
