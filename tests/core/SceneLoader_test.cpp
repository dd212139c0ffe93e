// glTF loading: the good scenes are checked value by value (they are written by
// tests/data/scenes/make_scenes.py, which documents each value); every bad file must end in a
// FileError that names the file and the problem.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>

#include <opencv2/imgcodecs.hpp>

#include "core/Error.h"
#include "core/scene/Scene.h"
#include "core/session/AtomicFile.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

fs::path scenesDir() {
    return test::testDataDir() / "scenes";
}
fs::path goodScene(const std::string& name) {
    return scenesDir() / "good" / name;
}

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void expectVec(const glm::vec2& a, const glm::vec2& b, float tol = 1e-6f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
}
void expectVec(const glm::vec3& a, const glm::vec3& b, float tol = 1e-6f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}
void expectVec(const glm::vec4& a, const glm::vec4& b, float tol = 1e-6f) {
    expectVec(glm::vec3(a), glm::vec3(b), tol);
    EXPECT_NEAR(a.w, b.w, tol);
}
void expectVec(const glm::dvec3& a, const glm::dvec3& b, double tol = 1e-9) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

bool hasWarning(const Scene& s, const std::string& part) {
    for (const std::string& w : s.warnings)
        if (w.find(part) != std::string::npos) return true;
    return false;
}

int nodeNamed(const Scene& s, const std::string& name) {
    for (size_t i = 0; i < s.nodes.size(); ++i)
        if (s.nodes[i].name == name) return static_cast<int>(i);
    ADD_FAILURE() << "no node " << name;
    return -1;
}

// Checks everything make_scenes.py put into showcase.gltf / showcase.glb.
void checkShowcase(const Scene& s) {
    ASSERT_EQ(s.textures.size(), 2u);
    ASSERT_EQ(s.materials.size(), 3u);
    ASSERT_EQ(s.meshes.size(), 3u);
    ASSERT_EQ(s.lights.size(), 3u);
    ASSERT_EQ(s.cameras.size(), 2u);
    ASSERT_EQ(s.nodes.size(), 10u);
    EXPECT_EQ(s.roots, (std::vector<int>{0, 4, 6, 7, 8}));

    // Textures: decoded to RGBA8, top row first; colour space from use.
    const Texture& checker = s.textures[0];
    EXPECT_EQ(checker.width, 2);
    EXPECT_EQ(checker.height, 2);
    EXPECT_EQ(checker.components, 4);
    EXPECT_EQ(checker.pixels, (std::vector<unsigned char>{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255,
                                                          255, 10, 20, 30, 40}));
    EXPECT_TRUE(checker.srgb);
    EXPECT_EQ(checker.wrapS, Texture::Wrap::Repeat);
    EXPECT_TRUE(checker.mipmaps);
    const Texture& mr = s.textures[1];
    EXPECT_EQ(mr.width, 2);
    EXPECT_EQ(mr.height, 1);
    EXPECT_EQ(mr.pixels, (std::vector<unsigned char>{0, 128, 255, 255, 0, 64, 32, 255}));
    EXPECT_FALSE(mr.srgb);
    EXPECT_EQ(mr.wrapS, Texture::Wrap::ClampToEdge);
    EXPECT_EQ(mr.wrapT, Texture::Wrap::MirroredRepeat);
    EXPECT_EQ(mr.magFilter, Texture::Filter::Nearest);
    EXPECT_EQ(mr.minFilter, Texture::Filter::Nearest);
    EXPECT_FALSE(mr.mipmaps);

    // Materials.
    const Material& floor = s.materials[0];
    EXPECT_EQ(floor.name, "FloorMat");
    expectVec(floor.baseColor, {0.8f, 0.7f, 0.6f, 1.0f});
    EXPECT_EQ(floor.baseColorTexture.texture, 0);
    EXPECT_EQ(floor.baseColorTexture.texCoord, 0);
    EXPECT_EQ(floor.metallicRoughnessTexture.texture, 1);
    EXPECT_FLOAT_EQ(floor.metallic, 0.0f);
    EXPECT_FLOAT_EQ(floor.roughness, 0.9f);
    expectVec(floor.emissive, {0.2f, 0.4f, 0.6f});  // emissiveFactor x emissiveStrength 2
    EXPECT_TRUE(floor.doubleSided);
    EXPECT_EQ(floor.alphaMode, Material::AlphaMode::Mask);
    EXPECT_FLOAT_EQ(floor.alphaCutoff, 0.25f);
    EXPECT_FALSE(floor.normalTexture.valid());
    EXPECT_FALSE(floor.isTransmissive());

    const Material& glass = s.materials[1];
    EXPECT_FLOAT_EQ(glass.transmission, 1.0f);
    EXPECT_FLOAT_EQ(glass.ior, 1.45f);
    EXPECT_FLOAT_EQ(glass.thickness, 0.05f);
    EXPECT_FLOAT_EQ(glass.attenuationDistance, 0.3f);
    expectVec(glass.attenuationColor, {0.9f, 0.8f, 0.7f});
    EXPECT_FLOAT_EQ(glass.roughness, 0.02f);
    // No retired extras: the showcase loads without that warning (RetiredRoughnessVariation).
    EXPECT_EQ(std::find_if(s.warnings.begin(), s.warnings.end(),
                           [](const std::string& w) {
                               return w.find("roughness_variation") != std::string::npos;
                           }),
              s.warnings.end());
    EXPECT_TRUE(glass.isTransmissive());
    EXPECT_FALSE(glass.isMirror());
    EXPECT_TRUE(s.materials[2].isMirror());
    EXPECT_FLOAT_EQ(s.materials[2].ior, 1.5f);  // KHR_materials_ior default
    EXPECT_TRUE(std::isinf(s.materials[2].attenuationDistance));

    // Mesh 0: indexed quad with every attribute.
    ASSERT_EQ(s.meshes[0].primitives.size(), 1u);
    const Primitive& quad = s.meshes[0].primitives[0];
    ASSERT_EQ(quad.positions.size(), 4u);
    expectVec(quad.positions[2], {1, 0, 1});
    EXPECT_EQ(quad.indices, (std::vector<uint32_t>{0, 2, 1, 0, 3, 2}));
    ASSERT_EQ(quad.normals.size(), 4u);
    expectVec(quad.normals[3], {0, 1, 0});
    ASSERT_EQ(quad.tangents.size(), 4u);
    expectVec(quad.tangents[0], {1, 0, 0, 1});
    ASSERT_EQ(quad.uv0.size(), 4u);
    expectVec(quad.uv0[2], {1, 1});
    EXPECT_TRUE(quad.uv1.empty());
    EXPECT_EQ(quad.material, 0);

    // Mesh 1: no normals, no indices, sparse override of vertex 2 -> flat normal (0, 0, 1).
    const Primitive& tri = s.meshes[1].primitives.at(0);
    ASSERT_EQ(tri.positions.size(), 3u);
    expectVec(tri.positions[0], {0, 0, 0});
    expectVec(tri.positions[1], {1, 0, 0});
    expectVec(tri.positions[2], {0, 1, 0});
    EXPECT_EQ(tri.indices, (std::vector<uint32_t>{0, 1, 2}));
    ASSERT_EQ(tri.normals.size(), 3u);
    for (const glm::vec3& n : tri.normals) expectVec(n, {0, 0, 1});

    // Mesh 2: triangle strip -> list with alternating winding; the LINES primitive is skipped.
    ASSERT_EQ(s.meshes[2].primitives.size(), 1u);
    const Primitive& strip = s.meshes[2].primitives[0];
    EXPECT_EQ(strip.indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3}));
    ASSERT_EQ(strip.uv1.size(), 4u);
    expectVec(strip.uv1[1], {0, 1});  // normalized UNSIGNED_BYTE 255 -> 1
    expectVec(strip.uv1[2], {1, 0});
    EXPECT_TRUE(hasWarning(s, "mesh 2 primitive 1 has mode 1"));

    // Lights.
    const Light& spot = s.lights[0];
    EXPECT_EQ(spot.type, Light::Type::Spot);
    EXPECT_EQ(spot.name, "KeySpot");
    expectVec(spot.color, {1.0f, 0.9f, 0.8f});
    EXPECT_FLOAT_EQ(spot.intensity, 50.0f);
    EXPECT_FLOAT_EQ(spot.range, 10.0f);
    EXPECT_FLOAT_EQ(spot.innerConeAngle, 0.2f);
    EXPECT_FLOAT_EQ(spot.outerConeAngle, 0.5f);
    EXPECT_EQ(s.lights[1].type, Light::Type::Point);
    EXPECT_FLOAT_EQ(s.lights[1].intensity, 5.0f);
    EXPECT_FLOAT_EQ(s.lights[1].range, 0.0f);  // infinite
    expectVec(s.lights[1].color, {1, 1, 1});
    EXPECT_EQ(s.lights[2].type, Light::Type::Directional);
    EXPECT_FLOAT_EQ(s.lights[2].intensity, 3.0f);

    // Cameras.
    EXPECT_EQ(s.cameras[0].name, "MainCam");
    EXPECT_FLOAT_EQ(s.cameras[0].yfov, 0.7f);
    EXPECT_FLOAT_EQ(s.cameras[0].aspectRatio, 1.5f);
    EXPECT_FLOAT_EQ(s.cameras[0].znear, 0.05f);
    EXPECT_FLOAT_EQ(s.cameras[0].zfar, 50.0f);
    EXPECT_FALSE(s.cameras[0].infiniteFar);
    EXPECT_FLOAT_EQ(s.cameras[1].aspectRatio, 0.0f);
    EXPECT_TRUE(s.cameras[1].infiniteFar);
    EXPECT_GT(s.cameras[1].zfar, s.cameras[1].znear);

    // Real/virtual: Room is real, its children inherit it unless they say otherwise.
    auto origin = [&](const char* name) {
        return s.nodes[static_cast<size_t>(nodeNamed(s, name))].origin;
    };
    EXPECT_EQ(origin("Room"), Origin::Real);
    EXPECT_EQ(origin("Floor"), Origin::Real);
    EXPECT_EQ(origin("Lamp"), Origin::Real);
    EXPECT_EQ(origin("VirtualMirror"), Origin::Virtual);
    EXPECT_EQ(origin("GlassObject"), Origin::Virtual);
    EXPECT_EQ(origin("GlassLight"), Origin::Virtual);
    EXPECT_EQ(origin("Sun"), Origin::Real);
    EXPECT_EQ(origin("NotInScene"), Origin::Virtual);

    // Hierarchy and world transforms.
    const Node& glassLight = s.nodes[5];
    EXPECT_EQ(glassLight.parent, 4);
    EXPECT_EQ(s.nodes[4].children, (std::vector<int>{5}));
    expectVec(glm::dvec3(glassLight.world[3]), {0.5, 1.5, 0.25});  // parent scale 0.5
    expectVec(glm::dvec3(s.nodes[1].world[0]), {2, 0, 0});         // Floor scale (2, 1, 2)

    // Instances: only nodes reachable from the scene's roots (NotInScene is not).
    std::vector<MeshInstance> meshes = s.meshInstances();
    ASSERT_EQ(meshes.size(), 3u);
    EXPECT_EQ(meshes[0].node, 1);
    EXPECT_EQ(meshes[0].origin, Origin::Real);
    EXPECT_EQ(meshes[1].node, 3);
    EXPECT_EQ(meshes[1].mesh, 2);
    EXPECT_EQ(meshes[1].origin, Origin::Virtual);
    EXPECT_EQ(meshes[2].node, 4);
    expectVec(glm::dvec3(meshes[2].world[3]), {0.5, 1.0, 0.25});

    std::vector<LightInstance> lights = s.lightInstances();
    ASSERT_EQ(lights.size(), 3u);
    EXPECT_EQ(lights[0].light, 0);  // Lamp: at (0, 2, 0), rotated to shine down
    expectVec(lights[0].position, {0, 2, 0});
    expectVec(lights[0].direction, {0, -1, 0}, 1e-7);
    EXPECT_EQ(lights[0].origin, Origin::Real);
    EXPECT_EQ(lights[1].light, 1);  // GlassLight: default direction -Z, under a scaled parent
    expectVec(lights[1].position, {0.5, 1.5, 0.25});
    expectVec(lights[1].direction, {0, 0, -1});
    EXPECT_EQ(lights[1].origin, Origin::Virtual);
    EXPECT_EQ(lights[2].light, 2);  // Sun: +90 degrees about Y -> shines along -X
    expectVec(lights[2].direction, {-1, 0, 0}, 1e-7);
    EXPECT_EQ(lights[2].origin, Origin::Real);

    EXPECT_EQ(s.findCameraNode("MainCamera"), 6);
    EXPECT_EQ(s.findCameraNode("TopCamera"), 8);
    EXPECT_EQ(s.findCameraNode(""), 6);
    try {
        s.findCameraNode("Nope");
        ADD_FAILURE() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'MainCamera', 'TopCamera'"), std::string::npos)
            << e.what();
    }
    EXPECT_TRUE(s.hasVirtual());
    EXPECT_FLOAT_EQ(s.material(-1).metallic, 1.0f);
    EXPECT_FLOAT_EQ(s.material(-1).roughness, 1.0f);
    expectVec(s.material(-1).baseColor, glm::vec4(1.0f));
    EXPECT_EQ(&s.material(1), &s.materials[1]);

    // Environment from scenes[0].extras, path resolved next to the glTF file.
    EXPECT_EQ(s.environment.kind, Environment::Kind::Equirectangular);
    EXPECT_EQ(s.environment.image, fs::absolute(goodScene("env.hdr")).lexically_normal());
    EXPECT_FLOAT_EQ(s.environment.intensity, 2.0f);
    EXPECT_DOUBLE_EQ(s.environment.rotationYDeg, 90.0);
    EXPECT_EQ(s.environment.origin, Origin::Real);
}

TEST(SceneLoader, ShowcaseGltf) {
    Scene s = loadScene(goodScene("showcase.gltf"));
    EXPECT_EQ(s.source, fs::absolute(goodScene("showcase.gltf")));
    checkShowcase(s);
}

TEST(SceneLoader, ShowcaseGlbHasTheSameContent) {
    Scene s = loadScene(goodScene("showcase.glb"));
    checkShowcase(s);
}

TEST(SceneLoader, GltfAndGlbGiveIdenticalGeometryAndTextures) {
    Scene a = loadScene(goodScene("showcase.gltf")), b = loadScene(goodScene("showcase.glb"));
    ASSERT_EQ(a.meshes.size(), b.meshes.size());
    for (size_t m = 0; m < a.meshes.size(); ++m) {
        ASSERT_EQ(a.meshes[m].primitives.size(), b.meshes[m].primitives.size());
        for (size_t p = 0; p < a.meshes[m].primitives.size(); ++p) {
            const Primitive &x = a.meshes[m].primitives[p], &y = b.meshes[m].primitives[p];
            EXPECT_EQ(x.positions, y.positions);
            EXPECT_EQ(x.normals, y.normals);
            EXPECT_EQ(x.tangents, y.tangents);
            EXPECT_EQ(x.uv0, y.uv0);
            EXPECT_EQ(x.uv1, y.uv1);
            EXPECT_EQ(x.indices, y.indices);
            EXPECT_EQ(x.material, y.material);
        }
    }
    ASSERT_EQ(a.textures.size(), b.textures.size());
    for (size_t t = 0; t < a.textures.size(); ++t)
        EXPECT_EQ(a.textures[t].pixels, b.textures[t].pixels);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (size_t n = 0; n < a.nodes.size(); ++n) {
        EXPECT_EQ(a.nodes[n].world, b.nodes[n].world);
        EXPECT_EQ(a.nodes[n].origin, b.nodes[n].origin);
    }
}

TEST(SceneLoader, LoadFromMemoryMatchesLoadFromFile) {
    Scene s =
        loadSceneFromMemory(readFile(goodScene("showcase.glb")), "in-memory.glb", goodScene(""));
    EXPECT_EQ(s.source, "in-memory.glb");
    checkShowcase(s);
}

// The retired extras.mirage.roughness_variation (roughness now varies through the
// metallicRoughnessTexture) is warned about, naming the material, and not read.
TEST(SceneLoader, RetiredRoughnessVariationIsWarnedAboutNotRead) {
    std::string json = readFile(goodScene("showcase.gltf"));
    const std::string glass = "\"name\": \"Glass\"";
    ASSERT_NE(json.find(glass), std::string::npos);
    json.replace(json.find(glass), glass.size(),
                 glass + ", \"extras\": {\"mirage\": {\"roughness_variation\": 0.1}}");
    const Scene s = loadSceneFromMemory(json, "retired.gltf", goodScene(""));
    const auto w = std::find_if(s.warnings.begin(), s.warnings.end(), [](const std::string& w) {
        return w.find("roughness_variation") != std::string::npos;
    });
    ASSERT_NE(w, s.warnings.end());
    EXPECT_NE(w->find("material 1"), std::string::npos) << *w;
    EXPECT_NE(w->find("metallicRoughnessTexture"), std::string::npos) << *w;
    EXPECT_FLOAT_EQ(s.materials[1].roughness, 0.02f);
}

TEST(SceneLoader, FisheyeEnvironmentFromAssetExtras) {
    Scene s = loadScene(goodScene("fisheye.gltf"));
    const Environment& e = s.environment;
    EXPECT_EQ(e.kind, Environment::Kind::Fisheye);
    EXPECT_EQ(e.calibration, fs::absolute(goodScene("fisheye.yaml")).lexically_normal());
    EXPECT_FLOAT_EQ(e.intensity, 0.5f);
    expectVec(e.T_world_camera.translation, {0.1, 2.0, -0.3});
    // q = (w 0, x 1, y 0, z 0): 180 degrees about X, camera looks along world -Z, +Y down -> up.
    expectVec(e.T_world_camera * glm::dvec3(0, 0, 1), glm::dvec3(0.1, 2.0, -1.3));
    // A single virtual triangle, default virtual.
    EXPECT_TRUE(s.hasVirtual());
    EXPECT_THROW(s.findCameraNode(""), Error);
}

// Builds a glTF around a base64 buffer in the test itself, for cases the data files do not cover.
std::string base64(const std::vector<unsigned char>& data) {
    static const char* kAlphabet =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
        uint32_t v = static_cast<uint32_t>(data[i]) << 16;
        if (i + 1 < data.size()) v |= static_cast<uint32_t>(data[i + 1]) << 8;
        if (i + 2 < data.size()) v |= data[i + 2];
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += i + 1 < data.size() ? kAlphabet[(v >> 6) & 63] : '=';
        out += i + 2 < data.size() ? kAlphabet[v & 63] : '=';
    }
    return out;
}

template <class T>
void append(std::vector<unsigned char>& out, const std::vector<T>& values) {
    const auto* p = reinterpret_cast<const unsigned char*>(values.data());
    out.insert(out.end(), p, p + values.size() * sizeof(T));
}

TEST(SceneLoader, TriangleFanWithUnsignedIntIndicesAllReal) {
    std::vector<unsigned char> buf;
    append(buf, std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});  // 48 bytes
    append(buf, std::vector<uint32_t>{0, 1, 2, 3});                       // 16 bytes
    std::string json = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
      "nodes":[{"mesh":0,"extras":{"mirage":{"real":true}}}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":6}]}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},
                   {"bufferView":1,"componentType":5125,"count":4,"type":"SCALAR"}],
      "bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":16}],
      "buffers":[{"byteLength":64,"uri":"data:application/octet-stream;base64,)" +
                       base64(buf) + R"("}]})";
    Scene s = loadSceneFromMemory(json, "fan.gltf", ".");
    ASSERT_EQ(s.meshes.size(), 1u);
    // Fan (0,1,2,3) -> (0,1,2), (0,2,3); no normals -> flat, un-indexed: 6 corners.
    const Primitive& p = s.meshes[0].primitives.at(0);
    ASSERT_EQ(p.positions.size(), 6u);
    expectVec(p.positions[4], {1, 1, 0});
    expectVec(p.positions[5], {0, 1, 0});
    expectVec(p.normals[5], {0, 0, 1});
    EXPECT_FALSE(s.hasVirtual());  // everything real: nothing to composite
    EXPECT_EQ(s.meshInstances().at(0).origin, Origin::Real);
}

// Textures in the formats glTF allows, encoded here by OpenCV and embedded as data URIs: JPEG
// (lossy: compared with a tolerance), 16-bit grey PNG (reduced to 8 bits), grey+alpha PNG.
std::string texturedTriangle(
    const std::vector<std::pair<std::string, std::vector<unsigned char>>>& images) {
    std::vector<unsigned char> buf;
    append(buf, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1});  // pos + uv
    std::string imageList, textureList;
    for (size_t i = 0; i < images.size(); ++i) {
        imageList += (i ? "," : "") + std::string(R"({"uri":"data:)") + images[i].first +
                     ";base64," + base64(images[i].second) + "\"}";
        textureList += (i ? "," : "") + std::string(R"({"source":)") + std::to_string(i) + "}";
    }
    return R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"material":0}]}],
      "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},
                   {"bufferView":0,"byteOffset":36,"componentType":5126,"count":3,"type":"VEC2"}],
      "bufferViews":[{"buffer":0,"byteLength":60}],
      "buffers":[{"byteLength":60,"uri":"data:application/octet-stream;base64,)" +
           base64(buf) + R"("}],"images":[)" + imageList + "],\"textures\":[" + textureList + "]}";
}

std::vector<unsigned char> encode(const std::string& ext, const cv::Mat& image) {
    std::vector<unsigned char> bytes;
    EXPECT_TRUE(cv::imencode(ext, image, bytes));
    return bytes;
}

TEST(SceneLoader, TextureFormatsDecodeToRgba8) {
    cv::Mat bgr(8, 8, CV_8UC3, cv::Scalar(40, 120, 200));  // B, G, R
    cv::Mat grey16(2, 3, CV_16UC1, cv::Scalar(65535));
    grey16.at<uint16_t>(1, 2) = 257 * 100;
    cv::Mat greyAlpha(1, 2, CV_8UC4, cv::Scalar(77, 77, 77, 128));  // written by OpenCV as RGBA
    Scene s = loadSceneFromMemory(texturedTriangle({{"image/jpeg", encode(".jpg", bgr)},
                                                    {"image/png", encode(".png", grey16)},
                                                    {"image/png", encode(".png", greyAlpha)}}),
                                  "formats.gltf", ".");
    ASSERT_EQ(s.textures.size(), 3u);
    const Texture& jpeg = s.textures[0];
    ASSERT_EQ(jpeg.width, 8);
    ASSERT_EQ(jpeg.height, 8);
    EXPECT_TRUE(jpeg.srgb);
    for (size_t p = 0; p < 64; ++p) {  // RGBA order after loading; JPEG is lossy
        EXPECT_NEAR(jpeg.pixels[p * 4 + 0], 200, 3);
        EXPECT_NEAR(jpeg.pixels[p * 4 + 1], 120, 3);
        EXPECT_NEAR(jpeg.pixels[p * 4 + 2], 40, 3);
        EXPECT_EQ(jpeg.pixels[p * 4 + 3], 255);
    }
    const Texture& g16 = s.textures[1];
    ASSERT_EQ(g16.width, 3);
    ASSERT_EQ(g16.height, 2);
    EXPECT_EQ(g16.pixels[0], 255);
    EXPECT_EQ(g16.pixels[(1 * 3 + 2) * 4 + 0], 100);  // row 1, column 2: top row first
    EXPECT_EQ(g16.pixels[(1 * 3 + 2) * 4 + 1], 100);
    EXPECT_EQ(g16.pixels[(1 * 3 + 2) * 4 + 3], 255);
    const Texture& ga = s.textures[2];
    ASSERT_EQ(ga.pixels.size(), 8u);
    EXPECT_EQ(ga.pixels[0], 77);
    EXPECT_EQ(ga.pixels[3], 128);
    EXPECT_FALSE(ga.srgb);  // unused by any material: data by default
}

// ---- bad files ---------------------------------------------------------------------------------

struct BadCase {
    const char* file;
    std::vector<std::string> mustMention;  // substrings of the error message
};

const std::vector<BadCase>& badCases() {
    static const std::vector<BadCase> cases = {
        {"missing_buffer.gltf", {"missing.bin"}},
        {"buffer_length_mismatch.gltf", {"Buffer"}},
        {"accessor_index_out_of_range.gltf",
         {"POSITION", "accessor 7", "2 accessors", "valid: 0..1"}},
        {"indices_accessor_out_of_range.gltf", {"indices", "out of bounds"}},
        {"bufferview_index_out_of_range.gltf", {"accessor 0", "bufferView 5"}},
        {"buffer_index_out_of_range.gltf", {"bufferView 0", "buffer 3"}},
        {"scene_node_out_of_range.gltf", {"scene 0", "node 4"}},
        {"child_node_out_of_range.gltf", {"node 0", "children", "node -2"}},
        {"mesh_index_out_of_range.gltf", {"node 0", "'mesh'", "mesh 4"}},
        {"material_index_out_of_range.gltf", {"mesh 0 primitive 0", "material 3"}},
        {"texture_index_out_of_range.gltf", {"material 0 baseColorTexture", "texture 2"}},
        {"accessor_exceeds_bufferview.gltf", {"accessor 0", "reads 4 elements", "36 bytes"}},
        {"accessor_offset_exceeds_bufferview.gltf", {"accessor 0", "byteOffset 8"}},
        {"bufferview_exceeds_buffer.gltf", {"bufferView 1", "only 42 bytes"}},
        {"wrong_accessor_type.gltf", {"accessor 0", "type VEC2, expected VEC3"}},
        {"wrong_component_type.gltf", {"accessor 0", "UNSIGNED_SHORT", "FLOAT"}},
        {"float_indices.gltf", {"accessor 1", "indices", "FLOAT"}},
        {"index_beyond_vertices.gltf", {"index 2 is 5", "3 vertices"}},
        {"nan_in_positions.gltf", {"accessor 0", "element 1 component 0 is NaN"}},
        {"translation_number_overflow.gltf", {"number overflow", "1e999"}},
        {"matrix_world_overflow.gltf", {"node 1", "world transform", "non-finite"}},
        {"world_transform_overflow.gltf", {"node 1", "world transform"}},
        {"zero_quaternion.gltf", {"node 0", "quaternion"}},
        {"node_cycle.gltf", {"cycle"}},
        {"node_self_child.gltf", {"node 0", "itself"}},
        {"node_two_parents.gltf", {"node 2", "both node 0", "node 1"}},
        {"unknown_required_extension.gltf", {"extensionsRequired", "KHR_draco_mesh_compression"}},
        {"missing_image.gltf", {"image 0", "no_such_image.png"}},
        {"image_not_png.gltf", {"image 0", "neither PNG nor JPEG"}},
        {"image_too_large.gltf", {"image 0", "100000x100000", "8192x8192"}},
        {"duplicate_child.gltf", {"node 0", "node 1 twice"}},
        {"light_index_out_of_range.gltf", {"node 0", "light 2"}},
        {"camera_index_out_of_range.gltf", {"node 0", "camera 1"}},
        {"spot_cone_inverted.gltf", {"light 0", "innerConeAngle < outerConeAngle"}},
        {"light_intensity_beyond_float.gltf",
         {"light 0 intensity", "outside the range of a float"}},
        {"real_not_bool.gltf", {"node 0", "extras.mirage.real"}},
        {"environment_image_missing.gltf", {"environment", "nowhere.hdr"}},
        {"attribute_count_mismatch.gltf", {"NORMAL", "2 elements", "POSITION has 3"}},
        {"invalid_mode.gltf", {"mesh 0 primitive 0", "mode 9"}},
        {"no_position.gltf", {"mesh 0 primitive 0", "POSITION"}},
        {"sparse_index_out_of_range.gltf", {"accessor 0", "sparse index 0 is 7"}},
        {"scattering_no_extinction.gltf",
         {"material 0 MIRAGE_materials_scattering", "no extinction", "attenuationDistance"}},
        {"scattering_albedo_out_of_range.gltf", {"material 0", "albedo[1]"}},
        {"scattering_density_missing.gltf", {"density", "nowhere.nrrd", "not found"}},
        {"scattering_bounds_inverted.gltf", {"boundsMax[1]", "boundsMin[1]"}},
        {"scattering_nrrd_short.gltf", {"grid_short.nrrd", "28 bytes", "need 32"}},
        {"scattering_nrrd_compressed.gltf", {"grid_gzip.nrrd", "encoding 'gzip'", "raw"}},
        {"scattering_negative_density.gltf", {"grid_negative.nrrd", "sample 5", ">= 0"}},
        {"scattering_raw_no_dimensions.gltf", {"grid.raw", "dimensions"}},
        {"scattering_thin_walled.gltf", {"material 0", "thicknessFactor", "thin-walled"}},
        {"deep_nesting.gltf", {"nesting"}},
        {"not_json.gltf", {"not a valid glTF file"}},
        {"empty.gltf", {"empty"}},
        {"truncated_glb.glb", {"binary"}},
    };
    return cases;
}

// Translucent materials: the mirage extension with NRRD and raw grids, and the standard
// diffuse-transmission + volume pair (values from make_scenes.py).
TEST(SceneLoader, TranslucentMaterialsAndDensityGrids) {
    const Scene s = loadScene(goodScene("translucent.gltf"));
    ASSERT_EQ(s.materials.size(), 3u);
    const Material& jade = s.materials[0];
    ASSERT_TRUE(jade.isTranslucent());
    EXPECT_FALSE(jade.isTransmissive());
    EXPECT_FALSE(jade.isMirror());
    EXPECT_FLOAT_EQ(jade.scattering.extinction, 40.0f);
    expectVec(jade.scattering.albedo, {0.6f, 0.9f, 0.7f});
    EXPECT_FLOAT_EQ(jade.ior, 1.6f);
    ASSERT_TRUE(jade.scattering.density);
    const DensityGrid& g = *jade.scattering.density;
    EXPECT_EQ(g.nx, 4);
    EXPECT_EQ(g.ny, 3);
    EXPECT_EQ(g.nz, 2);
    EXPECT_NEAR(g.at(3, 2, 1), 2.3f, 1e-6f);
    EXPECT_NEAR(g.maxValue, 2.3f, 1e-6f);
    expectVec(g.boundsMin, {-0.5f, -0.25f, 0.0f});
    // Cell centres: x at -0.375 + 0.25 i, y at -0.125 + 0.25 j, z at 0.05 + 0.1 k.
    EXPECT_NEAR(g.density({-0.375f, -0.125f, 0.05f}), 0.0f, 1e-6f);
    EXPECT_NEAR(g.density({0.375f, 0.375f, 0.15f}), 2.3f, 1e-5f);
    // Half way between x = 0 and x = 1 (density 0 and 0.1), and between z planes (+1.2).
    EXPECT_NEAR(g.density({-0.25f, -0.125f, 0.1f}), 0.05f + 0.6f, 1e-5f);
    // Clamped to the outermost centres inside the box, zero outside.
    EXPECT_NEAR(g.density({-0.49f, -0.24f, 0.01f}), 0.0f, 1e-6f);
    EXPECT_NEAR(g.density({0.49f, 0.49f, 0.19f}), 2.3f, 1e-5f);
    EXPECT_EQ(g.density({0.6f, 0.0f, 0.1f}), 0.0f);

    const Material& milk = s.materials[1];
    ASSERT_TRUE(milk.isTranslucent());
    expectVec(milk.scattering.albedo, {1, 1, 1});
    ASSERT_TRUE(milk.scattering.density);
    EXPECT_NEAR(milk.scattering.density->at(1, 0, 1), 1.0f, 1e-6f);
    EXPECT_NEAR(milk.scattering.density->at(1, 0, 0), 0.2f, 1e-6f);

    const Material& wax = s.materials[2];
    ASSERT_TRUE(wax.isTranslucent());
    EXPECT_FLOAT_EQ(wax.scattering.extinction, 4.0f);  // 1 / attenuationDistance
    expectVec(wax.scattering.albedo, {0.9f, 0.8f, 0.5f});
    EXPECT_FALSE(wax.scattering.density);
    // The loader warns about nothing here: every extension used is supported.
    EXPECT_TRUE(s.warnings.empty());
}

TEST(SceneLoader, NrrdHeaderVariants) {
    auto floats = [](std::vector<float> v) {
        return std::string(reinterpret_cast<const char*>(v.data()), v.size() * 4);
    };
    // CRLF header, big-endian ushort, comments and key/value pairs.
    std::string big =
        "NRRD0005\r\n# c\r\ntype: ushort\r\ndimension: 3\r\nsizes: 1 1 2\r\n"
        "encoding: raw\r\nendian: big\r\nunits:=mm\r\n\r\n";
    big += std::string("\xff\xff\x00\x00", 4);
    DensityGrid g = parseNrrdDensity(big);
    EXPECT_FLOAT_EQ(g.at(0, 0, 0), 1.0f);
    EXPECT_FLOAT_EQ(g.at(0, 0, 1), 0.0f);
    const std::string head =
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 1 1\n"
        "encoding: raw\nendian: little\n\n";
    EXPECT_FLOAT_EQ(parseNrrdDensity(head + floats({0.5f, 2.0f})).maxValue, 2.0f);
    auto rejects = [](const std::string& bytes, const std::string& part) {
        try {
            parseNrrdDensity(bytes);
            ADD_FAILURE() << "accepted: " << part;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
    };
    rejects(head + floats({0.5f, NAN}), "finite");
    rejects(
        "NRRD0004\ntype: float\ndimension: 2\nsizes: 2 1\nencoding: raw\nendian: "
        "little\n\n" +
            floats({1, 1}),
        "dimension");
    rejects(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 2000 1 1\nencoding: raw\nendian: "
        "little\n\n",
        "outside 1..1024");
    rejects("NRRD0004\ntype: int\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n", "type 'int'");
    rejects("NRRD0004\ntype: float\ndimension: 3\n", "no end");
    rejects("P6\n", "not an NRRD");
    rejects(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 1 1 1\nencoding: raw\nendian: "
        "little\ndata file: x.raw\n\n",
        "detached");
}

TEST(SceneLoader, BadFilesGiveFileErrorsNamingFileAndProblem) {
    for (const BadCase& c : badCases()) {
        SCOPED_TRACE(c.file);
        const fs::path path = scenesDir() / "bad" / c.file;
        ASSERT_TRUE(fs::exists(path));
        try {
            loadScene(path);
            ADD_FAILURE() << "loaded without error";
        } catch (const FileError& e) {
            EXPECT_EQ(e.file(), path.string());
            const std::string message = e.what();
            for (const std::string& part : c.mustMention)
                EXPECT_NE(message.find(part), std::string::npos)
                    << "missing '" << part << "' in: " << message;
        }
    }
}

TEST(SceneLoader, EveryBadFileHasAnExpectation) {
    std::set<std::string> listed;
    for (const BadCase& c : badCases()) listed.insert(c.file);
    for (const auto& entry : fs::directory_iterator(scenesDir() / "bad")) {
        const std::string name = entry.path().filename().string();
        if (entry.path().extension() == ".gltf" || entry.path().extension() == ".glb") {
            EXPECT_TRUE(listed.count(name))
                << name << " has no expected error in SceneLoader_test.cpp";
        }
    }
}

// A relative image URI is resolved against the glTF file's folder only. tinygltf also looks in the
// current directory, so a texture missing beside the glTF was silently taken from wherever mirage
// ran. Here the only tex.png lies in the current directory: the load must fail and say where it
// looked; beside the glTF (or reached from there by "../") the same file loads.
TEST(SceneLoader, TextureUriResolvesAgainstTheGltfFolderOnly) {
    const fs::path root = test::outputDir("scene_texture_uri");
    const fs::path gltfDir = root / "scene", elsewhere = root / "elsewhere";
    fs::create_directories(gltfDir);
    fs::create_directories(elsewhere);
    fs::remove(gltfDir / "tex.png");
    const cv::Mat red(4, 4, CV_8UC3, cv::Scalar(0, 0, 255));
    ASSERT_TRUE(cv::imwrite((elsewhere / "tex.png").string(), red));
    auto writeScene = [&](const std::string& uri) {
        std::string json = texturedTriangle({{"MARK", {}}});
        const std::string mark = "data:MARK;base64,";
        json.replace(json.find(mark), mark.size(), uri);
        std::ofstream(gltfDir / "tri.gltf") << json;
    };
    writeScene("tex.png");
    const fs::path previous = fs::current_path();
    fs::current_path(elsewhere);
    std::string message;
    try {
        loadScene(gltfDir / "tri.gltf");
    } catch (const FileError& e) {
        message = e.what();
    }
    fs::current_path(previous);
    EXPECT_NE(message.find("'tex.png'"), std::string::npos) << message;
    EXPECT_NE(message.find(fs::absolute(gltfDir).lexically_normal().string()), std::string::npos)
        << message;

    // A URI that leaves the glTF's folder is refused, even when the file exists.
    writeScene("../elsewhere/tex.png");
    message.clear();
    try {
        loadScene(gltfDir / "tri.gltf");
    } catch (const FileError& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("images[0].uri: the URI '../elsewhere/tex.png' leaves the folder"),
              std::string::npos)
        << message;

    fs::copy_file(elsewhere / "tex.png", gltfDir / "tex.png", fs::copy_options::overwrite_existing);
    writeScene("tex.png");
    const Scene beside = loadScene(gltfDir / "tri.gltf");
    ASSERT_EQ(beside.textures.size(), 1u);
    EXPECT_EQ(beside.textures[0].pixels[0], 255);  // red, RGBA
}

// Every loader resolves the files a scene names inside the scene's folder: a buffer or image URI
// that climbs out ("../../../etc/passwd"), is absolute or has a scheme is an error naming it,
// before any of it is read. Before, "../../../secret.bin" was read as the mesh's buffer.
TEST(SceneLoader, UrisOutsideTheSceneFolderAreRefused) {
    const fs::path root = test::outputDir("scene_uri_escape");
    const fs::path sceneDir = root / "a" / "b" / "c";
    fs::create_directories(sceneDir);
    std::ofstream(root / "secret.bin", std::ios::binary) << std::string(42, '\0');
    const std::string text = readFileBytes(scenesDir() / "bad" / "missing_buffer.gltf");
    const std::string absolute = fs::absolute(root / "secret.bin").string();
    for (const std::string& uri :
         {std::string("../../../secret.bin"), std::string("../../../etc/passwd"), absolute,
          std::string("sub/../../../../secret.bin"), std::string("%2e%2e/%2e%2e/%2e%2e/secret.bin"),
          std::string("file:///etc/passwd")}) {
        SCOPED_TRACE(uri);
        std::string json = text;
        json.replace(json.find("missing.bin"), 11, uri);
        std::ofstream(sceneDir / "scene.gltf", std::ios::trunc) << json;
        try {
            loadScene(sceneDir / "scene.gltf");
            ADD_FAILURE() << "loaded a buffer from outside the scene folder";
        } catch (const FileError& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("buffers[0].uri"), std::string::npos) << m;
            EXPECT_NE(m.find("'" + uri + "'"), std::string::npos) << m;
        }
    }
    // Inside the folder, also through a normalised path, the same bytes load.
    fs::create_directories(sceneDir / "sub");
    fs::copy_file(root / "secret.bin", sceneDir / "mesh.bin", fs::copy_options::overwrite_existing);
    std::string json = text;
    json.replace(json.find("missing.bin"), 11, "sub/../mesh.bin");
    std::ofstream(sceneDir / "scene.gltf", std::ios::trunc) << json;
    try {
        loadScene(sceneDir / "scene.gltf");
    } catch (const FileError& e) {
        // The buffer was found; the all-zero triangle may still be refused for what it holds.
        EXPECT_EQ(std::string(e.what()).find("uri"), std::string::npos) << e.what();
    }
}

// tinygltf skips a property of the wrong type without a word; every such field is an error
// naming its JSON path.
TEST(SceneLoader, FieldsOfTheWrongTypeAreErrorsWithTheirPath) {
    const fs::path dir = test::outputDir("scene_wrong_types");
    const std::string good = readFileBytes(scenesDir() / "bad" / "missing_buffer.gltf");
    struct Case {
        std::string from, to, path;
    };
    const std::vector<Case> cases = {
        {"\"mesh\": 0", "\"mesh\": 0, \"translation\": [\"a\", 0, 0]", "nodes[0].translation[0]"},
        {"\"mesh\": 0", "\"mesh\": 0, \"translation\": [0, 0]", "nodes[0].translation"},
        {"\"mesh\": 0", "\"mesh\": 0, \"scale\": \"big\"", "nodes[0].scale"},
        {"\"mesh\": 0", "\"mesh\": \"0\"", "nodes[0].mesh"},
        {"\"mesh\": 0", "\"mesh\": 0, \"rotation\": [0, 0, 0, null]", "nodes[0].rotation[3]"},
        {"\"count\": 3,\n   \"type\": \"VEC3\"", "\"count\": 3.5,\n   \"type\": \"VEC3\"",
         "accessors[0].count"},
        {"\"POSITION\": 0", "\"POSITION\": true", "meshes[0].primitives[0].attributes.POSITION"},
        {"\"byteLength\": 42", "\"byteLength\": \"42\"", "buffers[0].byteLength"},
        {"\"version\": \"2.0\"", "\"version\": 2.0", "asset.version"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.to);
        std::string json = good;
        ASSERT_NE(json.find(c.from), std::string::npos);
        json.replace(json.find(c.from), c.from.size(), c.to);
        std::ofstream(dir / "scene.gltf", std::ios::trunc) << json;
        try {
            loadScene(dir / "scene.gltf");
            ADD_FAILURE() << "loaded";
        } catch (const FileError& e) {
            EXPECT_NE(std::string(e.what()).find(c.path + ":"), std::string::npos) << e.what();
        }
    }
}

TEST(SceneLoader, MissingFile) {
    EXPECT_THROW(loadScene(scenesDir() / "does_not_exist.gltf"), FileError);
}

}  // namespace
}  // namespace mirage
