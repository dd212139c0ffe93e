#include "render/FrameContext.h"

#include "core/Error.h"

namespace mirage::render {

const char* resourceName(Resource r) {
    switch (r) {
        case Resource::CameraImage:
            return "CameraImage";
        case Resource::GBuffer:
            return "GBuffer";
        case Resource::ShadowMaps:
            return "ShadowMaps";
        case Resource::ShadowMapsReal:
            return "ShadowMapsReal";
        case Resource::ReflectiveShadowMaps:
            return "ReflectiveShadowMaps";
        case Resource::Vpls:
            return "Vpls";
        case Resource::ImperfectShadowMaps:
            return "ImperfectShadowMaps";
        case Resource::ImperfectShadowMapsReal:
            return "ImperfectShadowMapsReal";
        case Resource::DirectRv:
            return "DirectRv";
        case Resource::DirectR:
            return "DirectR";
        case Resource::IndirectRv:
            return "IndirectRv";
        case Resource::IndirectR:
            return "IndirectR";
        case Resource::LRv:
            return "LRv";
        case Resource::LR:
            return "LR";
        case Resource::BackFaces:
            return "BackFaces";
        case Resource::RealSurfaces:
            return "RealSurfaces";
        case Resource::ReflectionGBuffer:
            return "ReflectionGBuffer";
        case Resource::RefractionGBuffer:
            return "RefractionGBuffer";
        case Resource::SpecularRv:
            return "SpecularRv";
        case Resource::SpecularR:
            return "SpecularR";
        case Resource::Lenv:
            return "Lenv";
        case Resource::Composite:
            return "Composite";
        case Resource::Impostors:
            return "Impostors";
    }
    return "?";
}

FrameContext::FrameContext(const GpuScene& s, const CameraProjection& p, const RendererOptions& o)
    : scene(s),
      projection(p),
      options(o),
      frameUbo("frame ubo", sizeof(GpuFrame)),
      lightUbo("light ubo", sizeof(GpuLightBlock)),
      emptyVao("empty vao") {
    black_ = gl::Texture::create2D("black 1x1", 1, 1, GL_RGBA16F);
    const float zero[4] = {0, 0, 0, 0};
    black_.upload(GL_RGBA, GL_FLOAT, zero);
    farShadow_ = gl::Texture::create2DArray("far shadow 1x1", 1, 1, 1, GL_R32F);
    const float far = 1e30f;
    farShadow_.upload(GL_RED, GL_FLOAT, &far);
    farShadow_.setFilter(GL_NEAREST, GL_NEAREST);
}

void FrameContext::publish(Resource r, const gl::Texture* tex) {
    published_[r] = tex;
}

const gl::Texture& FrameContext::texture(Resource r) const {
    auto it = published_.find(r);
    MR_CHECK(it != published_.end() && it->second,
             std::string("resource ") + resourceName(r) + " read before any pass wrote it");
    return *it->second;
}

void FrameContext::bindFrameBlocks() const {
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingFrame, frameUbo.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingLights, lightUbo.id());
}

void FrameContext::beginFullscreen(const gl::Program& program, int width, int height) const {
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    program.use();
    bindFrameBlocks();
}

void FrameContext::drawFullscreenTriangle() const {
    emptyVao.bind();
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace mirage::render
