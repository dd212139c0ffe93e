#include "core/gl/Context.h"

#include <cstdlib>
#include <mutex>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/Error.h"
#include "core/Log.h"

namespace mirage::gl {

namespace {

void GLAPIENTRY debugCallback(GLenum, GLenum type, GLuint, GLenum severity, GLsizei,
                              const GLchar* message, const void*) {
    if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
    if (type == GL_DEBUG_TYPE_ERROR)
        spdlog::error("GL: {}", message);
    else
        spdlog::debug("GL: {}", message);
}

void enableDebug(bool on) {
    if (!on) return;
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(debugCallback, nullptr);
}

void requireVersion45(const char* how) {
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major * 10 + minor < 45)
        throw Error(std::string("OpenGL 4.5 core is required but the ") + how + " context is " +
                    std::to_string(major) + "." + std::to_string(minor) +
                    " (install Mesa 22+: apt-get install libgl1-mesa-dri libegl-mesa0)");
}

std::once_flag glfwInitOnce;
bool glfwReady = false;

}  // namespace

struct Context::Impl {
    Kind kind = Kind::Headless;
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    GLFWwindow* window = nullptr;

    ~Impl() {
        if (window) glfwDestroyWindow(window);
        if (context != EGL_NO_CONTEXT) {
            eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(display, context);
        }
        // The display is left initialised: EGL displays are process-wide and reference counted
        // by Mesa; terminating it would invalidate other live contexts on the same display.
    }
};

Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;
Context::~Context() = default;

Context Context::headless(const ContextOptions& opts) {
    auto impl = std::make_unique<Impl>();
    impl->kind = Kind::Headless;
    if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless"))
        throw Error(
            "headless OpenGL needs EGL's surfaceless platform (EGL_MESA_platform_surfaceless); "
            "install Mesa's EGL: apt-get install libegl-mesa0 libgl1-mesa-dri");
    impl->display =
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (impl->display == EGL_NO_DISPLAY || !eglInitialize(impl->display, &major, &minor))
        throw Error("could not initialise an EGL surfaceless display (EGL error 0x" +
                    std::to_string(eglGetError()) + "); is Mesa installed?");
    if (!eglBindAPI(EGL_OPENGL_API)) throw Error("EGL cannot bind the desktop OpenGL API");

    const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    eglChooseConfig(impl->display, configAttribs, &config, 1, &count);
    const EGLint ctxAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                 4,
                                 EGL_CONTEXT_MINOR_VERSION,
                                 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                 EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                 EGL_CONTEXT_OPENGL_DEBUG,
                                 opts.debugOutput ? EGL_TRUE : EGL_FALSE,
                                 EGL_NONE};
    impl->context = eglCreateContext(impl->display, count > 0 ? config : EGL_NO_CONFIG_KHR,
                                     EGL_NO_CONTEXT, ctxAttribs);
    if (impl->context == EGL_NO_CONTEXT)
        throw Error("could not create an OpenGL 4.5 core context through EGL (error " +
                    std::to_string(eglGetError()) + "); Mesa 22 or newer provides one");
    Context ctx(std::move(impl));
    ctx.makeCurrent();
    requireVersion45("headless EGL");
    enableDebug(opts.debugOutput);
    return ctx;
}

bool Context::displayAvailable() {
    const char* x = std::getenv("DISPLAY");
    const char* w = std::getenv("WAYLAND_DISPLAY");
    return (x && *x) || (w && *w);
}

Context Context::window(const ContextOptions& opts) {
    std::call_once(glfwInitOnce, [] {
        glfwSetErrorCallback(
            [](int code, const char* desc) { spdlog::warn("GLFW error {}: {}", code, desc); });
        glfwReady = glfwInit() == GLFW_TRUE;
    });
    if (!glfwReady)
        throw Error(
            "could not open a window: GLFW failed to initialise (no display?); "
            "run headless instead");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, opts.debugOutput ? GLFW_TRUE : GLFW_FALSE);
    auto impl = std::make_unique<Impl>();
    impl->kind = Kind::Window;
    impl->window = glfwCreateWindow(opts.width, opts.height, opts.title.c_str(), nullptr, nullptr);
    if (!impl->window)
        throw Error("could not create a 4.5 core OpenGL window (" + std::to_string(opts.width) +
                    "x" + std::to_string(opts.height) + ")");
    Context ctx(std::move(impl));
    ctx.makeCurrent();
    glfwSwapInterval(0);
    requireVersion45("GLFW window");
    enableDebug(opts.debugOutput);
    return ctx;
}

Context Context::automatic(const ContextOptions& opts, bool preferWindow) {
    if (preferWindow && displayAvailable()) {
        try {
            return window(opts);
        } catch (const Error& e) {
            spdlog::warn("{}; falling back to headless rendering", e.what());
        }
    }
    return headless(opts);
}

Context::Kind Context::kind() const {
    return impl_->kind;
}

void Context::makeCurrent() {
    if (impl_->window) {
        glfwMakeContextCurrent(impl_->window);
    } else if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context)) {
        throw Error("eglMakeCurrent failed (error " + std::to_string(eglGetError()) + ")");
    }
}

GLFWwindow* Context::glfwWindow() const {
    return impl_->window;
}
bool Context::shouldClose() const {
    return impl_->window && glfwWindowShouldClose(impl_->window);
}
void Context::swapBuffers() {
    if (impl_->window) glfwSwapBuffers(impl_->window);
}
void Context::pollEvents() {
    if (impl_->window) glfwPollEvents();
}
std::string Context::rendererName() const {
    auto s = glGetString(GL_RENDERER);
    return s ? reinterpret_cast<const char*>(s) : "";
}
std::string Context::versionString() const {
    auto s = glGetString(GL_VERSION);
    return s ? reinterpret_cast<const char*>(s) : "";
}

}  // namespace mirage::gl
