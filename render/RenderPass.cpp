#include "render/RenderPass.h"

#include "render/Shaders.h"

namespace mirage::render {

gl::Program fullscreenProgram(std::string_view label, std::string_view fragmentPath,
                              std::string_view defines) {
    return rasterProgram(label, "fullscreen.vert", fragmentPath, defines);
}

gl::Program rasterProgram(std::string_view label, std::string_view vertexPath,
                          std::string_view fragmentPath, std::string_view defines) {
    return gl::Program(
        label,
        {{GL_VERTEX_SHADER, std::string(vertexPath), shaders::source(vertexPath)},
         {GL_FRAGMENT_SHADER, std::string(fragmentPath), shaders::source(fragmentPath)}},
        defines);
}

gl::Program computeProgram(std::string_view label, std::string_view computePath,
                           std::string_view defines) {
    return gl::Program(
        label, {{GL_COMPUTE_SHADER, std::string(computePath), shaders::source(computePath)}},
        defines);
}

void PassBuilder::write(Resource r, GLenum format, SizeRule size, bool persistent) {
    writes_.push_back({r, false, format, size, persistent});
}

void PassBuilder::writeBuffer(Resource r, SizeRule size, bool persistent) {
    writes_.push_back({r, true, 0, size, persistent});
}

void PassBuilder::read(Resource r) {
    reads_.push_back({r, false});
}

void PassBuilder::readOptional(Resource r) {
    reads_.push_back({r, true});
}

}  // namespace mirage::render
