// `mirage render SCENE --camera NODE -o OUT`: reference images from the Embree renderer
// (docs/reference-renderer.md). OUT by extension: .exr/.pfm linear RGB float, .png tone-mapped
// (exposure x linear, then sRGB-encoded, clamped).
#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/ShardOptions.h"
#include "app/commands/ShardMerge.h"
#include "app/commands/TerminalProgress.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/Shards.h"
#include "core/image/ImageIO.h"
#include "core/scene/Scene.h"
#include "render/raytrace/DifferentialRendering.h"

namespace mirage::app {
namespace {

struct RenderArgs {
    std::string scene, camera, output, mode = "rv", cameraImage, shard, rows,
                                       scattering = "multiple";
    int spp = 64, width = 640, height = 0, threads = 0, photons = 0, maxDepth = 64;
    double seconds = 0.0;
    uint64_t seed = 1;
    float exposure = 1.0f;
    bool saveBuffers = false;
    bool force = false;
};

// --mode composite: L_r and L_rv rendered, composited into the camera image (the real-only
// render when none is given); --save-buffers writes L_r, L_rv and the coverage beside OUT (or
// hands them to the shard).
cv::Mat renderComposite(const RenderArgs& a, const Scene& scene, raytrace::EmbreeDevice& device,
                        const raytrace::RenderCamera& camera, const raytrace::RenderSettings& st,
                        const raytrace::ProgressCallback& progress, TerminalProgress& bar,
                        const cv::Mat& cameraImage, std::vector<OutputFile>& bufferFiles,
                        bool split, std::vector<cv::Mat>& shardBuffers) {
    raytrace::DifferentialImages images =
        raytrace::renderDifferential(scene, device, camera, st, progress);
    bar.finish();
    cv::Mat ci;
    if (a.cameraImage.empty()) {
        // Synthetic footage: the camera sees exactly the real-only render.
        ci = images.realOnly;
    } else {
        ci = cameraImage;
        if (ci.size() != images.realOnly.size())
            throw FileError(
                a.cameraImage,
                fmt::format("camera image is {}x{} but the render is {}x{}; pass "
                            "--width/--height matching it",
                            ci.cols, ci.rows, images.realOnly.cols, images.realOnly.rows));
    }
    const cv::Mat result = raytrace::compositeDifferential(ci, images);
    if (a.saveBuffers) {
        cv::Mat cov;
        cv::merge(std::vector<cv::Mat>(3, images.virtualCoverage), cov);
        if (split) {
            shardBuffers = {images.realOnly, images.realAndVirtual, cov};
        }
        const cv::Mat* buffers[] = {&images.realOnly, &images.realAndVirtual, &cov};
        for (size_t k = 0; k < bufferFiles.size(); ++k) {
            writeLinearRgb(bufferFiles[k].temp(), *buffers[k], 1.0f);
            bufferFiles[k].commit();
            spdlog::info("wrote {}", bufferFiles[k].path().string());
        }
    }
    spdlog::info("L_r: {} passes in {:.1f} s; L_rv: {} passes in {:.1f} s", images.realStats.passes,
                 images.realStats.seconds, images.mixedStats.passes, images.mixedStats.seconds);
    return result;
}

void run(const RenderArgs& a) {
    const std::filesystem::path out(a.output);
    std::string ext = out.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".exr" && ext != ".pfm" && ext != ".png")
        throw Error("mirage render: output '" + a.output +
                    "' must end in .exr or .pfm (linear) or .png (tone-mapped)");
    if (a.mode != "rv" && a.mode != "r" && a.mode != "composite")
        throw Error("mirage render: --mode must be rv, r or composite (got '" + a.mode + "')");
    if (a.spp < 1) throw Error("mirage render: --spp must be >= 1");
    if (a.seconds < 0) throw Error("mirage render: --seconds must be >= 0");
    if (a.width < 1 || a.height < 0)
        throw Error("mirage render: --width/--height must be positive");

    const ShardSpec shard = a.shard.empty() ? ShardSpec{} : parseShardSpec(a.shard);
    const ItemRange rowRange = a.rows.empty() ? ItemRange{} : parseItemRange(a.rows, "--rows");
    const bool split = !a.shard.empty() || !a.rows.empty();
    if (split && a.seconds > 0)
        throw Error(
            "mirage render: --shard/--rows need a fixed --spp: a time budget (--seconds) gives "
            "each shard a different number of passes, so the parts would not join");

    // Inputs and outputs are checked before the render, which can take hours: the output folder
    // is created and a temporary file reserved in it, the camera image is read now. A shard
    // writes into OUT.shards/ and leaves OUT to `mirage merge`.
    OutputRule rule{{a.scene}, a.force, "mirage render"};
    if (!a.cameraImage.empty()) rule.inputs.push_back(a.cameraImage);
    if (split) {
        checkOutput(out, OutputOrigin::Named, rule);
        const auto dir = shardFolder(out, shard);
        if (std::filesystem::exists(dir / "shard.json") && !a.force)
            throw FileError(dir.string(),
                            "this shard is already complete; pass --force to render it again");
    }
    std::optional<OutputFile> outFile;
    if (!split) outFile.emplace(out, OutputOrigin::Named, rule);
    std::vector<OutputFile> bufferFiles;
    if (a.saveBuffers && a.mode == "composite" && !split) {
        const auto stem = out.parent_path() / out.stem();
        for (const char* suffix : {"_Lr.exr", "_Lrv.exr", "_coverage.exr"})
            bufferFiles.emplace_back(stem.string() + suffix, OutputOrigin::Derived, rule);
    }
    cv::Mat cameraImage;
    if (!a.cameraImage.empty()) cameraImage = readLinearRgb(a.cameraImage);

    checkLooksLikeGltf(a.scene);
    Scene scene = loadScene(a.scene);
    int height = a.height;
    if (height == 0) {
        // Follow the camera's aspect ratio when the file gives one, else 4:3.
        int node = scene.findCameraNode(a.camera);
        float aspect = scene.cameras[size_t(scene.nodes[size_t(node)].camera)].aspectRatio;
        height = std::max(1, int(std::lround(a.width / (aspect > 0 ? aspect : 4.0f / 3.0f))));
    }
    raytrace::RenderCamera camera = raytrace::cameraFromNode(scene, a.camera, a.width, height);

    raytrace::RenderSettings st;
    if (split) st.rows = selectItems(height, rowRange, shard, "--rows", "image rows");
    if (split && st.rows.empty())
        throw Error(
            fmt::format("mirage render: shard {}/{} holds no row of the {} rows; use at "
                        "most as many shards as rows",
                        shard.index, shard.count, height));
    st.samplesPerPixel = a.seconds > 0 ? std::max(a.spp, 1 << 20) : a.spp;
    st.maxSeconds = a.seconds;
    st.seed = a.seed;
    st.threads = a.threads;
    st.photonsPerPass = a.photons;
    st.maxDepth = a.maxDepth;
    st.mediumScattering = a.scattering == "single" ? raytrace::MediumScattering::Single
                                                   : raytrace::MediumScattering::Multiple;
    raytrace::EmbreeDevice device(a.threads > 0 ? fmt::format("threads={}", a.threads) : "");

    TerminalProgress bar("render");
    auto progress = [&](int done, int total, double s) {
        if (a.seconds > 0)
            bar.update(s, a.seconds * (a.mode == "composite" ? 2 : 1),
                       fmt::format("{} passes, {:.1f} s", done, s));
        else
            bar.update(done, total, fmt::format("{}/{} passes, {:.1f} s", done, total, s));
    };
    spdlog::info("rendering '{}' camera '{}' at {}x{}, {}", a.scene, a.camera, a.width, height,
                 a.seconds > 0 ? fmt::format("{} s", a.seconds) : fmt::format("{} spp", a.spp));

    cv::Mat result;
    std::vector<cv::Mat> shardBuffers;  // L_r, L_rv, coverage of a split composite (--save-buffers)
    if (a.mode == "composite") {
        result = renderComposite(a, scene, device, camera, st, progress, bar, cameraImage,
                                 bufferFiles, split, shardBuffers);
    } else {
        raytrace::RayTracingScene rt(
            scene, a.mode == "r" ? raytrace::SceneSubset::RealOnly : raytrace::SceneSubset::All,
            device);
        raytrace::RenderResult r = raytrace::render(rt, camera, st, progress);
        bar.finish();
        spdlog::info("{} passes in {:.1f} s, {} caustic photons", r.passes, r.seconds,
                     r.photonsStored);
        if (r.nonFiniteSamples > 0)
            spdlog::warn("{} samples were NaN/Inf and dropped (a renderer bug; please report)",
                         r.nonFiniteSamples);
        result = r.radiance;
    }
    if (split) {
        RenderShard rs;
        rs.shard = shard;
        rs.range = rowRange;
        rs.rows = st.rows;
        rs.exposure = a.exposure;
        rs.image = result;
        rs.buffers = shardBuffers;
        // Everything that changes a pixel, and the scene's bytes; not threads.
        rs.fingerprint = hex64(fingerprint64(fmt::format(
            "{} {} {} {}x{} spp {} seed {} photons {} depth {} scattering {} exposure {:.9g} "
            "buffers {} scene {} image {}",
            a.camera, a.mode, ext, a.width, height, a.spp, a.seed, a.photons, a.maxDepth,
            a.scattering, a.exposure, a.saveBuffers, hex64(fileFingerprint(a.scene)),
            a.cameraImage.empty() ? std::string("-") : hex64(fileFingerprint(a.cameraImage)))));
        writeRenderShard(out, rs);
        return;
    }
    writeLinearRgb(outFile->temp(), result, ext == ".png" ? a.exposure : 1.0f);
    outFile->commit();
    spdlog::info("wrote {}", out.string());
}

const CommandRegistrar reg("render", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand(
        "render", "Render a glTF camera node with the Embree reference renderer");
    auto a = std::make_shared<RenderArgs>();
    cmd->add_option("scene", a->scene, "Scene (.gltf or .glb)")->required();
    cmd->add_option("--camera", a->camera, "Name of the glTF camera node to render")->required();
    cmd->add_option("-o,--output", a->output,
                    "Image: .exr/.pfm (linear RGB) or .png (tone-mapped sRGB)")
        ->required()
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--spp", a->spp, "Samples (passes) per pixel")
        ->capture_default_str()
        ->check(wholeIn(1, 1 << 30));
    cmd->add_option("--seconds", a->seconds,
                    "Time budget instead of --spp (per image; composite renders two)")
        ->check(finiteIn(0, 1e7));
    cmd->add_option("--width", a->width, "Image width in pixels")
        ->capture_default_str()
        ->check(wholeIn(1, 16384));
    cmd->add_option("--height", a->height,
                    "Image height (default: from the camera's aspect ratio, else 4:3)")
        ->check(wholeIn(0, 16384));
    cmd->add_option("--seed", a->seed, "Random seed (same seed = same image)")
        ->capture_default_str()
        ->check(wholeIn(0, kMaxSeed));
    cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")
        ->capture_default_str()
        ->check(wholeIn(0, 4096));
    cmd->add_option("--exposure", a->exposure,
                    "PNG only: multiplies linear radiance before sRGB encoding")
        ->capture_default_str()
        ->check(finiteIn(0, 1e6, true));
    cmd->add_option("--mode", a->mode,
                    "rv = real + virtual (L_rv), r = real only (L_r), composite = differential "
                    "rendering into "
                    "--camera-image (default: the real-only render itself)")
        ->capture_default_str();
    cmd->add_option("--camera-image", a->cameraImage,
                    "composite: the camera image (linear .exr/.pfm or sRGB .png)");
    cmd->add_flag("--force", a->force,
                  "Replace existing --save-buffers files beside the output (or an existing shard)");
    cmd->add_option("--shard", a->shard,
                    "Render part I of N (I/N, 0-based: every N-th image row from row I) into "
                    "OUT.shards/; join the parts with `mirage merge OUT` (docs/scale.md)")
        ->check(shardSpecCheck());
    cmd->add_option("--rows", a->rows,
                    "Render only image rows A to B-1 (A:B), as a shard; with --shard, the part "
                    "of those rows")
        ->check(itemRangeCheck("--rows"));
    cmd->add_flag("--save-buffers", a->saveBuffers,
                  "composite: also write OUT_Lr.exr, OUT_Lrv.exr, OUT_coverage.exr");
    cmd->add_option("--photons", a->photons, "Caustic photons per pass (0 = automatic)")
        ->capture_default_str()
        ->check(wholeIn(0, 1 << 30));
    cmd->add_option("--max-depth", a->maxDepth, "Maximum path vertices")
        ->capture_default_str()
        ->check(wholeIn(1, 1024));
    cmd->add_option("--scattering", a->scattering,
                    "Light transport in translucent objects' media: multiple (every order) or "
                    "single (once-scattered light only, what the voxel number map models)")
        ->capture_default_str()
        ->check(CLI::IsMember({"single", "multiple"}));
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
