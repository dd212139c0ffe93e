#include "core/session/Session.h"
#include "core/session/SessionReadOptions.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/Log.h"
#include "core/camera/CalibrationFile.h"
#include "core/session/AtomicFile.h"
#include "core/session/FrameInventory.h"
#include "core/session/FramesCsv.h"

namespace mirage {

using nlohmann::json;

const SessionCamera* Session::camera(const std::string& name) const {
    const int i = cameraIndex(name);
    return i < 0 ? nullptr : &cameras[size_t(i)];
}

int Session::cameraIndex(const std::string& name) const {
    for (size_t i = 0; i < cameras.size(); ++i)
        if (cameras[i].name == name) return int(i);
    return -1;
}

CameraCalibration loadSessionCalibration(const Session& s, const std::string& camera) {
    const SessionCamera* c = s.camera(camera);
    const std::string json = (s.dir / "session.json").string();
    if (!c) throw FileError(json, "no camera named '" + camera + "'");
    if (c->calibration.empty())
        throw FileError(
            json, "camera '" + camera + "' names no calibration file (set cameras[].calibration)");
    return loadCalibration(s.path(c->calibration));
}

void writeSessionJson(const Session& s) {
    json j;
    j["format"] = s.format;
    j["version"] = s.version;
    j["fps"] = s.fps;
    json cams = json::array();
    for (const auto& c : s.cameras) {
        json cj{{"name", c.name}, {"video", c.video}, {"role", c.role}};
        if (!c.calibration.empty()) cj["calibration"] = c.calibration;
        cams.push_back(cj);
    }
    j["cameras"] = cams;
    j["frames"] = s.framesFile;
    if (!s.board.empty()) j["board"] = s.board;
    if (!s.scene.empty()) j["scene"] = s.scene;
    j["created"] = {{"by", s.createdBy}, {"at", s.createdAt}};
    writeFileAtomically(s.dir / "session.json", j.dump(2) + "\n");
}

namespace {

// Field access with errors that name the field: "session.json: field 'cameras[1].video': ...".
struct JsonReader {
    std::string file;

    [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
        throw FileError(file, "field '" + field + "': " + problem);
    }
    std::string string(const json& j, const std::string& key, const std::string& field,
                       bool required, const std::string& fallback = {}) const {
        if (!j.contains(key)) {
            if (required) fail(field, "missing");
            return fallback;
        }
        if (!j[key].is_string()) fail(field, "expected a string");
        return j[key].get<std::string>();
    }
};

// A relative path inside the session folder (no absolute paths, no "..").
void checkRelative(const JsonReader& r, const std::string& field, const std::string& p) {
    const std::filesystem::path path(p);
    if (path.is_absolute()) r.fail(field, "must be relative to the session folder: '" + p + "'");
    for (const auto& part : path)
        if (part == "..") r.fail(field, "must stay inside the session folder: '" + p + "'");
}

}  // namespace

Session readSession(const std::filesystem::path& dir, SessionReadReport* reportOut) {
    return readSession(dir, reportOut, SessionReadOptions{});
}

Session readSession(const std::filesystem::path& dir, SessionReadReport* reportOut,
                    const SessionReadOptions& options) {
    SessionReadReport report;
    if (!std::filesystem::is_directory(dir))
        throw FileError(dir.string(), "not a folder (a session is a folder with session.json)");
    const auto jsonPath = dir / "session.json";
    if (!std::filesystem::is_regular_file(jsonPath))
        throw FileError(jsonPath.string(), "missing: the folder is not a mirage session");
    const JsonReader r{jsonPath.string()};

    json j;
    try {
        j = json::parse(readFileBytes(jsonPath));
    } catch (const json::exception& e) {
        // parse_error, and out_of_range for a number that overflows a double ("1e999", found
        // by session_fuzz).
        throw FileError(jsonPath.string(), std::string("not valid JSON: ") + e.what());
    }
    if (!j.is_object()) throw FileError(jsonPath.string(), "expected a JSON object at the top");

    Session s;
    s.dir = dir;
    s.format = r.string(j, "format", "format", true);
    if (s.format != kSessionFormat)
        r.fail("format", "is '" + s.format + "', expected '" + kSessionFormat + "'");
    if (!j.contains("version")) r.fail("version", "missing");
    if (!j["version"].is_number_integer()) r.fail("version", "expected an integer");
    s.version = j["version"].get<int>();
    if (s.version < 1) r.fail("version", "must be >= 1");
    if (s.version > kSessionVersion)
        r.fail("version", std::to_string(s.version) + " is newer than this mirage reads (" +
                              std::to_string(kSessionVersion) + "); update mirage");

    if (j.contains("fps")) {
        if (!j["fps"].is_number() || !(j["fps"].get<double>() > 0) ||
            !std::isfinite(j["fps"].get<double>()))
            r.fail("fps", "expected a positive number (frames per second)");
        s.fps = j["fps"].get<double>();
    } else {
        report.warnings.push_back("session.json: no 'fps'; assuming 30");
    }

    if (!j.contains("cameras") || !j["cameras"].is_array() || j["cameras"].empty())
        r.fail("cameras", "expected a non-empty list of cameras");
    for (size_t i = 0; i < j["cameras"].size(); ++i) {
        const json& cj = j["cameras"][i];
        const std::string f = "cameras[" + std::to_string(i) + "]";
        if (!cj.is_object()) r.fail(f, "expected an object with name, video, calibration, role");
        SessionCamera c;
        c.name = r.string(cj, "name", f + ".name", true);
        if (c.name.empty() || c.name.find_first_of(", \t/") != std::string::npos)
            r.fail(f + ".name", "must be a non-empty word (it names a frames.csv column)");
        if (s.cameraIndex(c.name) >= 0) r.fail(f + ".name", "duplicate camera '" + c.name + "'");
        c.video = r.string(cj, "video", f + ".video", true);
        checkRelative(r, f + ".video", c.video);
        c.calibration = r.string(cj, "calibration", f + ".calibration", false);
        checkRelative(r, f + ".calibration", c.calibration);
        c.role = r.string(cj, "role", f + ".role", false, i == 0 ? "main" : "environment");
        if (c.role != "main" && c.role != "environment")
            r.fail(f + ".role", "must be 'main' or 'environment', got '" + c.role + "'");
        s.cameras.push_back(c);
    }
    if (s.cameras[0].role != "main")
        r.fail("cameras[0].role", "the first camera must be the main camera");

    s.board = r.string(j, "board", "board", false);
    checkRelative(r, "board", s.board);
    s.scene = r.string(j, "scene", "scene", false);
    s.framesFile = r.string(j, "frames", "frames", false, "frames.csv");
    checkRelative(r, "frames", s.framesFile);
    if (j.contains("created") && j["created"].is_object()) {
        s.createdBy = r.string(j["created"], "by", "created.by", false);
        s.createdAt = r.string(j["created"], "at", "created.at", false);
    }

    // Files named by session.json: missing ones are warnings, the footage may still be usable.
    if (!s.board.empty() && !std::filesystem::exists(s.path(s.board)))
        report.warnings.push_back("board file " + s.board + " is missing");
    for (const auto& c : s.cameras) {
        if (c.calibration.empty()) continue;
        try {
            loadCalibration(s.path(c.calibration));
        } catch (const Error& e) {
            report.warnings.push_back("camera '" + c.name + "' calibration: " + e.what());
        }
    }

    // What each camera's video actually holds.
    std::vector<FrameInventory> inventories;
    for (const auto& c : s.cameras) {
        try {
            FrameInventory inv = inventoryFrames(s.path(c.video));
            for (auto& p : inv.problems) report.warnings.push_back("camera '" + c.name + "': " + p);
            inventories.push_back(std::move(inv));
        } catch (const Error& e) {
            report.warnings.push_back("camera '" + c.name + "': " + e.what());
            inventories.push_back(FrameInventory{});  // no frames
        }
    }

    std::vector<std::string> names;
    for (const auto& c : s.cameras) names.push_back(c.name);
    std::vector<FrameRecord> rows;
    const auto csvPath = s.path(s.framesFile);
    bool haveFrameList = false;
    if (std::filesystem::is_regular_file(csvPath)) {
        try {
            rows = readFramesCsv(csvPath, s.fps, names, report.warnings);
            haveFrameList = true;
        } catch (const FileError& e) {
            report.warnings.push_back(std::string(e.what()) +
                                      "; frames taken from the main video alone");
        }
    } else {
        report.warnings.push_back(s.framesFile +
                                  " is missing; frames taken from the main video alone");
    }
    if (!haveFrameList) {
        // No frame list: one row per frame of the main camera, times from the frame rate.
        const FrameInventory& main = inventories[0];
        std::vector<int> indices;
        if (main.isFolder)
            for (const auto& [i, p] : main.images) indices.push_back(i);
        else
            for (int i = 0; i < main.videoFrames; ++i) indices.push_back(i);
        for (int i : indices) {
            FrameRecord fr;
            fr.index = i;
            fr.timestamps.assign(s.cameras.size(), i / s.fps);
            rows.push_back(fr);
        }
    }
    report.framesListed = int(rows.size());

    // Keep the rows whose images every camera has (every camera but the environment cameras,
    // when the reader can do without them).
    auto required = [&](size_t ci) {
        return !(options.environmentOptional && ci > 0 && s.cameras[ci].role == "environment");
    };
    for (size_t ci = 0; ci < s.cameras.size(); ++ci) {
        int missing = 0, firstMissing = -1;
        for (const auto& row : rows)
            if (!inventories[ci].has(row.index) && missing++ == 0) firstMissing = row.index;
        if (missing > 0)
            report.warnings.push_back(
                "camera '" + s.cameras[ci].name + "': " + std::to_string(missing) + " of " +
                std::to_string(rows.size()) + " listed frames are not in " + s.cameras[ci].video +
                " (first: frame " + std::to_string(firstMissing) + "); " +
                (required(ci) ? "those rows are dropped" : "those frames have no image of it"));
        const int held = inventories[ci].count();
        const int lastListed = rows.empty() ? -1 : rows.back().index;
        if (!inventories[ci].isFolder && held > int64_t(lastListed) + 1 && !rows.empty())
            report.warnings.push_back(
                "camera '" + s.cameras[ci].name + "': " + s.cameras[ci].video + " holds " +
                std::to_string(held) + " frames but " + s.framesFile + " ends at frame " +
                std::to_string(lastListed) + "; the frames after it have no row and are ignored");
    }
    for (auto& row : rows) {
        bool all = true;
        for (size_t ci = 0; ci < inventories.size(); ++ci)
            all = all && (!required(ci) || inventories[ci].has(row.index));
        if (all) s.frames.push_back(std::move(row));
    }
    report.framesReadable = int(s.frames.size());

    // A caller that asks for the report shows it its own way; otherwise nothing is lost.
    if (reportOut)
        *reportOut = std::move(report);
    else
        for (const auto& w : report.warnings) spdlog::warn("session {}: {}", dir.string(), w);
    return s;
}

std::vector<std::filesystem::path> sessionInputs(const Session& s) {
    std::vector<std::filesystem::path> files = {s.dir, s.dir / "session.json",
                                                s.path(s.framesFile)};
    if (!s.board.empty()) files.push_back(s.path(s.board));
    for (const auto& c : s.cameras) {
        if (!c.video.empty()) files.push_back(s.path(c.video));
        if (!c.calibration.empty()) files.push_back(s.path(c.calibration));
    }
    return files;
}

}  // namespace mirage
