#include "core/session/PosesCsv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/Csv.h"
#include "core/Error.h"
#include "core/session/AtomicFile.h"
#include "core/session/Session.h"

namespace mirage {

namespace {

const char* const kStates[] = {"ok",        "no_tags", "tags_too_small", "too_blurred",
                               "ambiguous", "lost",    "uncertain"};
const char* const kPoseFields[7] = {"tx", "ty", "tz", "qw", "qx", "qy", "qz"};

struct PoseColumns {
    int frame = -1, state = -1, reason = -1;
    int pose[7] = {};
};

PoseColumns poseColumns(const std::vector<std::string>& header, const std::string& path) {
    auto col = [&](const std::string& name) {
        for (size_t i = 0; i < header.size(); ++i)
            if (header[i] == name) return int(i);
        throw FileError(path, "header has no column '" + name +
                                  "' (expected frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz)");
    };
    PoseColumns c;
    c.frame = col("frame");
    c.state = col("state");
    c.reason = col("reason");
    for (int i = 0; i < 7; ++i) c.pose[i] = col(kPoseFields[i]);
    return c;
}

// The pose of one row (fields f), or nullopt when tx is empty. `where` is "path: line N".
std::optional<Pose> parsePose(const std::vector<std::string>& f, const PoseColumns& c,
                              const std::string& path, const std::string& where) {
    if (f[size_t(c.pose[0])].empty()) return std::nullopt;
    double v[7];
    for (int i = 0; i < 7; ++i) {
        const std::string& text = f[size_t(c.pose[i])];
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v[i]);
        if (text.empty() || ec != std::errc() || end != text.data() + text.size())
            throw FileError(
                path, where + ", field " + kPoseFields[i] + ": '" + text + "' is not a number");
        // A pose is used as given or not at all: NaN or infinity is an error.
        if (!std::isfinite(v[i]))
            throw FileError(path, where + ", field " + kPoseFields[i] + ": " + text +
                                      " (NaN or infinity; leave the pose empty for a frame "
                                      "without one)");
        if (i < 3 && std::abs(v[i]) > kMaxPoseMetres)
            throw FileError(path, where + ", field " + kPoseFields[i] + ": " + text +
                                      " m is beyond +-" + exactDecimal(kMaxPoseMetres) +
                                      " m (translations are metres)");
    }
    // A quaternion that is not unit length (a zero one would silently become the identity).
    const double norm = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (std::abs(norm - 1.0) > 1e-3)
        throw FileError(path, where + ": pose quaternion (qw,qx,qy,qz) has length " +
                                  std::to_string(norm) +
                                  "; expected a unit quaternion (1 +- 0.001)");
    Pose p;
    p.translation = {v[0], v[1], v[2]};
    p.rotation = glm::normalize(glm::dquat(v[3], v[4], v[5], v[6]));
    return p;
}

}  // namespace

bool isTrackingStateName(const std::string& state) {
    for (const char* s : kStates)
        if (state == s) return true;
    return false;
}

std::string trackingStateNames() {
    std::string list;
    for (const char* s : kStates) list += (list.empty() ? "" : ", ") + std::string(s);
    return list;
}

// Reads a `mirage track` CSV: frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz (header required).
std::map<int, PoseRow> parsePosesCsv(const std::string& text, const std::string& path) {
    std::istringstream in(text);
    std::string line;
    if (!std::getline(in, line)) throw FileError(path, "empty poses file (no header)");
    const std::vector<std::string> header = splitCsvLine(line);
    const PoseColumns c = poseColumns(header, path);
    std::map<int, PoseRow> rows;
    int lineNo = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty()) continue;
        const std::string where = "line " + std::to_string(lineNo);
        // The reason column is quoted when it holds commas ("11 tag(s), RMS 0.17 px").
        std::vector<std::string> f = splitCsvLine(line);
        f.resize(header.size());
        PoseRow r;
        r.line = lineNo;
        r.state = f[size_t(c.state)];
        r.reason = f[size_t(c.reason)];
        const std::string& frameText = f[size_t(c.frame)];
        int frame = -1;
        const auto [end, ec] =
            std::from_chars(frameText.data(), frameText.data() + frameText.size(), frame);
        if (frameText.empty() || ec != std::errc() || end != frameText.data() + frameText.size() ||
            frame < 0)
            throw FileError(
                path, where + ", field frame: '" + frameText + "' is not a whole number >= 0");
        if (const auto it = rows.find(frame); it != rows.end())
            throw FileError(path, where + ", field frame: frame " + std::to_string(frame) +
                                      " again (first on line " + std::to_string(it->second.line) +
                                      "); one row per frame");
        if (!isTrackingStateName(r.state))
            throw FileError(path, where + ", field state: '" + r.state + "' is not a state (" +
                                      trackingStateNames() + ")");
        r.pose = parsePose(f, c, path, where);
        if (r.state == "ok" && !r.pose)
            throw FileError(path, where + ", field tx: state ok without a pose");
        rows[frame] = r;
    }
    return rows;
}

void checkPoseFrames(const std::map<int, PoseRow>& poses, const Session& session,
                     const std::string& source) {
    std::vector<int> frames;
    for (const FrameRecord& r : session.frames) frames.push_back(r.index);
    std::sort(frames.begin(), frames.end());
    for (const auto& [frame, row] : poses)
        if (!std::binary_search(frames.begin(), frames.end(), frame))
            throw FileError(
                source, "line " + std::to_string(row.line) + ", field frame: frame " +
                            std::to_string(frame) + " is not a frame of the session (" +
                            (frames.empty() ? std::string("it has none")
                                            : "frames " + std::to_string(frames.front()) + ".." +
                                                  std::to_string(frames.back())) +
                            "); are these the poses of this session?");
}

std::string exactDecimal(double v) {
    char buf[64];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    MR_CHECK(ec == std::errc(), "exactDecimal: buffer too small");
    return std::string(buf, end);
}

std::string posesCsvHeader() {
    return "frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz\n";
}

std::string posesCsvRow(int frame, double t, const PoseRow& row) {
    std::string s = std::to_string(frame) + "," + exactDecimal(t) + "," + csvField(row.state) +
                    "," + csvField(row.reason);
    if (row.pose) {
        const Pose& p = *row.pose;
        for (double v : {p.translation.x, p.translation.y, p.translation.z, p.rotation.w,
                         p.rotation.x, p.rotation.y, p.rotation.z})
            s += "," + exactDecimal(v);
    } else {
        s += ",,,,,,,";
    }
    return s + "\n";
}

std::map<int, PoseRow> readPosesCsv(const std::filesystem::path& path) {
    if (!std::filesystem::is_regular_file(path))
        throw FileError(path.string(), "cannot open the poses file (does it exist?)");
    return parsePosesCsv(readFileBytes(path), path.string());
}

}  // namespace mirage
