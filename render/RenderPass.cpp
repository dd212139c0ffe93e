#include "render/RenderPass.h"

#include "render/FrameGraph.h"
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

void TargetFramebuffer::bind(std::initializer_list<const gl::Texture*> colors) {
    std::vector<GLuint> ids;
    for (const gl::Texture* t : colors) ids.push_back(t->id());
    if (ids != ids_) {
        fbo_ = gl::Framebuffer(label_);
        int i = 0;
        for (const gl::Texture* t : colors) fbo_.attachColor(i++, *t);
        fbo_.finalize(i);
        ids_ = std::move(ids);
    }
    fbo_.bind();
}

int PassBuilder::newestVersion(Resource r) const {
    int v = graph_ ? graph_->newestVersion(r) : -1;
    for (const ResourceWrite& w : writes_)
        if (w.id == r) v = w.modifies ? v + 1 : 0;
    return v;
}

TextureHandle PassBuilder::create(Resource r, TextureDesc desc) {
    writes_.push_back({r, false, desc, false, 0});
    return {r, graph_ ? 0 : -1};
}

void PassBuilder::createBuffer(Resource r, SizeRule size, bool persistent) {
    writes_.push_back(
        {r, true, {0, size, persistent ? Storage::Persistent : Storage::PassOwned}, false, 0});
}

TextureHandle PassBuilder::modify(Resource r, TextureDesc desc) {
    const int v = newestVersion(r);
    reads_.push_back({r, false, v});
    writes_.push_back({r, false, desc, true, v + 1});
    return {r, graph_ && v >= 0 ? v + 1 : -1};
}

TextureHandle PassBuilder::modifyOptional(Resource r, TextureDesc desc) {
    const int v = newestVersion(r);
    reads_.push_back({r, true, v});
    writes_.push_back({r, false, desc, true, v + 1});
    return {r, graph_ && v >= 0 ? v + 1 : -1};
}

TextureHandle PassBuilder::read(Resource r) {
    reads_.push_back({r, false, -1});
    return {r, newestVersion(r)};
}

TextureHandle PassBuilder::readOptional(Resource r) {
    reads_.push_back({r, true, -1});
    return {r, newestVersion(r)};
}

TextureHandle PassBuilder::read(TextureHandle h) {
    reads_.push_back({h.resource, false, h.version});
    return h;
}

}  // namespace mirage::render
