#pragma once
// glTF loading, part 5 of 5: the parsed model -> mirage::Scene (SceneLoader.cpp): textures,
// materials, meshes, lights, cameras, the node graph and mirage's extras (real/virtual, the
// environment). Every failure is a mirage::FileError naming `name`, the object and the field.
#include <filesystem>
#include <string>

#include "core/scene/Scene.h"

namespace mirage::gltf {

// Parses a .gltf (JSON) or .glb from `bytes`; external buffers and images are read from
// `baseDir` (the glTF's folder) only.
Scene readGltf(const std::string& bytes, const std::string& name,
               const std::filesystem::path& baseDir);

}  // namespace mirage::gltf
