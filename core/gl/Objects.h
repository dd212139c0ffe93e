#pragma once
// Move-only RAII wrappers for OpenGL objects (4.5 DSA style). The destructor deletes the object;
// id() is the only raw access. Every object gets a debug label (glObjectLabel) so that GL debug
// output and frame captures name it.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <epoxy/gl.h>

namespace mirage::gl {

// Owns one GL name; Deleter is called with it when the handle dies.
template <void (*Deleter)(GLuint)>
class Handle {
public:
    Handle() = default;
    explicit Handle(GLuint id) : id_(id) {}
    Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
    Handle& operator=(Handle&& o) noexcept {
        if (this != &o) {
            reset();
            id_ = std::exchange(o.id_, 0);
        }
        return *this;
    }
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    ~Handle() { reset(); }
    GLuint id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    void reset() {
        if (id_) Deleter(id_);
        id_ = 0;
    }

private:
    GLuint id_ = 0;
};

namespace detail {
void deleteBuffer(GLuint id);
void deleteTexture(GLuint id);
void deleteFramebuffer(GLuint id);
void deleteRenderbuffer(GLuint id);
void deleteVertexArray(GLuint id);
void deleteProgram(GLuint id);
void deleteQuery(GLuint id);
void deleteSampler(GLuint id);
}  // namespace detail

class Buffer {
public:
    Buffer() = default;
    // Immutable storage (glNamedBufferStorage) of `bytes`, optionally initialised from `data`.
    Buffer(std::string_view label, size_t bytes, const void* data = nullptr,
           GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
    GLuint id() const { return h_.id(); }
    size_t size() const { return size_; }
    void upload(const void* data, size_t bytes, size_t offset = 0);

private:
    Handle<detail::deleteBuffer> h_;
    size_t size_ = 0;
};

class Texture {
public:
    Texture() = default;
    // 2D texture with immutable storage: internalFormat e.g. GL_RGBA16F, GL_DEPTH_COMPONENT32F.
    static Texture create2D(std::string_view label, int width, int height, GLenum internalFormat,
                            int levels = 1);
    static Texture create2DArray(std::string_view label, int width, int height, int layers,
                                 GLenum internalFormat, int levels = 1);
    static Texture createCube(std::string_view label, int size, GLenum internalFormat,
                              int levels = 1);
    // 3D texture (width x height x depth, depth reported as layers()), trilinear, clamp to edge.
    static Texture create3D(std::string_view label, int width, int height, int depth,
                            GLenum internalFormat);
    // A buffer texture (GL_TEXTURE_BUFFER): no storage of its own; attachBuffer points it at a
    // buffer's bytes, which shaders read with texelFetch(samplerBuffer, i).
    static Texture createBufferView(std::string_view label);
    // Points a buffer texture at `buffer`, read as texels of `internalFormat` (e.g. GL_RGBA32F).
    // Cheap: call it whenever the buffer may have been reallocated.
    void attachBuffer(const Buffer& buffer, GLenum internalFormat);
    // Textures created so far by this process (all the factories): lets a test check that a
    // per-frame loop allocates nothing once it runs (a renderer that did cost page faults on
    // every target and lost its temporal history).
    static std::uint64_t createdCount();
    GLuint id() const { return h_.id(); }
    int width() const { return width_; }
    int height() const { return height_; }
    int layers() const { return layers_; }
    GLenum format() const { return format_; }
    void setFilter(GLenum minFilter, GLenum magFilter);
    void setWrap(GLenum wrap);
    // Uploads level 0 (or a layer of an array texture; all of a 3D texture) from tightly packed
    // pixels.
    void upload(GLenum pixelFormat, GLenum pixelType, const void* pixels, int layer = 0);
    // Reads level 0 back (glGetTextureImage) into a tightly packed vector of `T`.
    template <class T>
    std::vector<T> read(GLenum pixelFormat, GLenum pixelType, int components) const {
        std::vector<T> out(size_t(width_) * size_t(height_) * size_t(layers_) * components);
        readInto(pixelFormat, pixelType, out.data(), out.size() * sizeof(T));
        return out;
    }

private:
    // The factories: immutable storage, label, min filter `minFilter`, clamp to edge.
    static Texture allocate(GLenum target, std::string_view label, int width, int height,
                            int layers, GLenum internalFormat, int levels, GLenum minFilter);
    void readInto(GLenum pixelFormat, GLenum pixelType, void* dst, size_t bytes) const;
    Handle<detail::deleteTexture> h_;
    int width_ = 0, height_ = 0, layers_ = 1;
    GLenum format_ = 0;
    GLenum target_ = GL_TEXTURE_2D;
};

class Framebuffer {
public:
    Framebuffer() = default;
    explicit Framebuffer(std::string_view label);
    GLuint id() const { return h_.id(); }
    void attachColor(int index, const Texture& tex, int level = 0);
    void attachColorLayer(int index, const Texture& tex, int layer, int level = 0);
    void attachDepth(const Texture& tex, int level = 0);
    void attachDepthLayer(const Texture& tex, int layer, int level = 0);
    // Selects the draw buffers COLOR_ATTACHMENT0..count-1 and throws mirage::Error if the
    // framebuffer is incomplete (naming the label and the GL status).
    void finalize(int colorCount);
    void bind() const;

private:
    Handle<detail::deleteFramebuffer> h_;
    std::string label_;
};

class VertexArray {
public:
    VertexArray() = default;
    explicit VertexArray(std::string_view label);
    GLuint id() const { return h_.id(); }
    void bind() const;

private:
    Handle<detail::deleteVertexArray> h_;
};

class Sampler {
public:
    Sampler() = default;
    Sampler(std::string_view label, GLenum minFilter, GLenum magFilter, GLenum wrap);
    GLuint id() const { return h_.id(); }

private:
    Handle<detail::deleteSampler> h_;
};

// A linked program. Compile/link failures throw mirage::Error with the shader's name and the log.
class Program {
public:
    struct Stage {
        GLenum type;       // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER, ...
        std::string name;  // for messages, e.g. "passes/gbuffer/gbuffer.frag"
        std::string_view source;
    };
    Program() = default;
    Program(std::string_view label, const std::vector<Stage>& stages,
            std::string_view defines = {});
    GLuint id() const { return h_.id(); }
    void use() const;
    GLint uniformLocation(const char* name) const;  // -1 when the uniform was optimised out

private:
    Handle<detail::deleteProgram> h_;
};

// GL_TIME_ELAPSED query for timing a pass; the result is read without stalling when possible.
class TimerQuery {
public:
    TimerQuery() = default;
    explicit TimerQuery(std::string_view label);
    void begin();
    void end();
    // Elapsed milliseconds of the last begin/end; waits for the result.
    double elapsedMs() const;

private:
    Handle<detail::deleteQuery> h_;
};

void label(GLenum identifier, GLuint id, std::string_view text);

}  // namespace mirage::gl
