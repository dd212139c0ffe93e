#pragma once
#include <cstddef>
#include <cstdint>

namespace mirage::fuzz {

// Loads `data` as a scene; true if it loaded, false if it was rejected with a mirage::Error.
// Anything else (another exception, a crash, a sanitizer report) is a bug in the loader.
bool loadSceneOnce(const uint8_t* data, size_t size);

}  // namespace mirage::fuzz
