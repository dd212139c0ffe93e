#include "core/gl/Objects.h"

#include <atomic>

#include "core/Error.h"

namespace mirage::gl {

namespace detail {
void deleteBuffer(GLuint id) {
    glDeleteBuffers(1, &id);
}
void deleteTexture(GLuint id) {
    glDeleteTextures(1, &id);
}
void deleteFramebuffer(GLuint id) {
    glDeleteFramebuffers(1, &id);
}
void deleteRenderbuffer(GLuint id) {
    glDeleteRenderbuffers(1, &id);
}
void deleteVertexArray(GLuint id) {
    glDeleteVertexArrays(1, &id);
}
void deleteProgram(GLuint id) {
    glDeleteProgram(id);
}
void deleteQuery(GLuint id) {
    glDeleteQueries(1, &id);
}
void deleteSampler(GLuint id) {
    glDeleteSamplers(1, &id);
}
}  // namespace detail

void label(GLenum identifier, GLuint id, std::string_view text) {
    if (!text.empty()) glObjectLabel(identifier, id, GLsizei(text.size()), text.data());
}

// ---- Buffer ----------------------------------------------------------------------------------
Buffer::Buffer(std::string_view lbl, size_t bytes, const void* data, GLbitfield flags)
    : size_(bytes) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    h_ = Handle<detail::deleteBuffer>(id);
    glNamedBufferStorage(id, GLsizeiptr(bytes), data, flags);
    label(GL_BUFFER, id, lbl);
}

void Buffer::upload(const void* data, size_t bytes, size_t offset) {
    MR_CHECK(offset + bytes <= size_, "buffer upload out of range");
    glNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), data);
}

// ---- Texture ---------------------------------------------------------------------------------
namespace {
std::atomic<std::uint64_t> texturesCreated{0};
}

std::uint64_t Texture::createdCount() {
    return texturesCreated.load();
}

namespace {
// A new texture name of `target`, counted and labelled (every factory below starts here).
GLuint createTextureName(GLenum target, std::string_view lbl) {
    GLuint id = 0;
    glCreateTextures(target, 1, &id);
    ++texturesCreated;
    label(GL_TEXTURE, id, lbl);
    return id;
}
}  // namespace

Texture Texture::allocate(GLenum target, std::string_view lbl, int w, int h, int layers, GLenum fmt,
                          int levels, GLenum minFilter) {
    MR_CHECK(w > 0 && h > 0 && layers > 0, "texture size must be positive");
    Texture t;
    const GLuint id = createTextureName(target, lbl);
    t.h_ = Handle<detail::deleteTexture>(id);
    t.width_ = w;
    t.height_ = h;
    t.layers_ = layers;
    t.format_ = fmt;
    t.target_ = target;
    if (target == GL_TEXTURE_2D_ARRAY || target == GL_TEXTURE_3D)
        glTextureStorage3D(id, levels, fmt, w, h, layers);
    else  // 2D, or a cube map (6 faces from one 2D storage call)
        glTextureStorage2D(id, levels, fmt, w, h);
    t.setFilter(minFilter, GL_LINEAR);
    t.setWrap(GL_CLAMP_TO_EDGE);
    return t;
}

Texture Texture::create2D(std::string_view lbl, int w, int h, GLenum fmt, int levels) {
    return allocate(GL_TEXTURE_2D, lbl, w, h, 1, fmt, levels,
                    levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
}

Texture Texture::create2DArray(std::string_view lbl, int w, int h, int layers, GLenum fmt,
                               int levels) {
    return allocate(GL_TEXTURE_2D_ARRAY, lbl, w, h, layers, fmt, levels, GL_LINEAR);
}

Texture Texture::create3D(std::string_view lbl, int w, int h, int d, GLenum fmt) {
    return allocate(GL_TEXTURE_3D, lbl, w, h, d, fmt, 1, GL_LINEAR);
}

Texture Texture::createBufferView(std::string_view lbl) {
    Texture t;
    t.h_ = Handle<detail::deleteTexture>(createTextureName(GL_TEXTURE_BUFFER, lbl));
    t.target_ = GL_TEXTURE_BUFFER;
    return t;
}

void Texture::attachBuffer(const Buffer& buffer, GLenum fmt) {
    MR_CHECK(target_ == GL_TEXTURE_BUFFER, "attachBuffer on a texture that is not a buffer view");
    glTextureBuffer(id(), fmt, buffer.id());
    format_ = fmt;
}

Texture Texture::createCube(std::string_view lbl, int size, GLenum fmt, int levels) {
    return allocate(GL_TEXTURE_CUBE_MAP, lbl, size, size, 6, fmt, levels, GL_LINEAR);
}

void Texture::setFilter(GLenum minFilter, GLenum magFilter) {
    glTextureParameteri(id(), GL_TEXTURE_MIN_FILTER, GLint(minFilter));
    glTextureParameteri(id(), GL_TEXTURE_MAG_FILTER, GLint(magFilter));
}

void Texture::setWrap(GLenum wrap) {
    glTextureParameteri(id(), GL_TEXTURE_WRAP_S, GLint(wrap));
    glTextureParameteri(id(), GL_TEXTURE_WRAP_T, GLint(wrap));
    glTextureParameteri(id(), GL_TEXTURE_WRAP_R, GLint(wrap));
}

void Texture::upload(GLenum pixelFormat, GLenum pixelType, const void* pixels, int layer) {
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (target_ == GL_TEXTURE_2D)
        glTextureSubImage2D(id(), 0, 0, 0, width_, height_, pixelFormat, pixelType, pixels);
    else if (target_ == GL_TEXTURE_3D)
        glTextureSubImage3D(id(), 0, 0, 0, 0, width_, height_, layers_, pixelFormat, pixelType,
                            pixels);
    else
        glTextureSubImage3D(id(), 0, 0, 0, layer, width_, height_, 1, pixelFormat, pixelType,
                            pixels);
}

void Texture::readInto(GLenum pixelFormat, GLenum pixelType, void* dst, size_t bytes) const {
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(id(), 0, pixelFormat, pixelType, GLsizei(bytes), dst);
}

// ---- Framebuffer -----------------------------------------------------------------------------
Framebuffer::Framebuffer(std::string_view lbl) : label_(lbl) {
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    h_ = Handle<detail::deleteFramebuffer>(id);
    label(GL_FRAMEBUFFER, id, lbl);
}

void Framebuffer::attachColor(int index, const Texture& tex, int level) {
    glNamedFramebufferTexture(id(), GLenum(GL_COLOR_ATTACHMENT0 + index), tex.id(), level);
}
void Framebuffer::attachColorLayer(int index, const Texture& tex, int layer, int level) {
    glNamedFramebufferTextureLayer(id(), GLenum(GL_COLOR_ATTACHMENT0 + index), tex.id(), level,
                                   layer);
}
void Framebuffer::attachDepth(const Texture& tex, int level) {
    glNamedFramebufferTexture(id(), GL_DEPTH_ATTACHMENT, tex.id(), level);
}
void Framebuffer::attachDepthLayer(const Texture& tex, int layer, int level) {
    glNamedFramebufferTextureLayer(id(), GL_DEPTH_ATTACHMENT, tex.id(), level, layer);
}

void Framebuffer::finalize(int colorCount) {
    std::vector<GLenum> bufs;
    for (int i = 0; i < colorCount; ++i) bufs.push_back(GLenum(GL_COLOR_ATTACHMENT0 + i));
    if (colorCount == 0)
        glNamedFramebufferDrawBuffer(id(), GL_NONE);
    else
        glNamedFramebufferDrawBuffers(id(), GLsizei(bufs.size()), bufs.data());
    GLenum status = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw Error("framebuffer '" + label_ + "' is incomplete (GL status 0x" +
                    std::to_string(status) + ")");
}

void Framebuffer::bind() const {
    glBindFramebuffer(GL_FRAMEBUFFER, id());
}

// ---- VertexArray / Sampler -------------------------------------------------------------------
VertexArray::VertexArray(std::string_view lbl) {
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    h_ = Handle<detail::deleteVertexArray>(id);
    label(GL_VERTEX_ARRAY, id, lbl);
}
void VertexArray::bind() const {
    glBindVertexArray(id());
}

Sampler::Sampler(std::string_view lbl, GLenum minFilter, GLenum magFilter, GLenum wrap) {
    GLuint id = 0;
    glCreateSamplers(1, &id);
    h_ = Handle<detail::deleteSampler>(id);
    glSamplerParameteri(id, GL_TEXTURE_MIN_FILTER, GLint(minFilter));
    glSamplerParameteri(id, GL_TEXTURE_MAG_FILTER, GLint(magFilter));
    glSamplerParameteri(id, GL_TEXTURE_WRAP_S, GLint(wrap));
    glSamplerParameteri(id, GL_TEXTURE_WRAP_T, GLint(wrap));
    glSamplerParameteri(id, GL_TEXTURE_WRAP_R, GLint(wrap));
    label(GL_SAMPLER, id, lbl);
}

// ---- Program ---------------------------------------------------------------------------------
namespace {
// Inserts `defines` right after the #version line so that a pass can compile variants.
std::string withDefines(std::string_view src, std::string_view defines) {
    std::string s(src);
    if (defines.empty()) return s;
    auto pos = s.find("#version");
    size_t lineEnd = pos == std::string::npos ? 0 : s.find('\n', pos);
    if (lineEnd == std::string::npos) lineEnd = s.size();
    s.insert(lineEnd == 0 ? 0 : lineEnd + 1, std::string(defines) + "\n");
    return s;
}
}  // namespace

Program::Program(std::string_view lbl, const std::vector<Stage>& stages, std::string_view defines) {
    GLuint prog = glCreateProgram();
    h_ = Handle<detail::deleteProgram>(prog);
    std::vector<GLuint> shaders;
    for (const Stage& st : stages) {
        std::string src = withDefines(st.source, defines);
        GLuint sh = glCreateShader(st.type);
        const char* p = src.c_str();
        glShaderSource(sh, 1, &p, nullptr);
        glCompileShader(sh);
        GLint ok = 0;
        glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            GLint len = 0;
            glGetShaderiv(sh, GL_INFO_LOG_LENGTH, &len);
            std::string log(size_t(std::max(len, 1)), '\0');
            glGetShaderInfoLog(sh, len, nullptr, log.data());
            glDeleteShader(sh);
            for (GLuint s : shaders) glDeleteShader(s);
            throw Error("shader " + st.name + " does not compile:\n" + log);
        }
        glAttachShader(prog, sh);
        shaders.push_back(sh);
    }
    glLinkProgram(prog);
    for (GLuint s : shaders) {
        glDetachShader(prog, s);
        glDeleteShader(s);
    }
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(prog, GL_INFO_LOG_LENGTH, &len);
        std::string log(size_t(std::max(len, 1)), '\0');
        glGetProgramInfoLog(prog, len, nullptr, log.data());
        throw Error("program " + std::string(lbl) + " does not link:\n" + log);
    }
    label(GL_PROGRAM, prog, lbl);
}

void Program::use() const {
    glUseProgram(id());
}
GLint Program::uniformLocation(const char* name) const {
    return glGetUniformLocation(id(), name);
}

// ---- TimerQuery ------------------------------------------------------------------------------
TimerQuery::TimerQuery(std::string_view lbl) {
    GLuint id = 0;
    glCreateQueries(GL_TIME_ELAPSED, 1, &id);
    h_ = Handle<detail::deleteQuery>(id);
    label(GL_QUERY, id, lbl);
}
void TimerQuery::begin() {
    glBeginQuery(GL_TIME_ELAPSED, h_.id());
}
void TimerQuery::end() {
    glEndQuery(GL_TIME_ELAPSED);
}
double TimerQuery::elapsedMs() const {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(h_.id(), GL_QUERY_RESULT, &ns);
    return double(ns) * 1e-6;
}

}  // namespace mirage::gl
