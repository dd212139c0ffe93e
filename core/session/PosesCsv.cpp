#include "core/session/PosesCsv.h"

#include <charconv>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/Csv.h"
#include "core/Error.h"
#include "core/session/AtomicFile.h"

namespace mirage {

// Reads a `mirage track` CSV: frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz (header required).
std::map<int, PoseRow> parsePosesCsv(const std::string& text, const std::string& path) {
    std::istringstream in(text);
    std::string line;
    if (!std::getline(in, line)) throw FileError(path, "empty poses file (no header)");
    const std::vector<std::string> header = splitCsvLine(line);
    auto col = [&](const std::string& name) {
        for (size_t i = 0; i < header.size(); ++i)
            if (header[i] == name) return int(i);
        throw FileError(path, "header has no column '" + name +
                                  "' (expected frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz)");
    };
    const int cFrame = col("frame"), cState = col("state"), cReason = col("reason");
    const int cP[7] = {col("tx"), col("ty"), col("tz"), col("qw"), col("qx"), col("qy"), col("qz")};
    std::map<int, PoseRow> rows;
    int lineNo = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty()) continue;
        // The reason column is quoted when it holds commas ("11 tag(s), RMS 0.17 px").
        std::vector<std::string> f = splitCsvLine(line);
        f.resize(header.size());
        PoseRow r;
        r.state = f[size_t(cState)];
        r.reason = f[size_t(cReason)];
        try {
            size_t used = 0;
            const int frame = std::stoi(f[size_t(cFrame)], &used);
            if (frame < 0 || used != f[size_t(cFrame)].size())
                throw FileError(path, "line " + std::to_string(lineNo) + ": frame number '" +
                                          f[size_t(cFrame)] + "' is not a whole number >= 0");
            if (!f[size_t(cP[0])].empty()) {
                double v[7];
                for (int i = 0; i < 7; ++i) v[i] = std::stod(f[size_t(cP[i])]);
                // A pose is used as given or not at all: NaN, infinity or a quaternion that is not
                // unit length (a zero one would silently become the identity) is an error.
                const double norm =
                    std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
                bool finite = true;
                for (double x : v) finite = finite && std::isfinite(x);
                if (!finite || std::abs(norm - 1.0) > 1e-3)
                    throw FileError(path,
                                    "line " + std::to_string(lineNo) + ": pose " +
                                        (finite ? "quaternion (qw,qx,qy,qz) has length " +
                                                      std::to_string(norm) +
                                                      "; expected a unit quaternion (1 +- 0.001)"
                                                : std::string("holds NaN or infinity")) +
                                        " (leave the pose empty for a frame without one)");
                Pose p;
                p.translation = {v[0], v[1], v[2]};
                p.rotation = glm::normalize(glm::dquat(v[3], v[4], v[5], v[6]));
                r.pose = p;
            }
            rows[frame] = r;
        } catch (const Error&) {
            throw;
        } catch (const std::exception&) {
            throw FileError(path, "line " + std::to_string(lineNo) +
                                      ": cannot parse frame number or pose numbers");
        }
    }
    return rows;
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
