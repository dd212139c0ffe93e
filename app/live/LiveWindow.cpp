#include "app/live/LiveWindow.h"

#include <epoxy/gl.h>

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "app/EffectSwitches.h"
#include "app/live/LiveRenderStage.h"
#include "core/Log.h"

namespace mirage::app {

LiveWindow::LiveWindow(gl::Context& ctx, const CameraIntrinsics& camera,
                       const PlacementPlane& plane)
    : ctx_(ctx), camera_(camera), plane_(plane), imgui_(ctx.glfwWindow()) {}

void LiveWindow::show(const cv::Mat& bgr) {
    if (bgr.empty()) return;
    if (shown_.id() == 0) {
        shown_ = gl::Texture::create2D("live view", bgr.cols, bgr.rows, GL_RGBA8);
        shown_.setFilter(GL_LINEAR, GL_LINEAR);
    }
    cv::cvtColor(bgr, shownRgba_, cv::COLOR_BGR2RGBA);
    shown_.upload(GL_RGBA, GL_UNSIGNED_BYTE, shownRgba_.data);
}

void LiveWindow::savePng(const std::string& path) const {
    saveWindowPng(path, ctx_.glfwWindow());
}

HudRequests LiveWindow::draw(const HudStatus& status, LiveControls& controls) {
    ctx_.pollEvents();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(ctx_.glfwWindow(), &fbw, &fbh);
    const int width = camera_.width, height = camera_.height;
    // The view fills the space left of the HUD, keeping the camera's aspect ratio.
    const float scale =
        std::min(float(std::max(fbw - kHudWidth, 1)) / float(width), float(fbh) / float(height));
    if (shown_.id() != 0)
        ImGui::GetBackgroundDrawList()->AddImage(
            reinterpret_cast<ImTextureID>(static_cast<uintptr_t>(shown_.id())), {0, 0},
            {float(width) * scale, float(height) * scale});
    HudRequests req;
    const ImGuiIO& io = ImGui::GetIO();
    if (!io.WantCaptureKeyboard) {
        if (ImGui::IsKeyPressed(GLFW_KEY_P, false)) controls.paused = !controls.paused;
        if (ImGui::IsKeyPressed(GLFW_KEY_R, false)) req.toggleRecord = true;
        if (ImGui::IsKeyPressed(GLFW_KEY_S, false)) req.screenshot = true;
        if (ImGui::IsKeyPressed(GLFW_KEY_H, false)) controls.hideVirtual = !controls.hideVirtual;
        if (ImGui::IsKeyPressed(GLFW_KEY_B, false))
            controls.view = (controls.view + 1) % kBufferViewCount;
        if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) req.close = true;
        req.placement = placementInput(status, scale);
    }
    const HudRequests hud = drawHud(status, controls, fbw, fbh);
    req.screenshot = req.screenshot || hud.screenshot;
    req.toggleRecord = req.toggleRecord || hud.toggleRecord;
    req.rebuild = hud.rebuild;
    req.close = req.close || ctx_.shouldClose();
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbw, fbh);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    return req;
}

// Placement, snapped to the board plane: 1 cm steps, 5 degree turns, 5 % scale; a left-drag on
// the view moves the objects with the point under the mouse (on the board plane, seen with the
// last tracked pose), snapped to whole millimetres.
std::optional<ScenePlacement> LiveWindow::placementInput(const HudStatus& status, float scale) {
    ScenePlacement p = status.placement;
    if (ImGui::IsKeyPressed(GLFW_KEY_LEFT)) p.moveU -= 0.01;
    if (ImGui::IsKeyPressed(GLFW_KEY_RIGHT)) p.moveU += 0.01;
    if (ImGui::IsKeyPressed(GLFW_KEY_UP)) p.moveV -= 0.01;
    if (ImGui::IsKeyPressed(GLFW_KEY_DOWN)) p.moveV += 0.01;
    if (ImGui::IsKeyPressed(GLFW_KEY_Q)) p.turnDeg += 5;
    if (ImGui::IsKeyPressed(GLFW_KEY_E)) p.turnDeg -= 5;
    if (ImGui::IsKeyPressed(GLFW_KEY_EQUAL) || ImGui::IsKeyPressed(GLFW_KEY_KP_ADD))
        p.scale *= 1.05;
    if (ImGui::IsKeyPressed(GLFW_KEY_MINUS) || ImGui::IsKeyPressed(GLFW_KEY_KP_SUBTRACT))
        p.scale /= 1.05;
    if (ImGui::IsKeyPressed(GLFW_KEY_0, false)) p = ScenePlacement{};
    const ImGuiIO& io = ImGui::GetIO();
    const ImVec2 mouse = io.MousePos;
    const glm::dvec2 px(mouse.x / scale, mouse.y / scale);
    const std::optional<Pose>& pose = status.last ? status.last->pose.pose : std::optional<Pose>{};
    if (ImGui::IsMouseClicked(0) && !io.WantCaptureMouse && pose &&
        mouse.x < float(camera_.width) * scale) {
        dragStart_ = pixelOnPlane(camera_, *pose, px, plane_);
        dragFrom_ = status.placement;
    }
    if (!ImGui::IsMouseDown(0)) dragStart_.reset();
    if (dragStart_ && pose && ImGui::IsMouseDragging(0)) {
        if (const auto hit = pixelOnPlane(camera_, *pose, px, plane_)) {
            const glm::dvec2 m = inPlaneMove(*dragStart_, *hit, plane_);
            p.moveU = dragFrom_.moveU + std::round(m.x * 1000) / 1000;
            p.moveV = dragFrom_.moveV + std::round(m.y * 1000) / 1000;
        }
    }
    if (p == status.placement) return std::nullopt;
    return p;
}

HudRequests LiveWindow::drawHud(const HudStatus& s, LiveControls& controls, int fbw, int fbh) {
    HudRequests req;
    ImGui::SetNextWindowPos({float(fbw - kHudWidth), 0});
    ImGui::SetNextWindowSize({float(kHudWidth), float(fbh)});
    ImGui::Begin("mirage live", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    const ImVec4 red(1, 0.4f, 0.4f, 1), green(0.4f, 1, 0.4f, 1), amber(1, 0.85f, 0.3f, 1);
    if (!s.lostReason.empty()) ImGui::TextColored(red, "CAMERA LOST: %s", s.lostReason.c_str());
    ImGui::Text("%.1f frames/s | latency %.0f ms (%s)", s.fps, s.latencyMs,
                s.pipelined ? "pipelined" : "serial");
    // Capture-to-display latency with prediction: how far the pose shown lags the display.
    if (std::isfinite(s.predictMs))
        ImGui::Text("pose predicted %.0f ms ahead: %.0f ms behind", s.predictMs,
                    s.latencyMs - s.predictMs);
    else
        ImGui::Text("pose not predicted: %.0f ms behind", s.latencyMs);
    ImGui::Text("dropped %lld (driver %lld)", s.dropped, s.driverDropped);
    const std::string st = s.last ? s.last->pose.state : std::string();
    const std::string mode =
        s.last && !s.last->trackingMode.empty() ? " (" + s.last->trackingMode + ")" : "";
    ImGui::TextColored(st == "ok"   ? green
                       : st.empty() ? amber
                                    : red,
                       "tracking: %s%s", st.empty() ? "waiting for a frame" : st.c_str(),
                       mode.c_str());
    ImGui::PushTextWrapPos(0);
    if (s.last && !s.last->pose.reason.empty())
        ImGui::TextWrapped("%s", s.last->pose.reason.c_str());
    ImGui::TextWrapped("exposure: %s", s.exposureText.c_str());
    // The gain the last frame was composited with (docs/camera-matching.md): R, G, B and whether
    // it was measured, a step, held or the prior.
    if (s.last && !s.last->exposureSource.empty())
        ImGui::Text("exposure gain: %.3f %.3f %.3f (%s)", s.last->exposureGain.r,
                    s.last->exposureGain.g, s.last->exposureGain.b, s.last->exposureSource.c_str());
    if (!s.environmentText.empty())
        ImGui::TextWrapped("environment: %s", s.environmentText.c_str());
    if (!s.budgetText.empty()) ImGui::TextWrapped("budget: %s", s.budgetText.c_str());
    for (const auto& w : s.exposureWarnings) ImGui::TextColored(amber, "%s", w.c_str());
    ImGui::PopTextWrapPos();
    ImGui::Separator();
    if (s.last && s.last->report &&
        ImGui::BeginTable("passes", 2, ImGuiTableFlags_SizingFixedFit)) {
        for (const auto& pr : s.last->report->passes) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(pr.name.c_str());
            ImGui::TableNextColumn();
            if (pr.ran)
                ImGui::Text("%6.2f ms", pr.gpuMs);
            else
                ImGui::TextDisabled("%s", pr.reused ? "reused" : "off");
        }
        ImGui::EndTable();
        ImGui::Text("GPU %.1f ms", s.last->gpuMs);
    }
    ImGui::Separator();
    if (ImGui::BeginCombo("quality", kQualityPresets[controls.preset].name)) {
        for (int i = 0; i < kQualityPresetCount; ++i)
            if (ImGui::Selectable(kQualityPresets[i].name, i == controls.preset) &&
                i != controls.preset) {
                controls.preset = i;
                req.rebuild = true;
            }
        ImGui::EndCombo();
    }
    if (ImGui::BeginCombo("view (B)", kBufferViews[controls.view].name)) {
        for (int i = 0; i < kBufferViewCount; ++i)
            if (ImGui::Selectable(kBufferViews[i].name, i == controls.view)) controls.view = i;
        ImGui::EndCombo();
    }
    if (!s.viewProblem.empty()) ImGui::TextColored(amber, "%s", s.viewProblem.c_str());
    // Effects on/off: each switch rebuilds the renderer (its passes leave the frame graph, and
    // the pass table above says why they did not run).
    if (ImGui::CollapsingHeader("effects")) {
        for (const EffectSwitch& e : kEffectSwitches) {
            bool on = e.flag(controls.effects);
            if (ImGui::Checkbox(e.label, &on)) {
                e.flag(controls.effects) = on;
                req.rebuild = true;
                spdlog::info("live: {} {}", e.name, on ? "on" : "off");
            }
        }
    }
    const ScenePlacement& p = s.placement;
    ImGui::Text("placement %+.2f %+.2f m, %+.0f deg, x%.2f%s", p.moveU, p.moveV, p.turnDeg, p.scale,
                s.placementPending ? " (moving)" : "");
    ImGui::TextDisabled("drag or arrows move, Q/E turn, +/- scale, 0 reset");
    ImGui::Checkbox("pause (P)", &controls.paused);
    ImGui::SameLine();
    ImGui::Checkbox("hide virtual (H)", &controls.hideVirtual);
    if (ImGui::Button(s.recordingText.empty() ? "record (R)" : "stop recording (R)"))
        req.toggleRecord = true;
    ImGui::SameLine();
    if (ImGui::Button("screenshot (S)")) req.screenshot = true;
    if (!s.recordingText.empty()) ImGui::TextColored(red, "%s", s.recordingText.c_str());
    if (!s.scanText.empty()) ImGui::TextColored(red, "%s", s.scanText.c_str());
    ImGui::End();
    return req;
}

}  // namespace mirage::app
