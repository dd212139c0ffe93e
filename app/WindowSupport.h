#pragma once
// What the windows of `mirage calibrate` (the wizard) and `mirage live` share: the Dear ImGui
// context over a GLFW window, and a PNG of the window for documentation and tests.
#include <filesystem>

struct GLFWwindow;

namespace mirage::app {

// RAII for the ImGui context and its GLFW/OpenGL3 backends (GL 4.5 core, no imgui.ini).
class ImGuiScope {
public:
    explicit ImGuiScope(GLFWwindow* window);
    ~ImGuiScope();
    ImGuiScope(const ImGuiScope&) = delete;
    ImGuiScope& operator=(const ImGuiScope&) = delete;
};

// The window's back buffer (what the next swap shows) as an 8-bit PNG; parent folders are
// created. Throws mirage::FileError if it cannot be written.
void saveWindowPng(const std::filesystem::path& path, GLFWwindow* window);

}  // namespace mirage::app
