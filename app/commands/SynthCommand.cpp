// `mirage synth SCENE -o SESSION`: synthetic footage with exact ground truth, rendered by the
// reference renderer from the scene's REAL parts only (what a real camera would film), along a
// camera path (orbit, hand-held shake, fast pan), with optional sensor effects, plus the fish-eye
// environment camera. Writes the session format of docs/session.md (docs/reference-renderer.md).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/ShardOptions.h"
#include "app/commands/TerminalProgress.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/Shards.h"
#include "core/scene/Scene.h"
#include "render/raytrace/SyntheticFootage.h"
#include "render/raytrace/SyntheticSession.h"
#include "tracking/Board.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;

struct SynthArgs {
    std::string scene, output, board, shard, frames;
    bool force = false, noEnv = false;
    std::vector<double> envWhiteBalance;    // --env-white-balance R,G,B (empty: 1,1,1)
    std::vector<double> whiteBalanceDrift;  // --white-balance-drift R,G,B (empty: none)
    double panFraction = -1.0;              // --pan-fraction (negative: the path's default)
    raytrace::SyntheticSessionOptions o;
};

// A part of the session (core/Shards.h): its frames into OUT.shards/I-of-N, written to a
// temporary folder and moved into place when complete, like the session itself.
void writeShard(const SynthArgs& a, const Scene& scene, const ShardSpec& shard,
                const ItemRange& range, int total, const std::vector<int>& frames) {
    const fs::path out(a.output);
    const fs::path dir = shardFolder(out, shard);
    if (fs::exists(dir / "shard.json") && !a.force)
        throw FileError(dir.string(),
                        "this shard is already complete; pass --force to render it again");
    if (frames.empty())
        throw Error(
            fmt::format("mirage synth: shard {}/{} of frames {}:{} holds no frame; use at "
                        "most as many shards as frames",
                        shard.index, shard.count, range.begin, range.end < 0 ? total : range.end));
    StagedPath staged(dir);
    const fs::path& temp = staged.temp();

    TerminalProgress bar("synth");
    const auto start = std::chrono::steady_clock::now();
    ShardManifest m;
    m.command = "synth";
    m.unit = "frames";
    m.shard = shard;
    m.total = total;
    m.range = range;
    m.items = frames;
    m.fingerprint = raytrace::syntheticFingerprint(a.o, fileFingerprint(a.scene),
                                                   fileFingerprint(a.o.boardFile));
    m.commandLine = commandLine();
    m.payload = raytrace::writeSyntheticShard(
        scene, temp, a.o, frames, [&](int done, int count, const std::string& segment) {
            const double elapsed =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            bar.update(done, count,
                       fmt::format("shard {}/{}: frame {}/{} ({}), {:.0f} s", shard.index,
                                   shard.count, done, count, segment, elapsed));
        });
    bar.finish();
    writeShardManifest(temp, m);
    staged.commit();  // replaces an earlier attempt (--force, checked above)
    spdlog::info("wrote shard {}/{} ({} frames) to {}; when every shard is done: mirage merge {}",
                 shard.index, shard.count, frames.size(), dir.string(), out.string());
}

void run(SynthArgs a) {
    const fs::path out(a.output);
    const double frames = a.o.fps * a.o.seconds;
    if (!(frames >= 1 && frames <= 1e6))
        throw Error(
            fmt::format("mirage synth: --fps {} x --seconds {} gives {} frames; the "
                        "footage must have 1 to 1000000 frames",
                        a.o.fps, a.o.seconds, frames));
    OutputRule rule{{a.scene}, a.force, "mirage synth"};
    if (!a.board.empty()) rule.inputs.push_back(a.board);
    checkOutput(out, OutputOrigin::Named, rule, /*outIsFolder=*/true);
    std::error_code ec;
    if (fs::exists(out / "session.json")) {
        if (!a.force)
            throw FileError(
                out.string(),
                "already holds a session; choose another folder or pass --force to replace it");
    } else if (fs::exists(out) && !fs::is_empty(out, ec) && !a.force) {
        throw FileError(out.string(),
                        "exists and is not empty; choose another folder or pass --force to "
                        "replace it");
    }
    checkLooksLikeGltf(a.scene);
    Scene scene = loadScene(a.scene);
    fs::path boardPath =
        a.board.empty() ? fs::path(a.scene).parent_path() / "board.json" : fs::path(a.board);
    if (!fs::exists(boardPath))
        throw FileError(
            boardPath.string(),
            "board file not found; pass --board BOARD.json (the board the scene shows)");
    tracking::Board::load(boardPath);  // validates it before hours of rendering
    a.o.boardFile = boardPath;
    a.o.environmentCamera = !a.noEnv;
    if (!a.envWhiteBalance.empty()) {
        for (double g : a.envWhiteBalance)
            if (!(std::isfinite(g) && g > 0 && g < 1e6))
                throw Error("mirage synth: --env-white-balance gains must be positive numbers");
        a.o.envWhiteBalance = glm::vec3(float(a.envWhiteBalance[0]), float(a.envWhiteBalance[1]),
                                        float(a.envWhiteBalance[2]));
    }
    if (a.o.sensor.responseGamma != 0.0 && a.o.sensor.responseGamma < 1.0)
        throw Error(
            fmt::format("mirage synth: --response-gamma {} is neither 0 (sRGB) nor in "
                        "[1, 4]",
                        a.o.sensor.responseGamma));
    if (!a.whiteBalanceDrift.empty())
        a.o.sensor.whiteBalanceDrift =
            glm::dvec3(a.whiteBalanceDrift[0], a.whiteBalanceDrift[1], a.whiteBalanceDrift[2]);
    if (a.panFraction >= 0) {
        // The orbit and the hand-held hold share the rest in their default proportion (5 : 3).
        const double rest = 1.0 - a.panFraction;
        a.o.path.orbitFraction = rest * 0.625;
        a.o.path.shakeFraction = rest * 0.375;
    }
    // The scene's path as given (made absolute): ground_truth.json names it for `mirage bench`.
    a.o.sceneName = fs::absolute(a.scene).lexically_normal().string();

    const ShardSpec shard = a.shard.empty() ? ShardSpec{} : parseShardSpec(a.shard);
    const ItemRange range = a.frames.empty() ? ItemRange{} : parseItemRange(a.frames);
    const int total = raytrace::syntheticFrameCount(a.o);
    const std::vector<int> selected = selectItems(total, range, shard, "--frames", "frames");
    if (!shard.whole() || int(selected.size()) != total) {
        writeShard(a, scene, shard, range, total, selected);
        return;
    }

    // The session is written into a temporary folder beside OUT and moved into place when
    // complete: a failed or interrupted synth leaves no half-written session at OUT.
    StagedPath staged(out);
    const fs::path& temp = staged.temp();

    TerminalProgress bar("synth");
    const auto start = std::chrono::steady_clock::now();
    raytrace::writeSyntheticSession(
        scene, temp, a.o, [&](int done, int total, const std::string& segment) {
            const double elapsed =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            bar.update(done, total,
                       fmt::format("frame {}/{} ({}), {:.0f} s", done, total, segment, elapsed));
        });
    bar.finish();
    staged.commit();  // replaces a session (--force, checked above) or an empty folder
}

const CommandRegistrar reg("synth", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand("synth",
                                      "Render a synthetic session (real parts of a scene, exact "
                                      "ground-truth poses) with the reference renderer");
    auto a = std::make_shared<SynthArgs>();
    cmd->add_option("scene", a->scene, "Scene (.gltf/.glb) with REAL nodes, a board plane, lights")
        ->required();
    cmd->add_option("-o,--output", a->output, "Session folder to create")
        ->required()
        ->check(outputPath(OutputShape::Folder));
    cmd->add_option("--board", a->board,
                    "Board file the scene shows (default: board.json beside the scene)");
    cmd->add_option("--width", a->o.width, "Main camera width (pixels)")
        ->capture_default_str()
        ->check(wholeIn(1, 16384));
    cmd->add_option("--height", a->o.height, "Main camera height (pixels)")
        ->capture_default_str()
        ->check(wholeIn(1, 16384));
    cmd->add_option("--hfov", a->o.hfovDeg, "Main camera horizontal field of view (degrees)")
        ->capture_default_str()
        ->check(finiteIn(raytrace::kPinholeHfovDeg));
    cmd->add_option("--fps", a->o.fps, "Frame rate")
        ->capture_default_str()
        ->check(finiteIn(0, 1000, true));
    cmd->add_option("--seconds", a->o.seconds, "Length of the footage")
        ->capture_default_str()
        ->check(finiteIn(0, 86400, true));
    cmd->add_option("--spp", a->o.samplesPerPixel, "Samples per pixel per frame")
        ->capture_default_str()
        ->check(wholeIn(1, 1 << 20));
    cmd->add_option("--seed", a->o.seed, "Random seed (render noise, sensor noise, shake)")
        ->capture_default_str()
        ->check(wholeIn(0, kMaxSeed));
    cmd->add_option("--threads", a->o.threads, "Worker threads (0 = all cores)")
        ->capture_default_str()
        ->check(wholeIn(0, 4096));
    cmd->add_option("--orbit-radius", a->o.path.radius, "Orbit radius (metres)")
        ->capture_default_str()
        ->check(finiteIn(0, 1e3, true));
    cmd->add_option("--orbit-height", a->o.path.height, "Camera height above the target (metres)")
        ->capture_default_str()
        ->check(finiteIn(-1e3, 1e3));
    cmd->add_option("--pan-deg", a->o.path.panDeg, "Yaw of the final fast pan (degrees)")
        ->capture_default_str()
        ->check(finiteIn(-3600, 3600));
    cmd->add_option("--pan-fraction", a->panFraction,
                    "Share of the footage the final fast pan takes (0..1; default 0.2; 1: the "
                    "whole clip is the pan, for strong motion blur with --shutter)")
        ->check(finiteIn(0, 1));
    cmd->add_option("--shake-mm", a->o.path.shakeTranslation, "Hand-held shake amplitude (metres)")
        ->capture_default_str()
        ->check(finiteIn(0, 1));
    cmd->add_option("--exposure", a->o.sensor.exposure, "Exposure (multiplies linear radiance)")
        ->capture_default_str()
        ->check(finiteIn(0, 1e6, true));
    cmd->add_flag("--exposure-change", a->o.sensor.exposureChange,
                  "Auto-exposure step (x0.55) at 60 % of the footage");
    cmd->add_option("--exposure-step", a->o.sensor.exposureStep,
                    "Sudden exposure step: the exposure is multiplied by this from 50 % of the "
                    "footage on, between two frames (1 = none)")
        ->capture_default_str()
        ->check(finiteIn(0, 1e3, true));
    cmd->add_option("--white-balance-drift", a->whiteBalanceDrift,
                    "Main camera's white balance drifts linearly from 1,1,1 at the first frame "
                    "to these gains R,G,B at the last")
        ->delimiter(',')
        ->expected(3)
        ->check(finiteIn(NumberRange{0, 1e3, true, true}));
    cmd->add_option("--response-gamma", a->o.sensor.responseGamma,
                    "Main camera's response: 0 = sRGB; G in [1, 4] = codes of value^(1/G) "
                    "(written to main.yaml as its `response`)")
        ->capture_default_str()
        ->check(finiteIn(0, 4));
    cmd->add_option("--vignette", a->o.sensor.vignette, "Corner darkening (0 = none)")
        ->capture_default_str()
        ->check(finiteIn(0, 1));
    cmd->add_option("--noise", a->o.sensor.noise,
                    "Sensor noise (Poisson-Gaussian, linear units; 0 = none)")
        ->capture_default_str()
        ->check(finiteIn(0, 1));
    cmd->add_option("--shutter", a->o.shutter,
                    "Motion blur: shutter open time as a fraction of the frame interval")
        ->capture_default_str()
        ->check(finiteIn(0, 1));
    cmd->add_option("--blur-subframes", a->o.blurSubframes,
                    "Sub-frame renders averaged for motion blur")
        ->capture_default_str()
        ->check(wholeIn(1, 256));
    cmd->add_option("--env-size", a->o.envSize,
                    "Fish-eye environment camera image size (square, pixels)")
        ->capture_default_str()
        ->check(wholeIn(16, 8192));
    cmd->add_option("--env-fov", a->o.envFovDeg, "Fish-eye field of view (degrees)")
        ->capture_default_str()
        ->check(finiteIn(raytrace::kFisheyeFovDeg));
    cmd->add_option("--env-exposure", a->o.envExposure,
                    "Environment camera's exposure (multiplies the linear radiance it films)")
        ->capture_default_str()
        ->check(finiteIn(0, 1e6, true));
    cmd->add_option("--env-white-balance", a->envWhiteBalance,
                    "Environment camera's white balance: gains R,G,B on the radiance it films")
        ->delimiter(',')
        ->expected(3)
        ->check(finiteIn(NumberRange{0, 1e6, true, true}));
    cmd->add_option("--env-rotation", a->o.envRotationDegPerSecond,
                    "The room light moves: the scene's environment turns about +Y at this rate "
                    "(degrees per second; footage, environment camera and ground truth follow)")
        ->capture_default_str()
        ->check(finiteIn(-36000, 36000));
    cmd->add_flag("--no-env", a->noEnv, "Do not render the environment camera");
    cmd->add_flag("--image-sequence", a->o.imageSequence, "PNG folders instead of MKV videos");
    cmd->add_flag("--ground-truth-composite", a->o.groundTruthComposite,
                  "Also write each frame's ground-truth composite (real + virtual, same sensor) "
                  "and the mask of pixels the virtual objects influence (docs/session.md)");
    cmd->add_option("--influence-threshold", a->o.influenceThreshold,
                    "Linear change (camera units) that marks a pixel as influenced")
        ->capture_default_str()
        ->check(finiteIn(0, 1e6));
    cmd->add_option("--shard", a->shard,
                    "Render part I of N (I/N, 0-based: every N-th frame from frame I) into "
                    "OUT.shards/; join the parts with `mirage merge OUT` (docs/scale.md)")
        ->check(shardSpecCheck());
    cmd->add_option("--frames", a->frames,
                    "Render only frames A to B-1 (A:B), as a shard; with --shard, the part of "
                    "that range")
        ->check(itemRangeCheck("--frames"));
    cmd->add_flag("--force", a->force,
                  "Replace an existing session in the output folder (or an existing shard)");
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
