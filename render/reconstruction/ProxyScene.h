#pragma once
// The reconstructed scene as glTF (docs/scene.md, "Reconstructed scenes"): the virtual objects of
// a given scene file, kept as they are, plus the reconstructed real proxies, light and camera,
// marked real. The real nodes of the given file (hand-made proxies, their lights) are dropped:
// the footage replaces them. Writes SCENE.gltf, SCENE.proxies.bin (the new meshes) and
// SCENE.table.png (the table's albedo, sRGB); URIs of the given file are rewritten relative to the
// new file's folder (files outside it copied in), so it stays a plain, editable glTF.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "render/reconstruction/LightFit.h"
#include "render/reconstruction/ProxyGeometry.h"

namespace mirage::reconstruction {

struct ProxySceneContent {
    const FusedGeometry* geometry = nullptr;
    const LightingEstimate* lighting = nullptr;
    double tableThicknessM = 0.03;  // the table is a slab under the plane
    // The main camera as the session places it (first tracked frame), and its vertical field of
    // view (radians) and aspect ratio.
    std::optional<Pose> camera;
    double yfov = 0.8, aspectRatio = 4.0 / 3.0;
};

struct ProxySceneSummary {
    int droppedNodes = 0;  // real nodes of the virtual scene file
    int keptNodes = 0;     // virtual nodes
    std::vector<std::string> warnings;
    // Files of the virtual scene copied beside the output (a scene names files in its own
    // folder only).
    std::vector<std::string> copiedFiles;
};

// Throws FileError naming `virtualScene` when it is not a .gltf JSON file (.glb: convert it) or
// is malformed, and naming `out` when it cannot be written.
ProxySceneSummary writeProxyScene(const ProxySceneContent& content,
                                  const std::filesystem::path& virtualScene,
                                  const std::filesystem::path& out);

}  // namespace mirage::reconstruction
