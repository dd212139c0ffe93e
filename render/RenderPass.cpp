#include "render/RenderPass.h"

#include "render/Shaders.h"

namespace mirage::render {

gl::Program fullscreenProgram(std::string_view label, std::string_view fragmentPath,
                              std::string_view defines) {
    return gl::Program(
        label,
        {{GL_VERTEX_SHADER, "fullscreen.vert", shaders::source("fullscreen.vert")},
         {GL_FRAGMENT_SHADER, std::string(fragmentPath), shaders::source(fragmentPath)}},
        defines);
}

}  // namespace mirage::render
