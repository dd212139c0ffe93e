#include "core/session/Session.h"
#include "core/session/SessionReadOptions.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "core/ContainedPath.h"
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
        if (c.shutter) cj["shutter"] = *c.shutter;
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

// A file the session names: inside the session folder (core/ContainedPath.h). Empty names are
// for optional files the session leaves out.
void checkContained(const JsonReader& r, const std::string& field, const std::string& p) {
    if (p.empty()) return;
    const std::string problem = containedReferenceProblem(p);
    if (!problem.empty())
        r.fail(field, "'" + p + "' " + problem + "; name a file inside the session folder");
}

json parseSessionJson(const std::filesystem::path& jsonPath) {
    try {
        json j = json::parse(readFileBytes(jsonPath));
        if (!j.is_object()) throw FileError(jsonPath.string(), "expected a JSON object at the top");
        return j;
    } catch (const json::exception& e) {
        // parse_error, and out_of_range for a number that overflows a double ("1e999", found
        // by session_fuzz).
        throw FileError(jsonPath.string(), std::string("not valid JSON: ") + e.what());
    }
}

// format, version and fps.
void readFormat(const JsonReader& r, const json& j, Session& s, SessionReadReport& report) {
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
}

// cameras[]: the first is the main camera, exactly one is.
void readCameras(const JsonReader& r, const json& j, Session& s) {
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
        if (c.video.empty()) r.fail(f + ".video", "is empty; name the camera's video or folder");
        checkContained(r, f + ".video", c.video);
        c.calibration = r.string(cj, "calibration", f + ".calibration", false);
        checkContained(r, f + ".calibration", c.calibration);
        c.role = r.string(cj, "role", f + ".role", false, i == 0 ? "main" : "environment");
        if (c.role != "main" && c.role != "environment")
            r.fail(f + ".role", "must be 'main' or 'environment', got '" + c.role + "'");
        if (cj.contains("shutter")) {
            const json& sh = cj["shutter"];
            if (!sh.is_number() || !std::isfinite(sh.get<double>()) || sh.get<double>() < 0 ||
                sh.get<double>() > 10)
                r.fail(f + ".shutter",
                       "expected the exposure time in seconds (0..10; 0 = no motion blur)");
            c.shutter = sh.get<double>();
        }
        if (i > 0 && c.role == "main")
            r.fail(f + ".role",
                   "is 'main', but cameras[0] is the main camera and a session has one; mark "
                   "this one 'environment' or list it first");
        s.cameras.push_back(c);
    }
    if (s.cameras[0].role != "main")
        r.fail("cameras[0].role", "the first camera must be the main camera");
}

// board, scene, frames, created.
void readNamedFiles(const JsonReader& r, const json& j, Session& s) {
    s.board = r.string(j, "board", "board", false);
    checkContained(r, "board", s.board);
    s.scene = r.string(j, "scene", "scene", false);
    s.framesFile = r.string(j, "frames", "frames", false, "frames.csv");
    if (s.framesFile.empty()) r.fail("frames", "is empty; name the frame list (frames.csv)");
    checkContained(r, "frames", s.framesFile);
    if (j.contains("created") && j["created"].is_object()) {
        s.createdBy = r.string(j["created"], "by", "created.by", false);
        s.createdAt = r.string(j["created"], "at", "created.at", false);
    }
}

// Files named by session.json: missing or bad ones are warnings, the footage may still be usable.
void checkNamedFiles(const Session& s, SessionReadReport& report) {
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
}

// What each camera's video actually holds.
std::vector<FrameInventory> inventoryCameras(const Session& s, SessionReadReport& report) {
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
    return inventories;
}

// frames.csv's rows; without a usable one, one row per frame of the main camera, times from
// the frame rate.
std::vector<FrameRecord> readFrameRows(const Session& s, const FrameInventory& main,
                                       SessionReadReport& report) {
    std::vector<std::string> names;
    for (const auto& c : s.cameras) names.push_back(c.name);
    const auto csvPath = s.path(s.framesFile);
    if (std::filesystem::is_regular_file(csvPath)) {
        try {
            return readFramesCsv(csvPath, s.fps, names, report.warnings);
        } catch (const FileError& e) {
            report.warnings.push_back(std::string(e.what()) +
                                      "; frames taken from the main video alone");
        }
    } else {
        report.warnings.push_back(s.framesFile +
                                  " is missing; frames taken from the main video alone");
    }
    std::vector<int> indices;
    if (main.isFolder)
        for (const auto& [i, p] : main.images) indices.push_back(i);
    else
        for (int i = 0; i < main.videoFrames; ++i) indices.push_back(i);
    std::vector<FrameRecord> rows;
    for (int i : indices) {
        FrameRecord fr;
        fr.index = i;
        fr.timestamps.assign(s.cameras.size(), i / s.fps);
        rows.push_back(fr);
    }
    return rows;
}

// Keeps the rows whose images every camera has (every camera but the environment cameras, when
// the reader can do without them); says which are dropped.
void keepReadableRows(Session& s, std::vector<FrameRecord> rows,
                      const std::vector<FrameInventory>& inventories,
                      const SessionReadOptions& options, SessionReadReport& report) {
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
    const json j = parseSessionJson(jsonPath);

    Session s;
    s.dir = dir;
    readFormat(r, j, s, report);
    readCameras(r, j, s);
    readNamedFiles(r, j, s);
    checkNamedFiles(s, report);
    const std::vector<FrameInventory> inventories = inventoryCameras(s, report);
    std::vector<FrameRecord> rows = readFrameRows(s, inventories[0], report);
    report.framesListed = int(rows.size());
    keepReadableRows(s, std::move(rows), inventories, options, report);
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
