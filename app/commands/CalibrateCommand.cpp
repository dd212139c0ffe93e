// `mirage calibrate`: camera calibration (docs/calibration.md).
//   mirage calibrate --batch INPUT... --board BOARD -o CAM.yaml [--model pinhole|fisheye]
//   mirage calibrate [--source INPUT... | --camera /dev/videoN] --board BOARD -o CAM.yaml  (wizard)
//   mirage calibrate --write-synthetic DIR [--model ...]   (a test set with known intrinsics)
// Exit codes: 0 = reliable calibration written; 2 = written but marked `reliable: false` (the
// reason is in the file and the report); 1 = error, no file written.
#include <fstream>
#include <optional>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "app/Command.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/wizard/CalibrationWizard.h"
#include "calibration/BatchCalibration.h"
#include "calibration/Extrinsics.h"
#include "calibration/SyntheticViews.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/camera/CalibrationFile.h"
#include "core/capture/CameraCatalog.h"
#include "core/capture/V4l2Device.h"

namespace mirage::app {
namespace {

struct CalibrateArgs {
    bool force = false;
    bool batch = false;
    std::vector<std::string> inputs;
    std::string board;
    std::string output;
    std::string model = "pinhole";
    std::string ros;
    std::string rosName = "camera";
    std::string report;
    bool fixK3 = false;
    int videoStep = 0;
    // Extrinsics.
    std::string mainCalib;
    std::vector<std::string> mainInputs;
    std::string worldImage;
    // Wizard.
    std::string camera;
    std::string screenshot;
    int screenshotAfterFrames = 0;
    // Synthetic set.
    std::string writeSynthetic;
    int syntheticViews = 14;
};

DistortionModel modelOf(const std::string& name) {
    if (name == "pinhole") return DistortionModel::BrownConrady;
    if (name == "fisheye") return DistortionModel::KannalaBrandt;
    throw Error("--model '" + name + "': use pinhole or fisheye");
}

void writeText(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    closeChecked(out, path);
}

void runBatch(const CalibrateArgs& a) {
    if (a.board.empty())
        throw Error(
            "--board is required (a board file, chessboard:9x6:0.025 or charuco:5x7:0.04:0.02)");
    if (a.output.empty()) throw Error("-o CAM.yaml is required");
    const auto target = calib::CalibrationTarget::parse(a.board);
    // Outputs checked before the work (core/OutputFile.h): never an input, parent folders
    // created, the report beside the calibration never replaced without --force.
    OutputRule rule{{}, a.force, "mirage calibrate"};
    for (const auto& in : a.inputs) rule.inputs.push_back(in);
    for (const auto& in : a.mainInputs) rule.inputs.push_back(in);
    for (const std::string& in : {a.board, a.mainCalib, a.worldImage})
        if (!in.empty()) rule.inputs.push_back(in);
    OutputFile calOut(a.output, OutputOrigin::Named, rule);
    const std::string reportPath = a.report.empty() ? a.output + ".report.txt" : a.report;
    OutputFile reportOut(reportPath, a.report.empty() ? OutputOrigin::Derived : OutputOrigin::Named,
                         rule);
    std::optional<OutputFile> rosOut;
    if (!a.ros.empty()) rosOut.emplace(a.ros, OutputOrigin::Named, rule);
    calib::BatchOptions o;
    o.calibration.model = modelOf(a.model);
    o.calibration.fixK3 = a.fixK3;
    o.source.videoStep = a.videoStep;
    const auto result = calib::runBatchCalibration(a.inputs, target, o);
    CameraCalibration cal = calib::calibrationForFile(result.calibration);

    std::string extrinsicReport;
    if (!a.mainCalib.empty()) {
        if (a.mainInputs.empty())
            throw Error(
                "--main-calib needs --main-input: the main camera's frames taken at the "
                "same moments as INPUT (paired by order)");
        const auto mainCal = loadCalibration(a.mainCalib);
        if (!mainCal.reliable)
            spdlog::warn("{} is marked unreliable ({}); the extrinsics inherit its errors",
                         a.mainCalib, mainCal.unreliableReason);
        const auto ext = calib::extrinsicsFromPairedInputs(mainCal.intrinsics, a.mainInputs,
                                                           cal.intrinsics, a.inputs, target);
        cal.T_parent_camera = ext.T_main_camera;
        cal.extrinsicParent = "main";
        extrinsicReport = calib::formatExtrinsics(ext);
    } else if (!a.worldImage.empty()) {
        const auto ext = calib::poseFromWorldBoard(cal.intrinsics, a.worldImage, target);
        cal.T_parent_camera = ext.T_world_camera;
        cal.extrinsicParent = "world";
        extrinsicReport = fmt::format("pose relative to the world board from {}: RMS {:.3f} px\n",
                                      a.worldImage, ext.rmsPx);
    }

    const std::string report = calib::formatReport(result) + extrinsicReport;
    fmt::print("{}", report);
    saveCalibration(calOut.temp(), cal);
    writeText(reportOut.temp(), report);
    calOut.commit();
    reportOut.commit();
    spdlog::info("wrote {} and {}", a.output, reportPath);
    if (rosOut) {
        if (cal.reliable) {
            saveRosCameraInfo(rosOut->temp(), cal, a.rosName);
            rosOut->commit();
            spdlog::info("wrote ROS camera_info {}", a.ros);
        } else {
            spdlog::warn("not writing {}: ROS camera_info cannot carry 'reliable: false'", a.ros);
        }
    }
    if (!cal.reliable) {
        spdlog::warn("calibration is UNRELIABLE ({}); {} is marked reliable: false",
                     cal.unreliableReason, a.output);
        commandExitCode() = 2;
    }
}

// A folder of rendered board images with known intrinsics (truth.yaml), for trying the batch
// mode and the wizard without a camera, plus a short video of the board moving between poses.
void writeSynthetic(const CalibrateArgs& a) {
    namespace fs = std::filesystem;
    const auto model = modelOf(a.model);
    CameraIntrinsics cam;
    cam.width = 640;
    cam.height = 480;
    cam.model = model;
    if (model == DistortionModel::KannalaBrandt) {
        cam.fx = cam.fy = 230;
        cam.cx = 321;
        cam.cy = 238;
        cam.distortion = {0.02, -0.01, 0.004, -0.001};
    } else {
        cam.fx = 520;
        cam.fy = 518;
        cam.cx = 322.5;
        cam.cy = 238;
        cam.distortion = {-0.25, 0.08, 0.0008, -0.0006, -0.01};
    }
    const calib::ChessboardGeometry board{9, 6, 0.025};
    std::mt19937 rng(2024);
    calib::PoseSamplerOptions po;
    po.minDistance = model == DistortionModel::KannalaBrandt ? 0.18 : 0.3;
    po.maxDistance = model == DistortionModel::KannalaBrandt ? 0.35 : 0.55;
    po.marginPx = 12;
    // Checked and staged like every folder output (core/OutputFile.h): written under a temporary
    // name beside the folder and moved into place when complete; an existing set is replaced
    // only with --force, a folder holding other files never.
    const fs::path outDir(a.writeSynthetic);
    checkOutput(outDir, OutputOrigin::Named, OutputRule{{}, a.force, "mirage calibrate"}, true);
    std::error_code ec;
    if (fs::is_directory(outDir, ec) && !fs::is_empty(outDir, ec) &&
        !(a.force && fs::exists(outDir / "truth.yaml")))
        throw FileError(a.writeSynthetic,
                        fs::exists(outDir / "truth.yaml")
                            ? "already holds a synthetic set; pass --force to replace it"
                            : "exists and is not empty; choose a new folder");
    const auto poses = calib::sampleBoardPoses(cam, board, a.syntheticViews, po, rng);
    StagedPath staged(outDir);
    const fs::path dir = staged.temp();
    fs::create_directories(dir);
    const calib::ChessboardRenderer hiRes(cam, 3);
    for (size_t i = 0; i < poses.size(); ++i) {
        const cv::Mat img = hiRes.render(board, poses[i]);
        const auto path = dir / fmt::format("view_{:02}.png", i);
        if (!cv::imwrite(path.string(), img)) throw FileError(path.string(), "cannot write");
    }
    // A video of the board moving from pose to pose (motion-blurred while it moves), holding
    // still at each, with one pose first held out of focus: what the wizard's auto-capture sees.
    const calib::ChessboardRenderer renderer(cam, 2);
    const auto videoPath = (dir / "sequence.avi").string();
    cv::VideoWriter video(videoPath, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 15.0,
                          cv::Size(cam.width, cam.height), false);
    if (!video.isOpened()) throw FileError(videoPath, "cannot open for writing (MJPG/AVI)");
    auto emit = [&](const calib::BoardPose& pose, double blurSigma) {
        cv::Mat img = renderer.render(board, pose);
        if (blurSigma > 0) img = calib::blurInLinearLight(img, blurSigma);
        cv::Mat n(img.size(), CV_16S);
        cv::randn(n, 0, 1.5);  // sensor noise, 8-bit units
        img.convertTo(img, CV_16S);
        img += n;
        img.convertTo(img, CV_8U);
        video.write(img);
    };
    for (size_t i = 0; i < poses.size(); ++i) {
        if (i > 0)
            for (int k = 1; k <= 5; ++k) {
                const double t = k / 6.0;
                calib::BoardPose p;
                p.rvec = poses[i - 1].rvec * (1 - t) + poses[i].rvec * t;
                p.tvec = poses[i - 1].tvec * (1 - t) + poses[i].tvec * t;
                emit(p, 2.5);
            }
        if (i == 1)
            for (int k = 0; k < 5; ++k) emit(poses[i], 3.0);  // still but out of focus
        for (int k = 0; k < 6; ++k) emit(poses[i], 0.0);
    }
    CameraCalibration truth;
    truth.intrinsics = cam;
    video.release();
    saveCalibration(dir / "truth.yaml", truth);
    staged.commit();
    spdlog::info("wrote {} views of chessboard:9x6:0.025, sequence.avi and truth.yaml into {}",
                 poses.size(), a.writeSynthetic);
}

const CommandRegistrar reg("calibrate", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand(
        "calibrate", "Calibrate a camera (pinhole or fish-eye): the wizard, or --batch");
    auto a = std::make_shared<CalibrateArgs>();
    cmd->add_flag("--batch", a->batch, "Headless: calibrate from INPUT... and write -o");
    cmd->add_option("inputs", a->inputs, "Image files, folders of images, or videos");
    cmd->add_option("--board", a->board,
                    "Board file (JSON), chessboard:COLSxROWS:SQUARE_METRES (inner corners) or "
                    "charuco:SQUARESXxSQUARESY:SQUARE_M:MARKER_M[:DICT] (squares)");
    cmd->add_option("-o,--output", a->output,
                    "Calibration file to write (OpenCV YAML); with --camera the default is the "
                    "camera folder mirage live reads")
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--model", a->model, "pinhole (Brown-Conrady) or fisheye (Kannala-Brandt)")
        ->capture_default_str();
    cmd->add_option("--ros", a->ros, "Also export a ROS camera_info YAML here")
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--ros-name", a->rosName, "camera_name in the ROS export")
        ->capture_default_str();
    cmd->add_option("--report", a->report, "Report file (default: OUTPUT.report.txt)")
        ->check(outputPath(OutputShape::File));
    cmd->add_flag("--force", a->force,
                  "Replace an existing report beside the output (or an existing synthetic set)");
    cmd->add_flag("--fix-k3", a->fixK3, "Pinhole: keep k3 = 0 (narrow lenses)");
    cmd->add_option("--video-step", a->videoStep,
                    "Videos: use every Nth frame (default: about 120 frames per video)")
        ->check(wholeIn(1, 100000000));
    cmd->add_option("--main-calib", a->mainCalib,
                    "Extrinsics: the main camera's calibration; with --main-input gives this "
                    "camera's pose relative to the main camera");
    cmd->add_option("--main-input", a->mainInputs,
                    "Extrinsics: the main camera's frames, taken with INPUT's (paired by order)");
    cmd->add_option("--world-image", a->worldImage,
                    "Extrinsics: an image from this camera with the board at its world place; "
                    "gives the pose relative to the world");
    cmd->add_option(
        "--camera", a->camera,
        "Wizard: live V4L2 camera device (e.g. /dev/video0); without -o the calibration is "
        "saved where mirage live looks for this camera (docs/live.md)");
    cmd->add_option("--screenshot", a->screenshot,
                    "Wizard: save a PNG of the window after --screenshot-after frames, then exit")
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--screenshot-after", a->screenshotAfterFrames,
                    "Wizard: frames to process before the screenshot (default: all)")
        ->check(wholeIn(1, 100000000));
    cmd->add_option("--write-synthetic", a->writeSynthetic,
                    "Write rendered board views with known intrinsics (truth.yaml) to this folder")
        ->check(outputPath(OutputShape::Folder));
    cmd->add_option("--synthetic-views", a->syntheticViews,
                    "Views for --write-synthetic (a calibration needs at least 3)")
        ->capture_default_str()
        ->check(wholeIn(3, 1000));
    cmd->callback([a] {
        if (!a->writeSynthetic.empty()) return writeSynthetic(*a);
        if (a->batch) {
            if (a->inputs.empty())
                throw Error("--batch needs INPUT...: image files, a folder or a video");
            return runBatch(*a);
        }
        WizardOptions w;
        w.inputs = a->inputs;
        w.cameraDevice = a->camera;
        w.board = a->board;
        w.output = a->output;
        // A webcam calibrated without -o is saved where `mirage live` looks for that camera's
        // calibration (core/capture/CameraCatalog.h), and the board beside it if it has none.
        std::optional<CameraFiles> kept;
        if (w.output.empty() && !a->camera.empty() && a->writeSynthetic.empty()) {
            const std::string card = V4l2Device(a->camera).card();
            kept = cameraFiles(card);
            std::filesystem::create_directories(kept->calibration.parent_path());
            w.output = kept->calibration.string();
            spdlog::info("calibrate: camera '{}': saving to {} (where mirage live looks for it)",
                         card, w.output);
        }
        w.model = modelOf(a->model);
        w.fixK3 = a->fixK3;
        w.screenshot = a->screenshot;
        w.screenshotAfterFrames = a->screenshotAfterFrames;
        commandExitCode() = runCalibrationWizard(w);
        // (A board given as a file; a "chessboard:..." spec is not one live can track.)
        if (kept && std::filesystem::exists(kept->calibration) &&
            std::filesystem::is_regular_file(a->board) && !std::filesystem::exists(kept->board())) {
            std::filesystem::copy_file(a->board, kept->ownBoard);
            spdlog::info("calibrate: board copied to {} for mirage live", kept->ownBoard.string());
        }
    });
});

}  // namespace
}  // namespace mirage::app
