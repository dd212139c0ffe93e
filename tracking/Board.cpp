#include "tracking/Board.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {
using nlohmann::json;

std::array<glm::dvec3, 4> BoardTag::cornersInTag(double s) {
    const double h = 0.5 * s;
    return {glm::dvec3(-h, h, 0), glm::dvec3(h, h, 0), glm::dvec3(h, -h, 0), glm::dvec3(-h, -h, 0)};
}

std::array<glm::dvec3, 4> BoardTag::cornersInWorld() const {
    auto c = cornersInTag(size);
    for (auto& p : c) p = T_world_tag * p;
    return c;
}

const BoardTag* Board::find(int id) const {
    for (const auto& t : tags)
        if (t.id == id) return &t;
    return nullptr;
}

bool Board::isPlanar() const {
    std::vector<glm::dvec3> pts;
    for (const auto& t : tags)
        for (const auto& p : t.cornersInWorld()) pts.push_back(p);
    if (pts.size() < 4) return true;
    // Plane through the first tag (its normal); every other corner must lie on it.
    const glm::dvec3 n = tags[0].T_world_tag.rotation * glm::dvec3(0, 0, 1);
    const glm::dvec3 o = tags[0].T_world_tag.translation;
    for (const auto& p : pts)
        if (std::abs(glm::dot(p - o, n)) > 1e-6) return false;
    return true;
}

namespace {

json poseToJson(const Pose& p) {
    return json{{"t", {p.translation.x, p.translation.y, p.translation.z}},
                {"q_wxyz", {p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z}}};
}

struct Ctx {
    std::string source;
    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw FileError(source, "field '" + field + "': " + what);
    }
    const json& get(const json& j, const char* key, const std::string& where) const {
        if (!j.is_object() || !j.contains(key)) fail(where + key, "missing");
        return j.at(key);
    }
    double number(const json& j, const std::string& field) const {
        if (!j.is_number()) fail(field, "must be a number");
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(field, "must be finite");
        return v;
    }
    Pose pose(const json& j, const std::string& field) const {
        const json& t = get(j, "t", field + ".");
        const json& q = get(j, "q_wxyz", field + ".");
        if (!t.is_array() || t.size() != 3) fail(field + ".t", "must be [x, y, z] in metres");
        if (!q.is_array() || q.size() != 4)
            fail(field + ".q_wxyz", "must be a unit quaternion [w, x, y, z]");
        Pose p;
        for (int i = 0; i < 3; ++i)
            p.translation[i] = number(t[i], field + ".t[" + std::to_string(i) + "]");
        glm::dquat r(number(q[0], field + ".q_wxyz[0]"), number(q[1], field + ".q_wxyz[1]"),
                     number(q[2], field + ".q_wxyz[2]"), number(q[3], field + ".q_wxyz[3]"));
        const double n = glm::length(r);
        if (std::abs(n - 1.0) > 1e-3)
            fail(field + ".q_wxyz", "is not a unit quaternion (norm " + std::to_string(n) + ")");
        p.rotation = r / n;
        return p;
    }
};

}  // namespace

Board Board::parse(const std::string& text, const std::string& source) {
    Ctx c{source};
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        throw FileError(source, std::string("not valid JSON: ") + e.what());
    }
    if (!j.is_object()) throw FileError(source, "a board file is a JSON object");
    if (j.contains("format") && j["format"] != "mirage-board")
        c.fail("format", "must be \"mirage-board\"");
    Board b;
    // Required: a board printed with another family than assumed finds no tags, or wrong ones.
    if (!j.contains("family"))
        c.fail("family",
               "missing: name the tag family the board was printed with, e.g. "
               "\"tag36h11\" (mirage board writes it)");
    if (!j["family"].is_string()) c.fail("family", "must be a string such as \"tag36h11\"");
    b.family = j["family"].get<std::string>();
    int codeCount = 0;
    try {
        codeCount = TagFamily(b.family).codeCount();
    } catch (const Error& e) {
        c.fail("family", e.what());
    }
    const json& tags = c.get(j, "tags", "");
    if (!tags.is_array() || tags.empty()) c.fail("tags", "must be a non-empty array of tags");
    std::set<int> ids;
    for (size_t i = 0; i < tags.size(); ++i) {
        const std::string f = "tags[" + std::to_string(i) + "].";
        BoardTag t;
        const json& id = c.get(tags[i], "id", f);
        if (!id.is_number_integer()) c.fail(f + "id", "must be an integer");
        t.id = id.get<int>();
        if (t.id < 0 || t.id >= codeCount)
            c.fail(f + "id", std::to_string(t.id) + " is outside family " + b.family + " (0.." +
                                 std::to_string(codeCount - 1) + ")");
        if (!ids.insert(t.id).second) c.fail(f + "id", "duplicate id " + std::to_string(t.id));
        t.size = c.number(c.get(tags[i], "size", f), f + "size");
        if (!(t.size > 0)) c.fail(f + "size", "must be > 0 (metres between detection corners)");
        t.T_world_tag = c.pose(c.get(tags[i], "T_world_tag", f), f + "T_world_tag");
        b.tags.push_back(t);
    }
    if (j.contains("sheet")) {
        const json& s = j["sheet"];
        BoardSheet sh;
        sh.width = c.number(c.get(s, "width", "sheet."), "sheet.width");
        sh.height = c.number(c.get(s, "height", "sheet."), "sheet.height");
        if (!(sh.width > 0 && sh.height > 0)) c.fail("sheet.width/height", "must be > 0 metres");
        sh.T_world_sheet = c.pose(c.get(s, "T_world_sheet", "sheet."), "sheet.T_world_sheet");
        if (s.contains("scale_bar")) {
            const json& sb = s["scale_bar"];
            const json& tl = c.get(sb, "top_left", "sheet.scale_bar.");
            if (!tl.is_array() || tl.size() != 2)
                c.fail("sheet.scale_bar.top_left", "must be [x, y] in page metres");
            sh.scaleBarTopLeft = {c.number(tl[0], "sheet.scale_bar.top_left[0]"),
                                  c.number(tl[1], "sheet.scale_bar.top_left[1]")};
            sh.scaleBarLength =
                c.number(c.get(sb, "length", "sheet.scale_bar."), "sheet.scale_bar.length");
            sh.scaleBarThickness =
                c.number(c.get(sb, "thickness", "sheet.scale_bar."), "sheet.scale_bar.thickness");
        }
        if (s.contains("caption") && s["caption"].is_string()) sh.caption = s["caption"];
        b.sheet = sh;
    }
    return b;
}

Board Board::load(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) throw FileError(path.string(), "cannot open board file (does it exist?)");
    std::stringstream ss;
    ss << in.rdbuf();
    return parse(ss.str(), path.string());
}

std::string Board::toJson() const {
    json j;
    j["format"] = "mirage-board";
    j["version"] = 1;
    j["family"] = family;
    j["units"] =
        "metres; T_world_tag maps tag frame (centre, +X right, +Y down, +Z into tag) "
        "to world (glTF, +Y up); q_wxyz = w,x,y,z";
    json arr = json::array();
    for (const auto& t : tags)
        arr.push_back({{"id", t.id}, {"size", t.size}, {"T_world_tag", poseToJson(t.T_world_tag)}});
    j["tags"] = arr;
    if (sheet) {
        json s{{"width", sheet->width},
               {"height", sheet->height},
               {"T_world_sheet", poseToJson(sheet->T_world_sheet)}};
        if (sheet->scaleBarLength > 0)
            s["scale_bar"] = {{"top_left", {sheet->scaleBarTopLeft.x, sheet->scaleBarTopLeft.y}},
                              {"length", sheet->scaleBarLength},
                              {"thickness", sheet->scaleBarThickness}};
        if (!sheet->caption.empty()) s["caption"] = sheet->caption;
        j["sheet"] = s;
    }
    return j.dump(2) + "\n";
}

void Board::save(const std::filesystem::path& path) const {
    const auto tmp = path.string() + ".tmp";
    {
        std::ofstream out(tmp);
        if (!out) throw FileError(path.string(), "cannot write board file");
        out << toJson();
        if (!out) throw FileError(path.string(), "write failed");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw FileError(path.string(), "cannot rename temporary file: " + ec.message());
}

}  // namespace mirage::tracking
