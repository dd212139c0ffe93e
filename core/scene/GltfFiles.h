#pragma once
// glTF loading, part 2 of 5: the file access tinygltf gets for external buffers and images
// (SceneLoader.cpp). Regular files only, size-capped, no '~' expansion, nothing written, and only
// files resolved against the glTF's own folder: tinygltf also looks a relative URI up in the
// current directory, which would silently take a same-named file from wherever mirage was started
// when the file beside the glTF is missing. A URI that climbs out of the folder ("../x") is refused
// here as well as by the schema check (GltfSchema.h), which names it.
#include <filesystem>
#include <string>

#include <tiny_gltf.h>

namespace mirage::gltf {

// The callbacks for tinygltf::TinyGLTF::SetFsCallbacks. `baseDir` (the glTF's folder, the same
// string given to tinygltf as its base directory) must outlive the callbacks. An empty `baseDir`
// allows no external file at all.
tinygltf::FsCallbacks fileCallbacks(const std::string* baseDir);

// Whether `path`, as tinygltf joins it (baseDir + '/' + uri), names a file under `baseDir`: the
// part after the prefix must stay inside it after normalisation (core/ContainedPath.h).
bool resolvedAgainst(const std::string& path, const std::string& baseDir);

}  // namespace mirage::gltf
