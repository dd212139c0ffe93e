#include "render/FrameContext.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/Error.h"

namespace mirage::render {

void RendererOptions::validate() const {
    vpl.validate();
    indirect.validate();
    ism.validate();
    shadow.validate();
    direct.validate();
    caustic.validate();
    specular.validate();
    fuzzy.validate();
    rough.validate();
    impostor.validate();
    environment.validate();
    translucency.validate();
    composite.validate();
    exposureMatch.validate();
    motionBlur.validate();
    aa.validate();
    grain.validate();
    checkOption(temporalBlend >= 0.0f && temporalBlend <= 0.98f, "temporalBlend",
                "in [0, 0.98] (the history's weight)", temporalBlend);
    passes.validate();
}

int ismTilesPerRow(int vplCount) {
    return std::max(1, int(std::ceil(std::sqrt(double(std::max(vplCount, 1))))));
}

FrameContext::FrameContext(const GpuScene& s, const CameraProjection& p, const RendererOptions& o)
    : scene(s),
      projection(p),
      options(o),
      frameUbo("frame ubo", sizeof(GpuFrame)),
      lightUbo("light ubo", sizeof(GpuLightBlock)),
      emptyVao("empty vao") {
    exposure.gain =
        glm::dvec3(double(o.composite.exposure));  // the prior, until a frame says otherwise
    black_ = gl::Texture::create2D("black 1x1", 1, 1, GL_RGBA16F);
    const float zero[4] = {0, 0, 0, 0};
    black_.upload(GL_RGBA, GL_FLOAT, zero);
    farShadow_ = gl::Texture::create2DArray("far shadow 1x1", 1, 1, 1, GL_R32F);
    const float far = 1e30f;
    farShadow_.upload(GL_RED, GL_FLOAT, &far);
    farShadow_.setFilter(GL_NEAREST, GL_NEAREST);
    noGlass_ = gl::Texture::create2DArray("no glass 1x1", 1, 1, 1, GL_RGBA32F);
    const float noGlass[4] = {0.0f, 0.0f, 0.0f, 1e30f};
    noGlass_.upload(GL_RGBA, GL_FLOAT, noGlass);
    noGlass_.setFilter(GL_NEAREST, GL_NEAREST);
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

void FrameContext::clearForRects(const std::vector<glm::ivec4>& rects, DrawnRects& drawn, int first,
                                 int count, bool clearDepth) const {
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const float one = 1.0f;
    auto inside = [](const glm::ivec4& a, const glm::ivec4& b) {  // a within b
        return a.x >= b.x && a.y >= b.y && a.x + a.z <= b.x + b.z && a.y + a.w <= b.y + b.w;
    };
    glEnable(GL_SCISSOR_TEST);
    auto clearIn = [&](const glm::ivec4& r) {
        if (r.z <= 0 || r.w <= 0) return;
        glScissor(r.x, r.y, r.z, r.w);
        for (int i = first; i < first + count; ++i) glClearBufferfv(GL_COLOR, i, zero);
        if (clearDepth) glClearBufferfv(GL_DEPTH, 0, &one);
    };
    for (const glm::ivec4& r : drawn.rects) clearIn(r);
    for (const glm::ivec4& r : rects)
        if (std::none_of(drawn.rects.begin(), drawn.rects.end(),
                         [&](const glm::ivec4& d) { return inside(r, d); }))
            clearIn(r);
    glDisable(GL_SCISSOR_TEST);
    drawn.rects = rects;
}

void FrameContext::drawFullscreenTriangleIn(const std::vector<glm::ivec4>& rects) const {
    glEnable(GL_SCISSOR_TEST);
    for (const glm::ivec4& rect : rects) {
        if (rect.z <= 0 || rect.w <= 0) continue;
        glScissor(rect.x, rect.y, rect.z, rect.w);
        drawFullscreenTriangle();
    }
    glDisable(GL_SCISSOR_TEST);
}

void FrameContext::drawFullscreenTriangleOutsideSpecular(int first, int count) const {
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glEnable(GL_SCISSOR_TEST);
    for (const glm::ivec4& r : specularRects) {
        if (r.z <= 0 || r.w <= 0) continue;
        glScissor(r.x, r.y, r.z, r.w);
        for (int i = first; i < first + count; ++i) glClearBufferfv(GL_COLOR, i, zero);
    }
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);  // the triangle lies at depth 0.5: passes where the mask is 1
    glDepthMask(GL_FALSE);
    drawFullscreenTriangle();
    glDepthMask(GL_TRUE);
    glDisable(GL_DEPTH_TEST);
}

bool rectsOverlap(const glm::ivec4& a, const glm::ivec4& b) {
    return a.x < b.x + b.z && b.x < a.x + a.z && a.y < b.y + b.w && b.y < a.y + a.w;
}

void separateMirrorRects(std::vector<glm::ivec4>& glass, std::vector<glm::ivec4>& mirror) {
    glass = mergeOverlappingRects(std::move(glass));
    mirror = mergeOverlappingRects(std::move(mirror));
    // A merge of the glass rectangles can reach another mirror one: repeat until none meets.
    for (bool moved = true; moved;) {
        moved = false;
        for (size_t i = 0; i < mirror.size() && !moved; ++i)
            if (std::any_of(glass.begin(), glass.end(),
                            [&](const glm::ivec4& g) { return rectsOverlap(mirror[i], g); })) {
                glass.push_back(mirror[i]);
                mirror.erase(mirror.begin() + std::ptrdiff_t(i));
                glass = mergeOverlappingRects(std::move(glass));
                moved = true;
            }
    }
}

std::vector<glm::ivec4> mergeOverlappingRects(std::vector<glm::ivec4> rects) {
    std::erase_if(rects, [](const glm::ivec4& r) { return r.z <= 0 || r.w <= 0; });
    // Merging two can make the union overlap a third that neither did: repeat until no pair
    // overlaps (n is the number of specular objects in view, a handful).
    for (bool merged = true; merged;) {
        merged = false;
        for (size_t i = 0; i < rects.size() && !merged; ++i)
            for (size_t j = i + 1; j < rects.size() && !merged; ++j) {
                const glm::ivec4 a = rects[i], b = rects[j];
                if (!rectsOverlap(a, b)) continue;
                const int x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
                const int x1 = std::max(a.x + a.z, b.x + b.z), y1 = std::max(a.y + a.w, b.y + b.w);
                rects[i] = {x0, y0, x1 - x0, y1 - y0};
                rects.erase(rects.begin() + std::ptrdiff_t(j));
                merged = true;
            }
    }
    return rects;
}

}  // namespace mirage::render
