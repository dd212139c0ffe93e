#include "render/reconstruction/ProxyScene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"

namespace mirage::reconstruction {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Binary buffer of the new meshes with its views and accessors.
struct BufferBuilder {
    std::string bytes;
    int buffer = 0;
    json& gltf;
    explicit BufferBuilder(json& g) : gltf(g) {}

    int view(const void* data, size_t size, int target) {
        while (bytes.size() % 4) bytes.push_back('\0');
        json v = {{"buffer", buffer},
                  {"byteOffset", bytes.size()},
                  {"byteLength", size},
                  {"target", target}};
        bytes.append(static_cast<const char*>(data), size);
        gltf["bufferViews"].push_back(v);
        return int(gltf["bufferViews"].size()) - 1;
    }
    int vec3(const std::vector<glm::vec3>& v) {
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (const auto& p : v) lo = glm::min(lo, p), hi = glm::max(hi, p);
        gltf["accessors"].push_back({{"bufferView", view(v.data(), v.size() * 12, 34962)},
                                     {"componentType", 5126},
                                     {"count", v.size()},
                                     {"type", "VEC3"},
                                     {"min", {lo.x, lo.y, lo.z}},
                                     {"max", {hi.x, hi.y, hi.z}}});
        return int(gltf["accessors"].size()) - 1;
    }
    int vec2(const std::vector<glm::vec2>& v) {
        gltf["accessors"].push_back({{"bufferView", view(v.data(), v.size() * 8, 34962)},
                                     {"componentType", 5126},
                                     {"count", v.size()},
                                     {"type", "VEC2"}});
        return int(gltf["accessors"].size()) - 1;
    }
    int indices(const std::vector<uint32_t>& v) {
        gltf["accessors"].push_back({{"bufferView", view(v.data(), v.size() * 4, 34963)},
                                     {"componentType", 5125},
                                     {"count", v.size()},
                                     {"type", "SCALAR"}});
        return int(gltf["accessors"].size()) - 1;
    }
};

json array3(const glm::dvec3& v) {
    return {v.x, v.y, v.z};
}

json quaternion(const glm::dmat3& r) {
    const glm::dquat q = glm::normalize(glm::quat_cast(r));
    return {q.x, q.y, q.z, q.w};  // glTF order
}

int material(json& gltf, const std::string& name, const glm::dvec3& albedo, int texture) {
    json pbr = {{"baseColorFactor", {albedo.x, albedo.y, albedo.z, 1.0}},
                {"metallicFactor", 0.0},
                {"roughnessFactor", 0.8}};
    if (texture >= 0) {
        pbr["baseColorFactor"] = {1.0, 1.0, 1.0, 1.0};
        pbr["baseColorTexture"] = {{"index", texture}};
    }
    gltf["materials"].push_back({{"name", name}, {"pbrMetallicRoughness", pbr}});
    return int(gltf["materials"].size()) - 1;
}

void addRealNode(json& gltf, json node) {
    node["extras"] = {{"mirage", {{"real", true}}}};
    gltf["nodes"].push_back(node);
    gltf["scenes"][gltf.value("scene", 0)]["nodes"].push_back(gltf["nodes"].size() - 1);
}

// Real origin of every node, inherited from parents as docs/scene.md says.
std::vector<bool> realNodes(const json& gltf) {
    const json& nodes = gltf.value("nodes", json::array());
    std::vector<int> parent(nodes.size(), -1);
    for (size_t i = 0; i < nodes.size(); ++i)
        for (const auto& c : nodes[i].value("children", json::array()))
            if (c.is_number_integer() && c.get<int>() >= 0 && size_t(c.get<int>()) < nodes.size())
                parent[size_t(c.get<int>())] = int(i);
    std::vector<bool> real(nodes.size(), false);
    for (size_t i = 0; i < nodes.size(); ++i) {
        for (int n = int(i); n >= 0; n = parent[size_t(n)]) {
            const json& r = nodes[size_t(n)]
                                .value("extras", json::object())
                                .value("mirage", json::object())
                                .value("real", json());
            if (r.is_boolean()) {
                real[i] = r.get<bool>();
                break;
            }
        }
    }
    return real;
}

bool sameBytes(const fs::path& a, const fs::path& b) {
    std::error_code ec;
    if (fs::file_size(a, ec) != fs::file_size(b, ec) || ec) return false;
    std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
    return std::equal(std::istreambuf_iterator<char>(fa), std::istreambuf_iterator<char>(),
                      std::istreambuf_iterator<char>(fb));
}

// A URI of the given file, made relative to the new file's folder (data URIs stay). Scenes may
// only name files inside their own folder (docs/scene.md), so a file the new folder does not
// hold is copied into it, under its own name (or name_N when another file has that name); the
// copies are listed in `copied`.
std::string rebase(const std::string& uri, const fs::path& from, const fs::path& to,
                   std::vector<std::string>& copied) {
    if (uri.rfind("data:", 0) == 0 || fs::path(uri).is_absolute()) return uri;
    const fs::path source = fs::absolute(from / uri);
    const fs::path rel = fs::relative(source, fs::absolute(to));
    if (!rel.empty() && *rel.begin() != "..") return rel.generic_string();
    fs::path target = to / source.filename();
    for (int n = 1; fs::exists(target) && !sameBytes(source, target); ++n)
        target =
            to / (source.stem().string() + "_" + std::to_string(n) + source.extension().string());
    if (!fs::exists(target)) {
        std::error_code ec;
        fs::copy_file(source, target, ec);
        if (ec)
            throw FileError(target.string(),
                            "cannot copy " + source.string() +
                                " there (the scene refers to it): " + ec.message());
        copied.push_back(target.string());
    }
    return target.filename().generic_string();
}

void rebaseUris(json& gltf, const fs::path& from, const fs::path& to,
                std::vector<std::string>& copied) {
    for (const char* key : {"buffers", "images"})
        for (auto& item : gltf[key])
            if (item.contains("uri"))
                item["uri"] = rebase(item["uri"].get<std::string>(), from, to, copied);
    auto fixEnvironment = [&](json& holder) {
        if (!holder.contains("extras") || !holder["extras"].contains("mirage")) return;
        json& m = holder["extras"]["mirage"];
        if (!m.contains("environment")) return;
        for (const char* key : {"image", "calibration"})
            if (m["environment"].contains(key) && m["environment"][key].is_string())
                m["environment"][key] = rebase(m["environment"][key], from, to, copied);
    };
    for (auto& s : gltf["scenes"]) fixEnvironment(s);
    if (gltf.contains("asset")) fixEnvironment(gltf["asset"]);
}

json readJson(const fs::path& path) {
    if (path.extension() == ".glb")
        throw FileError(path.string(),
                        "is a binary glTF; mirage proxies needs the JSON form (.gltf): convert it "
                        "(e.g. gltf-transform copy IN.glb OUT.gltf)");
    std::ifstream in(path);
    if (!in) throw FileError(path.string(), "cannot be opened");
    try {
        return json::parse(in);
    } catch (const json::exception& e) {
        throw FileError(path.string(), std::string("is not valid glTF JSON: ") + e.what());
    }
}

void addTable(json& gltf, BufferBuilder& buf, const ProxySceneContent& c, int textureIndex) {
    const FusedGeometry& g = *c.geometry;
    const TableEstimate& t = g.table;
    const LightingEstimate& l = *c.lighting;
    auto at = [&](double u, double v, double h) { return glm::vec3(t.plane.toWorld({u, v, h})); };
    const double d = -c.tableThicknessM;
    // Top: textured quad, (u, v) = (uMin, vMin) at texture (0, 0).
    std::vector<glm::vec3> top{at(t.uMin, t.vMin, 0), at(t.uMax, t.vMin, 0), at(t.uMax, t.vMax, 0),
                               at(t.uMin, t.vMax, 0)};
    std::vector<glm::vec2> uv{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    std::vector<uint32_t> topIdx{0, 1, 2, 0, 2, 3};
    // Sides and bottom: the slab's other faces, the table's median albedo.
    std::vector<glm::vec3> slab;
    std::vector<uint32_t> slabIdx;
    const double us[2] = {t.uMin, t.uMax}, vs[2] = {t.vMin, t.vMax};
    auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 cc, glm::vec3 dd) {
        const auto base = uint32_t(slab.size());
        slab.insert(slab.end(), {a, b, cc, dd});
        slabIdx.insert(slabIdx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    };
    quad(at(us[0], vs[1], d), at(us[1], vs[1], d), at(us[1], vs[0], d), at(us[0], vs[0], d));
    quad(at(us[1], vs[0], d), at(us[1], vs[1], d), at(us[1], vs[1], 0), at(us[1], vs[0], 0));
    quad(at(us[0], vs[0], 0), at(us[0], vs[1], 0), at(us[0], vs[1], d), at(us[0], vs[0], d));
    quad(at(us[0], vs[1], d), at(us[0], vs[1], 0), at(us[1], vs[1], 0), at(us[1], vs[1], d));
    quad(at(us[1], vs[0], d), at(us[1], vs[0], 0), at(us[0], vs[0], 0), at(us[0], vs[0], d));
    const int topMat = material(gltf, "table (reconstructed albedo)", l.tableAlbedo, textureIndex);
    const int slabMat = material(gltf, "table sides (reconstructed)", l.tableAlbedo, -1);
    json mesh = {{"name", "real_table"},
                 {"primitives",
                  {{{"attributes", {{"POSITION", buf.vec3(top)}, {"TEXCOORD_0", buf.vec2(uv)}}},
                    {"indices", buf.indices(topIdx)},
                    {"material", topMat}},
                   {{"attributes", {{"POSITION", buf.vec3(slab)}}},
                    {"indices", buf.indices(slabIdx)},
                    {"material", slabMat}}}}};
    gltf["meshes"].push_back(mesh);
    addRealNode(gltf, {{"name", "real_table"}, {"mesh", gltf["meshes"].size() - 1}});
}

void addLightAndCamera(json& gltf, const ProxySceneContent& c) {
    if (c.lighting->spot) {
        const FittedSpotLight& s = *c.lighting->spot;
        const double I = std::max({s.intensity.x, s.intensity.y, s.intensity.z});
        const glm::dvec3 colour = I > 0 ? s.intensity / I : glm::dvec3(1.0);
        json& ext = gltf["extensions"]["KHR_lights_punctual"];
        if (!ext.contains("lights")) ext["lights"] = json::array();
        ext["lights"].push_back(
            {{"name", "real_spot"},
             {"type", "spot"},
             {"color", array3(colour)},
             {"intensity", I},
             {"spot", {{"innerConeAngle", s.innerConeRad}, {"outerConeAngle", s.outerConeRad}}}});
        // The node's -Z is the light's direction.
        const glm::dvec3 z = -s.direction;
        const glm::dvec3 helper = std::abs(z.y) < 0.99 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
        const glm::dvec3 x = glm::normalize(glm::cross(helper, z));
        const glm::dvec3 y = glm::cross(z, x);
        addRealNode(gltf, {{"name", "real_spot"},
                           {"translation", array3(s.position)},
                           {"rotation", quaternion(glm::dmat3(x, y, z))},
                           {"extensions",
                            {{"KHR_lights_punctual", {{"light", ext["lights"].size() - 1}}}}}});
        auto& used = gltf["extensionsUsed"];
        if (std::find(used.begin(), used.end(), "KHR_lights_punctual") == used.end())
            used.push_back("KHR_lights_punctual");
    }
    if (c.camera) {
        gltf["cameras"].push_back({{"name", "session_camera"},
                                   {"type", "perspective"},
                                   {"perspective",
                                    {{"yfov", c.yfov},
                                     {"aspectRatio", c.aspectRatio},
                                     {"znear", 0.01},
                                     {"zfar", 50.0}}}});
        const Pose gltfCam = *c.camera * kCvFromGltfCamera;
        const glm::dquat q = glm::normalize(gltfCam.rotation);
        addRealNode(gltf, {{"name", "session_camera"},
                           {"camera", gltf["cameras"].size() - 1},
                           {"translation", array3(gltfCam.translation)},
                           {"rotation", {q.x, q.y, q.z, q.w}}});
    }
}

void writeTexture(const cv::Mat& linearRgb, const fs::path& path) {
    cv::Mat bgr(linearRgb.size(), CV_8UC3);
    for (int y = 0; y < linearRgb.rows; ++y)
        for (int x = 0; x < linearRgb.cols; ++x) {
            const cv::Vec3f c = linearRgb.at<cv::Vec3f>(y, x);
            for (int k = 0; k < 3; ++k)
                bgr.at<cv::Vec3b>(y, x)[2 - k] =
                    uchar(std::lround(255.0f * linearToSrgb(std::clamp(c[k], 0.0f, 1.0f))));
        }
    if (!cv::imwrite(path.string(), bgr)) throw FileError(path.string(), "cannot be written");
}

}  // namespace

ProxySceneSummary writeProxyScene(const ProxySceneContent& c, const fs::path& virtualScene,
                                  const fs::path& out) {
    ProxySceneSummary summary;
    json gltf = readJson(virtualScene);
    const fs::path outDir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
    rebaseUris(gltf, virtualScene.parent_path(), outDir, summary.copiedFiles);
    for (const char* key : {"nodes", "meshes", "materials", "accessors", "bufferViews", "buffers",
                            "images", "textures", "samplers", "cameras", "extensionsUsed"})
        if (!gltf.contains(key)) gltf[key] = json::array();
    if (!gltf.contains("scenes") || gltf["scenes"].empty())
        gltf["scenes"] = {{{"nodes", json::array()}}};
    // Real nodes become empty placeholders (indices stay valid) and leave the scene.
    const std::vector<bool> real = realNodes(gltf);
    for (size_t i = 0; i < real.size(); ++i) {
        if (!real[i]) {
            ++summary.keptNodes;
            continue;
        }
        ++summary.droppedNodes;
        json& n = gltf["nodes"][i];
        n = {
            {"name", n.value("name", std::string("node")) + " (real, replaced by mirage proxies)"}};
    }
    auto unlink = [&](json& list) {
        json kept = json::array();
        for (const auto& idx : list)
            if (!idx.is_number_integer() || size_t(idx.get<int>()) >= real.size() ||
                !real[size_t(idx.get<int>())])
                kept.push_back(idx);
        list = kept;
    };
    for (auto& s : gltf["scenes"])
        if (s.contains("nodes")) unlink(s["nodes"]);
    for (auto& n : gltf["nodes"])
        if (n.contains("children")) unlink(n["children"]);

    BufferBuilder buf(gltf);
    buf.buffer = int(gltf["buffers"].size());
    const std::string stem = out.stem().string();
    const fs::path binPath = outDir / (stem + ".proxies.bin");
    const fs::path texPath = outDir / (stem + ".table.png");
    writeTexture(c.lighting->tableAlbedoTexture, texPath);
    gltf["images"].push_back({{"uri", texPath.filename().string()}});
    gltf["samplers"].push_back(
        {{"magFilter", 9729}, {"minFilter", 9729}, {"wrapS", 33071}, {"wrapT", 33071}});
    gltf["textures"].push_back(
        {{"source", gltf["images"].size() - 1}, {"sampler", gltf["samplers"].size() - 1}});
    addTable(gltf, buf, c, int(gltf["textures"].size()) - 1);
    const FusedGeometry& g = *c.geometry;
    for (size_t i = 0; i < g.objects.size(); ++i) {
        const ProxyObject& o = g.objects[i];
        const glm::dvec3 albedo =
            i < c.lighting->objectAlbedo.size() ? c.lighting->objectAlbedo[i] : glm::dvec3(0.5);
        const int mat = material(gltf, o.name + " (reconstructed albedo)", albedo, -1);
        gltf["meshes"].push_back({{"name", o.name},
                                  {"primitives",
                                   {{{"attributes", {{"POSITION", buf.vec3(o.positions)}}},
                                     {"indices", buf.indices(o.indices)},
                                     {"material", mat}}}}});
        addRealNode(gltf, {{"name", o.name}, {"mesh", gltf["meshes"].size() - 1}});
    }
    addLightAndCamera(gltf, c);
    gltf["buffers"].push_back(
        {{"uri", binPath.filename().string()}, {"byteLength", buf.bytes.size()}});
    gltf["asset"]["generator"] = "mirage proxies";
    {
        std::ofstream bin(binPath, std::ios::binary);
        bin.write(buf.bytes.data(), std::streamsize(buf.bytes.size()));
        if (!bin) throw FileError(binPath.string(), "cannot be written");
    }
    std::ofstream file(out);
    file << gltf.dump(1) << "\n";
    if (!file) throw FileError(out.string(), "cannot be written");
    return summary;
}

}  // namespace mirage::reconstruction
