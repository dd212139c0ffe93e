#pragma once
// The GLSL sources embedded at build time (scripts/cmake/EmbedShaders.cmake): every .vert,
// .frag, .comp, .geom, .glsl under render/, by path relative to render/, with #include lines
// already expanded. The program therefore runs from any directory.
#include <string_view>
#include <vector>

namespace mirage::shaders {
// Throws std::runtime_error naming the shader when there is none by that name (a bug).
std::string_view source(std::string_view name);
std::vector<std::string_view> names();
}  // namespace mirage::shaders
