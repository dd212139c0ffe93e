#include "app/wizard/CalibrationWizard.h"

#include <epoxy/gl.h>

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <algorithm>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "app/WindowSupport.h"
#include "calibration/BatchCalibration.h"
#include "calibration/CalibrationSession.h"
#include "calibration/Undistorter.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CalibrationFile.h"
#include "core/capture/V4l2Camera.h"
#include "core/gl/Context.h"
#include "core/gl/Objects.h"
#include "core/session/FrameSource.h"

namespace mirage::app {
namespace {

// An RGBA8 texture showing an 8-bit BGR image (sRGB-encoded values shown as they are).
class ImageTexture {
public:
    void show(const cv::Mat& bgr) {
        if (tex_.id() == 0 || tex_.width() != bgr.cols || tex_.height() != bgr.rows) {
            tex_ = gl::Texture::create2D("wizard image", bgr.cols, bgr.rows, GL_RGBA8);
            tex_.setFilter(GL_LINEAR, GL_LINEAR);
        }
        cv::cvtColor(bgr, rgba_, cv::COLOR_BGR2RGBA);
        tex_.upload(GL_RGBA, GL_UNSIGNED_BYTE, rgba_.data);
    }
    ImTextureID id() const {
        return reinterpret_cast<ImTextureID>(static_cast<uintptr_t>(tex_.id()));
    }
    bool empty() const { return tex_.id() == 0; }

private:
    gl::Texture tex_;
    cv::Mat rgba_;
};

cv::Scalar decisionColour(calib::CaptureDecision d) {
    using D = calib::CaptureDecision;
    switch (d) {
        case D::Captured:
        case D::Held:
            return {80, 220, 80};
        case D::Blurred:
            return {60, 60, 230};
        case D::Similar:
            return {220, 160, 60};
        default:
            return {40, 220, 240};
    }
}

// The camera frame with the overlay: coverage tint per cell, the region to fill next, and the
// detected corners coloured by the capture decision.
cv::Mat overlay(const cv::Mat& frame, const calib::CalibrationSession& s,
                const calib::FrameReport& rep) {
    cv::Mat img = frame.channels() == 3 ? frame.clone() : cv::Mat();
    if (img.empty()) cv::cvtColor(frame, img, cv::COLOR_GRAY2BGR);
    const auto& cov = s.coverage();
    cv::Mat tint = img.clone();
    const double cw = double(img.cols) / cov.cols(), ch = double(img.rows) / cov.rows();
    for (int r = 0; r < cov.rows(); ++r)
        for (int c = 0; c < cov.cols(); ++c)
            if (cov.count(c, r) > 0)
                cv::rectangle(tint, cv::Rect(int(c * cw), int(r * ch), int(cw) + 1, int(ch) + 1),
                              {60, 200, 60}, cv::FILLED);
    cv::addWeighted(tint, 0.25, img, 0.75, 0, img);
    if (s.state() != calib::CalibrationSession::State::Done && !s.views().empty()) {
        std::string name;
        const cv::Point2f centre = cov.emptiestRegion(name);
        const cv::Size2f half(float(1.5 * cw), float(1.5 * ch));
        cv::rectangle(img,
                      cv::Rect(cv::Point(int(centre.x - half.width), int(centre.y - half.height)),
                               cv::Size(int(2 * half.width), int(2 * half.height))),
                      {0, 200, 255}, 2);
    }
    if (rep.boardFound) {
        const auto colour = decisionColour(rep.decision);
        const auto& pts = rep.view.imagePoints;
        for (size_t i = 0; i + 1 < pts.size(); ++i)
            cv::line(img, pts[i], pts[i + 1], colour * 0.6, 1, cv::LINE_AA);
        for (const auto& p : pts) cv::circle(img, p, 3, colour, 2, cv::LINE_AA);
        if (rep.decision == calib::CaptureDecision::Captured)
            cv::rectangle(img, cv::Rect(0, 0, img.cols, img.rows), {255, 255, 255}, 8);
    }
    return img;
}

void drawCoverage(const calib::CalibrationSession& s, ImVec2 size) {
    const auto& cov = s.coverage();
    ImDrawList* dl = ImGui::GetWindowDrawList();
    const ImVec2 p0 = ImGui::GetCursorScreenPos();
    const float cw = size.x / float(cov.cols()), ch = size.y / float(cov.rows());
    int maxCount = 1;
    for (int r = 0; r < cov.rows(); ++r)
        for (int c = 0; c < cov.cols(); ++c) maxCount = std::max(maxCount, cov.count(c, r));
    for (int r = 0; r < cov.rows(); ++r)
        for (int c = 0; c < cov.cols(); ++c) {
            const int n = cov.count(c, r);
            const float t = n == 0 ? 0.f : 0.3f + 0.7f * float(n) / float(maxCount);
            const ImU32 col = n == 0 ? IM_COL32(90, 30, 30, 255)
                                     : IM_COL32(int(40 * (1 - t)), int(80 + 170 * t), 60, 255);
            const ImVec2 a(p0.x + c * cw + 1, p0.y + r * ch + 1), b(a.x + cw - 2, a.y + ch - 2);
            dl->AddRectFilled(a, b, col);
        }
    ImGui::Dummy(size);
}

void saveCalibrationFile(const WizardOptions& o, const calib::CalibrationSession& s,
                         std::string& status, int& exitCode) {
    if (!s.result()) {
        status = "nothing to save yet";
        return;
    }
    const auto cal = calib::calibrationForFile(*s.result());
    // Through core/OutputFile.h like every output: never over an input or a special file.
    OutputFile out(o.output, OutputOrigin::Named,
                   OutputRule{{o.inputs.begin(), o.inputs.end()}, true, "mirage calibrate"});
    saveCalibration(out.temp(), cal);
    out.commit();
    status = cal.reliable ? "saved " + o.output
                          : "saved " + o.output + " marked UNRELIABLE: " + cal.unreliableReason;
    exitCode = cal.reliable ? 0 : 2;
    spdlog::info("{}", status);
}

// The wizard: its input, the calibration session deciding on every frame, and the window.
class CalibrationWizard {
public:
    CalibrationWizard(const WizardOptions& options, WizardInput& input, cv::Mat first,
                      std::string firstName, const calib::SessionOptions& sessionOptions);
    int run();

private:
    void processFrame();  // the calibration session's decision on the current frame
    void advance();       // the next frame, unless paused, at the end or about to screenshot
    void drawCameraPanel();
    void drawPreviewPanel();
    void drawCoveragePanel();
    void drawCalibrationPanel();
    void drawParameters();
    void drawViews();

    const WizardOptions& o_;
    WizardInput& input_;
    calib::SessionOptions sessionOptions_;
    calib::CalibrationSession session_;
    cv::Mat current_;
    std::string frameName_;
    gl::Context ctx_;
    ImGuiScope imgui_;
    ImageTexture camTex_, undistTex_;
    calib::Undistorter undistorter_;
    calib::FrameReport rep_;
    bool haveFrame_ = true, endOfInput_ = false, paused_ = false, showUndistorted_ = true;
    int framesProcessed_ = 0, exitCode_ = 0, screenshotCountdown_ = -1;
    std::string status_;
};

gl::Context wizardWindow() {
    gl::ContextOptions co;
    co.width = 1280;
    co.height = 800;
    co.title = "mirage calibrate";
    return gl::Context::window(co);
}

CalibrationWizard::CalibrationWizard(const WizardOptions& options, WizardInput& input,
                                     cv::Mat first, std::string firstName,
                                     const calib::SessionOptions& sessionOptions)
    : o_(options),
      input_(input),
      sessionOptions_(sessionOptions),
      session_(calib::CalibrationTarget::parse(options.board), first.size(), sessionOptions),
      current_(std::move(first)),
      frameName_(std::move(firstName)),
      ctx_(wizardWindow()),
      imgui_(ctx_.glfwWindow()),
      status_("source: " + input.description()) {}

void CalibrationWizard::processFrame() {
    if (!haveFrame_) return;
    rep_ = session_.processFrame(current_, frameName_);
    ++framesProcessed_;
    camTex_.show(overlay(current_, session_, rep_));
    if (session_.result() && showUndistorted_)
        undistTex_.show(undistorter_.apply(current_, session_.result()->calibration.intrinsics, 0.5,
                                           session_.result()->calibration.reachDeg));
    haveFrame_ = false;
}

void CalibrationWizard::advance() {
    const bool screenshotDue =
        !o_.screenshot.empty() &&
        ((o_.screenshotAfterFrames > 0 && framesProcessed_ >= o_.screenshotAfterFrames) ||
         endOfInput_);
    if (!paused_ && !endOfInput_ && !screenshotDue) {
        if (input_.next(current_, frameName_)) {
            haveFrame_ = true;
        } else {
            endOfInput_ = true;
            status_ = "end of input: " + std::to_string(framesProcessed_) + " frames";
        }
    }
    if (screenshotDue && screenshotCountdown_ < 0) screenshotCountdown_ = 2;  // let ImGui lay out
}

constexpr ImGuiWindowFlags kFixed =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse;

void CalibrationWizard::drawCameraPanel() {
    ImGui::SetNextWindowPos({0, 0});
    ImGui::SetNextWindowSize({660, 540});
    ImGui::Begin("Camera", nullptr, kFixed);
    if (!camTex_.empty()) {
        const float scale = std::min(640.f / float(current_.cols), 480.f / float(current_.rows));
        ImGui::Image(camTex_.id(), {float(current_.cols) * scale, float(current_.rows) * scale});
    }
    ImGui::Text("%s | %s | motion %.2f px | sharpness %.0f | tilt %.0f deg", frameName_.c_str(),
                calib::captureDecisionName(rep_.decision), rep_.motionPx, rep_.sharpness,
                rep_.tiltDeg);
    ImGui::End();
}

void CalibrationWizard::drawPreviewPanel() {
    ImGui::SetNextWindowPos({0, 540});
    ImGui::SetNextWindowSize({330, 260});
    ImGui::Begin("Undistorted preview", nullptr, kFixed);
    ImGui::Checkbox("show", &showUndistorted_);
    if (session_.result() && showUndistorted_ && !undistTex_.empty())
        ImGui::Image(undistTex_.id(), {270, 270.f * float(current_.rows) / float(current_.cols)});
    else
        ImGui::TextWrapped("Appears after the first calibration (%d views).",
                           sessionOptions_.calibration.minViews);
    ImGui::End();
}

void CalibrationWizard::drawCoveragePanel() {
    ImGui::SetNextWindowPos({330, 540});
    ImGui::SetNextWindowSize({330, 260});
    ImGui::Begin("Coverage and tilts", nullptr, kFixed);
    drawCoverage(session_, {300, 130});
    const auto& cov = session_.coverage();
    if (cov.angular()) {
        // Fish-eye: corners per ring of angle off-axis (the fraction is over rings x sectors).
        ImGui::Text("off-axis bins covered: %.0f%%", 100 * cov.coveredFraction());
        std::string rings;
        for (int r = 0; r < cov.reachableRings(); ++r) {
            const int lo = int(calib::CoverageMap::kRingStepDeg * r);
            const int hi = int(calib::CoverageMap::kRingStepDeg * (r + 1));
            rings +=
                fmt::format("{}{}: {}", r ? ", " : "",
                            r + 1 < calib::CoverageMap::kRingCount ? fmt::format("{}-{}", lo, hi)
                                                                   : fmt::format("{}+", lo),
                            cov.ringCount(r));
        }
        ImGui::TextWrapped("deg off-axis %s", rings.c_str());
    } else {
        ImGui::Text("cells covered: %.0f%%", 100 * cov.coveredFraction());
    }
    const auto& tilts = session_.tilts();
    for (int b = 0; b < calib::TiltCoverage::BinCount; ++b) {
        const auto bin = calib::TiltCoverage::Bin(b);
        ImGui::TextColored(tilts.count(bin) ? ImVec4(0.5f, 1, 0.5f, 1) : ImVec4(1, 0.5f, 0.4f, 1),
                           "%-16s %d", calib::TiltCoverage::binName(bin), tilts.count(bin));
        if (b % 2 == 0 && b + 1 < calib::TiltCoverage::BinCount) ImGui::SameLine(160);
    }
    ImGui::Text("largest tilt: %.0f deg", tilts.maxTiltDeg());
    ImGui::End();
}

void CalibrationWizard::drawParameters() {
    const auto& r = session_.result();
    if (!r) {
        if (!session_.calibrationError().empty())
            ImGui::TextWrapped("calibration failed: %s", session_.calibrationError().c_str());
        return;
    }
    const auto& c = r->calibration;
    const auto& in = c.intrinsics;
    ImGui::Text("RMS reprojection error: %.3f px   views used: %d", c.avgReprojectionError,
                r->usedViewCount());
    if (!c.reliable) {
        ImGui::PushTextWrapPos(0);
        ImGui::TextColored({1, 0.4f, 0.4f, 1}, "UNRELIABLE: %s", c.unreliableReason.c_str());
        ImGui::PopTextWrapPos();
    }
    if (!ImGui::BeginTable("params", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) return;
    ImGui::TableSetupColumn("parameter");
    ImGui::TableSetupColumn("value");
    ImGui::TableSetupColumn("std dev (1 sigma)");
    ImGui::TableHeadersRow();
    for (size_t i = 0; i < r->parameterNames.size(); ++i) {
        const double v = i == 0   ? in.fx
                         : i == 1 ? in.fy
                         : i == 2 ? in.cx
                         : i == 3 ? in.cy
                                  : in.coeff(i - 4);
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(r->parameterNames[i].c_str());
        ImGui::TableNextColumn();
        ImGui::Text("%.5f", v);
        ImGui::TableNextColumn();
        ImGui::Text("%.5f", i < c.stdDeviations.size() ? c.stdDeviations[i] : -1.0);
    }
    ImGui::EndTable();
}

void CalibrationWizard::drawViews() {
    ImGui::Text("Views (RMS px, tilt deg):");
    ImGui::BeginChild("views", {0, 0}, true);
    std::optional<size_t> drop;
    for (size_t i = 0; i < session_.views().size(); ++i) {
        const auto& r = session_.result();
        const bool rejected = r && r->views[i].rejected;
        ImGui::PushID(int(i));
        if (ImGui::SmallButton("drop")) drop = i;
        ImGui::SameLine();
        if (rejected)
            ImGui::TextColored({1, 0.4f, 0.4f, 1}, "%-22s OUTLIER: %s",
                               session_.views()[i].name.c_str(), r->views[i].rejectReason.c_str());
        else if (r)
            ImGui::Text("%-22s %.3f  %4.0f", session_.views()[i].name.c_str(), r->views[i].rmsPx,
                        r->views[i].tiltDeg);
        else
            ImGui::Text("%-22s", session_.views()[i].name.c_str());
        ImGui::PopID();
    }
    ImGui::EndChild();
    if (drop) session_.dropView(*drop);
}

void CalibrationWizard::drawCalibrationPanel() {
    ImGui::SetNextWindowPos({660, 0});
    ImGui::SetNextWindowSize({620, 800});
    ImGui::Begin("Calibration", nullptr, kFixed);
    const bool done = session_.state() == calib::CalibrationSession::State::Done;
    ImGui::TextColored(done ? ImVec4(0.4f, 1, 0.4f, 1) : ImVec4(1, 0.85f, 0.3f, 1), "%s",
                       done ? "DONE" : "COLLECTING");
    ImGui::SameLine();
    ImGui::Text("| %s | %s model | %zu views", session_.target().description().c_str(),
                o_.model == DistortionModel::KannalaBrandt ? "fisheye" : "pinhole",
                session_.views().size());
    ImGui::Separator();
    ImGui::PushTextWrapPos(0);
    ImGui::TextColored({0.6f, 0.85f, 1, 1}, "Next: %s", session_.advice().c_str());
    ImGui::PopTextWrapPos();
    ImGui::Separator();
    if (ImGui::Button(paused_ ? "Resume" : "Pause")) paused_ = !paused_;
    ImGui::SameLine();
    if (ImGui::Button("Capture now") && rep_.boardFound) session_.addView(rep_.view);
    ImGui::SameLine();
    ImGui::BeginDisabled(o_.output.empty() || !session_.result());
    if (ImGui::Button("Save")) {
        try {
            saveCalibrationFile(o_, session_, status_, exitCode_);
        } catch (const Error& e) {
            status_ = e.what();
        }
    }
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::TextWrapped("%s", o_.output.empty() ? "(-o not given)" : o_.output.c_str());
    ImGui::TextWrapped("%s", status_.c_str());
    ImGui::Separator();
    drawParameters();
    const auto unmet = session_.unmetTargets();
    if (!unmet.empty()) {
        ImGui::Text("Not done yet:");
        for (const auto& u : unmet) ImGui::BulletText("%s", u.c_str());
    }
    ImGui::Separator();
    drawViews();
    ImGui::End();
}

int CalibrationWizard::run() {
    while (!ctx_.shouldClose()) {
        ctx_.pollEvents();
        processFrame();
        advance();
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        drawCameraPanel();
        drawPreviewPanel();
        drawCoveragePanel();
        drawCalibrationPanel();
        ImGui::Render();
        int fw = 0, fh = 0;
        glfwGetFramebufferSize(ctx_.glfwWindow(), &fw, &fh);
        glViewport(0, 0, fw, fh);
        glClearColor(0.1f, 0.1f, 0.12f, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        if (screenshotCountdown_ >= 0 && screenshotCountdown_-- == 0) {
            saveWindowPng(o_.screenshot, ctx_.glfwWindow());
            break;
        }
        ctx_.swapBuffers();
    }
    return exitCode_;
}

}  // namespace

WizardInput::WizardInput(const WizardOptions& o) {
    if (!o.inputs.empty()) {
        FrameListOptions so;
        so.allVideoFrames = true;  // stillness is measured between consecutive video frames
        source_ = openFrameList(o.inputs, so);
        stillImages_ = std::none_of(o.inputs.begin(), o.inputs.end(),
                                    [](const std::string& i) { return isVideoFile(i); });
        description_ = o.inputs.front();
    } else if (!o.cameraDevice.empty()) {
        source_ = std::make_unique<V4l2Camera>(o.cameraDevice, CaptureRequest{});
        description_ = o.cameraDevice;
    } else {
        throw Error(
            "the wizard needs a source: INPUT... (images, a folder or a video) or "
            "--camera /dev/videoN; for headless use, --batch");
    }
}

bool WizardInput::next(cv::Mat& bgr, std::string& name) {
    while (source_->read(bgr)) {
        const int i = index_++;
        name = source_->lastName();
        if (name.empty()) name = fmt::format("frame {}", i);
        if (!bgr.empty()) return true;
        spdlog::warn("{}: frame lost ({}), skipped", name, source_->lastProblem());
    }
    return false;
}

int runCalibrationWizard(const WizardOptions& o) {
    if (o.board.empty())
        throw Error("--board is required (a board file or chessboard:COLSxROWS:SQUARE_METRES)");
    WizardInput input(o);
    calib::CalibrationTarget::parse(o.board);  // a bad board is refused before the window opens
    cv::Mat first;
    std::string firstName;
    if (!input.next(first, firstName)) throw Error("the input holds no frames");
    calib::SessionOptions so;
    so.calibration.model = o.model;
    so.calibration.fixK3 = o.fixK3;
    // Separate photos are each a deliberate, still capture: no stillness over frames needed.
    if (input.stillImages()) so.stillFrames = 0;
    CalibrationWizard wizard(o, input, std::move(first), std::move(firstName), so);
    return wizard.run();
}

}  // namespace mirage::app
