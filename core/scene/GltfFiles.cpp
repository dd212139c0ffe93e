#include "core/scene/GltfFiles.h"

#include <fstream>

#include "core/ContainedPath.h"
#include "core/scene/GltfScreening.h"

namespace mirage::gltf {
namespace {

namespace fs = std::filesystem;

const std::string& baseOf(void* userData) {
    return *static_cast<const std::string*>(userData);
}

bool fileExists(const std::string& path, void* userData) {
    if (!resolvedAgainst(path, baseOf(userData))) return false;
    std::error_code ec;
    return fs::is_regular_file(path, ec);
}

std::string expandFilePath(const std::string& path, void*) {
    return path;
}

bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                   void* userData) {
    if (!resolvedAgainst(path, baseOf(userData))) {
        if (err) *err += "not beside the glTF file: " + path + "\n";
        return false;
    }
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
        if (err) *err += "not a regular file: " + path + "\n";
        return false;
    }
    uintmax_t size = fs::file_size(path, ec);
    if (ec || size > kMaxFileBytes) {
        if (err) *err += "cannot read or too large (> 2 GiB): " + path + "\n";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    out->resize(static_cast<size_t>(size));
    if (size > 0 &&
        !in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size))) {
        if (err) *err += "read failed: " + path + "\n";
        return false;
    }
    return true;
}

bool writeWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                    void*) {
    if (err) *err += "mirage's scene loader never writes files\n";
    return false;
}

}  // namespace

bool resolvedAgainst(const std::string& path, const std::string& baseDir) {
    if (baseDir.empty()) return false;
    const std::string prefix = baseDir.back() == '/' ? baseDir : baseDir + "/";
    // The URI part after the prefix must itself stay inside the folder once normalised
    // ("base/../../etc/passwd" starts with the prefix too).
    return path.size() > prefix.size() && path.compare(0, prefix.size(), prefix) == 0 &&
           containedReferenceProblem(path.substr(prefix.size())).empty();
}

tinygltf::FsCallbacks fileCallbacks(const std::string* baseDir) {
    return tinygltf::FsCallbacks{&fileExists, &expandFilePath, &readWholeFile, &writeWholeFile,
                                 const_cast<std::string*>(baseDir)};
}

}  // namespace mirage::gltf
