#pragma once
// An OpenGL 4.5 core context. Headless through EGL's surfaceless platform (Mesa llvmpipe on
// machines without a GPU or display), or a visible GLFW window. Everything above this class is
// the same code on both paths: it renders into framebuffers it owns and reads them back, and a
// window additionally blits to its default framebuffer and swaps.
#include <memory>
#include <string>

struct GLFWwindow;

namespace mirage::gl {

struct ContextOptions {
    int width = 640, height = 480;  // window size; ignored for headless
    std::string title = "mirage";
    bool debugOutput = false;  // KHR_debug messages to the log (slow; for development)
};

class Context {
public:
    enum class Kind { Headless, Window };

    // EGL surfaceless context. Throws mirage::Error (with what to install) if none can be made.
    static Context headless(const ContextOptions& opts = {});
    // GLFW window. Throws mirage::Error if there is no display.
    static Context window(const ContextOptions& opts);
    // A window when a display is available and `preferWindow`, else headless.
    static Context automatic(const ContextOptions& opts, bool preferWindow);
    static bool displayAvailable();

    Context(Context&&) noexcept;
    Context& operator=(Context&&) noexcept;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    ~Context();

    Kind kind() const;
    void makeCurrent();
    GLFWwindow* glfwWindow() const;    // nullptr when headless
    bool shouldClose() const;          // window closed by the user (always false headless)
    void swapBuffers();                // no-op headless
    void pollEvents();                 // no-op headless
    std::string rendererName() const;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string versionString() const;

    struct Impl;

private:
    explicit Context(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace mirage::gl
