// `mirage bench SESSION -o OUTDIR`: speed against error of the real-time renderer (docs/bench.md).
// Runs the renderer over the frames of a synthetic session (made with `mirage synth
// --ground-truth-composite`) at the ground-truth poses, for a grid of knobs
// (render/evaluation/RealtimeBench.h), and writes:
//   OUTDIR/bench.csv         one row per configuration: median GPU ms per pass and in total (with
//                            syncPasses the wall time of each pass between two glFinish; else GL
//                            timer queries), median wall ms, PSNR/SSIM over the whole
//                            frame and over the influenced pixels (pooled over frames)
//   OUTDIR/bench_frames.csv  the same per configuration and frame
//   OUTDIR/bench.md          a markdown table of bench.csv with the command, date and load average
// A "footage only" row per resolution judges the footage itself (the virtual contribution
// removed): every real configuration should beat it in the influenced pixels.
#include <algorithm>
#include <cctype>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/InputChecks.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/ShardOptions.h"
#include "app/commands/BenchSuite.h"
#include "app/commands/MachineInfo.h"
#include "app/commands/ShardMerge.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/Shards.h"
#include "core/camera/CalibrationFile.h"
#include "core/gl/Context.h"
#include "core/image/ImageIO.h"
#include "core/scene/Scene.h"
#include "core/session/Session.h"
#include "render/SessionEnvironment.h"
#include "render/evaluation/RealtimeBench.h"
#include "render/governor/FrameBudgetGovernor.h"
#include "render/raytrace/GroundTruthComposite.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;

struct BenchArgs {
    std::string session, scene, output, shard, suite, suiteFile;
    std::vector<std::string> knobs;  // NAME=V1,V2,...
    bool quick = false, listKnobs = false, noBaseline = false, images = false, force = false;
    int maxFrames = -1, start = 0, repeats = 1;
    float exposure = 1.0f;
    double budgetMs = 0;  // > 0: the setting a frame-time governor holds there (budget.md)
};

// The rows' governed knobs, median wall ms and influenced PSNR as the governor's table.
render::SpeedErrorTable speedErrorTable(const std::vector<render::BenchResult>& results) {
    std::vector<render::SpeedErrorRow> rows;
    for (const render::BenchResult& r : results) {
        if (r.baseline) continue;
        render::SpeedErrorRow row;
        for (const auto& [name, value] : r.config.knobs)
            if (render::isGovernedKnob(name)) row.setting[name] = value;
        row.frameMs = r.medianWallMs;
        row.psnrDb = r.error.psnrInfluenced;
        rows.push_back(std::move(row));
    }
    return render::SpeedErrorTable(std::move(rows));
}

std::map<std::string, std::vector<std::string>> parseKnobs(const std::vector<std::string>& specs) {
    std::map<std::string, std::vector<std::string>> out;
    for (const auto& spec : specs) {
        const size_t eq = spec.find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
            throw Error(
                "mirage bench: --knob expects NAME=VALUE[,VALUE...] (e.g. vpls=64,256), "
                "got '" +
                spec + "'; --list-knobs lists the knobs");
        std::vector<std::string> values;
        std::stringstream ss(spec.substr(eq + 1));
        for (std::string v; std::getline(ss, v, ',');)
            if (!v.empty()) values.push_back(v);
        out[spec.substr(0, eq)] = values;
    }
    return out;
}

std::string commandLine(const BenchArgs& a) {
    std::string s = "mirage bench " + a.session + " -o " + a.output;
    if (!a.scene.empty()) s += " --scene " + a.scene;
    if (a.quick) s += " --quick";
    for (const auto& k : a.knobs) s += " --knob " + k;
    if (a.start > 0) s += fmt::format(" --start {}", a.start);
    if (a.maxFrames >= 0) s += fmt::format(" --frames {}", a.maxFrames);
    if (a.repeats != 1) s += fmt::format(" --repeat {}", a.repeats);
    if (a.exposure != 1.0f) s += fmt::format(" --exposure {}", a.exposure);
    if (a.noBaseline) s += " --no-baseline";
    if (a.images) s += " --images";
    return s;
}

// The first frame of every configuration beside its ground truth (sRGB PNG). File names are the
// configuration's number and its label, cut to stay under the file systems' 255-byte limit (the
// full grid's labels are longer); labels.txt maps each file to its whole label.
void writeBenchImages(const fs::path& folder, const std::vector<render::BenchResult>& results) {
    fs::create_directories(folder);
    std::string index;
    for (size_t i = 0; i < results.size(); ++i) {
        const auto& r = results[i];
        const std::string label = r.baseline ? "footage " + r.config.label() : r.config.label();
        std::string name = label.substr(0, 200);
        for (char& ch : name)
            if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
        name = fmt::format("{:02d}_{}.png", i, name);
        writeBgr8(folder / name, r.firstComposite);
        writeBgr8(folder / fmt::format("truth_{}x{}.png", r.config.width, r.config.height),
                  r.firstTruth);
        index += name + " " + label + "\n";
    }
    std::ofstream(folder / "labels.txt") << index;
}

// The benchmarked session with its ground-truth composite, the main camera's calibration and
// the scene it was synthesised from; what to do when one is missing.
struct BenchInputs {
    Session session;
    render::GroundTruthInfo gt;
    CameraCalibration calib;
    std::string scenePath;
};
BenchInputs readBenchInputs(const BenchArgs& a) {
    BenchInputs in;
    SessionReadReport readReport;
    in.session = readSession(a.session, &readReport);
    const Session& session = in.session;
    for (const auto& w : readReport.warnings) spdlog::warn("session: {}", w);
    const std::optional<render::GroundTruthInfo> gt = render::readGroundTruthInfo(session.dir);
    if (!gt)
        throw FileError(fs::path(a.session) / render::kGroundTruthFile,
                        "the session has no ground-truth composite; make it with `mirage synth "
                        "SCENE -o SESSION --ground-truth-composite` (docs/bench.md)");
    in.gt = *gt;
    const SessionCamera* main = session.cameras.empty() ? nullptr : &session.cameras.front();
    for (const auto& c : session.cameras)
        if (c.role == "main") main = &c;
    if (!main || main->calibration.empty())
        throw FileError(a.session, "the main camera has no calibration file in session.json");
    in.calib = loadCalibration(session.path(main->calibration));
    in.scenePath = a.scene.empty() ? gt->scene : a.scene;
    if (in.scenePath.empty() || !fs::exists(in.scenePath))
        throw FileError(in.scenePath.empty()
                            ? (fs::path(a.session) / render::kGroundTruthFile).string()
                            : in.scenePath,
                        "scene not found; pass --scene SCENE.gltf (the scene the session was "
                        "synthesised from, with its virtual objects)");
    return in;
}

// The session's environment camera, for configurations with env_source=camera (nullopt when
// the grid has none); what is wrong with it otherwise.
std::optional<render::SessionEnvironment> benchEnvironment(
    const std::vector<render::BenchConfig>& grid, const Session& session, const BenchArgs& a) {
    if (std::none_of(grid.begin(), grid.end(),
                     [](const render::BenchConfig& c) { return c.environmentCamera; }))
        return std::nullopt;
    std::string why;
    std::optional<render::SessionEnvironment> env =
        render::SessionEnvironment::open(session, a.exposure, why);
    if (!env)
        throw FileError(
            a.session,
            "knob env_source=camera: " +
                (why.empty() ? std::string("the session has no environment camera") : why));
    return env;
}

// The head of bench.md: the command, the session, the machine and what the figures are.
std::string benchPreamble(const BenchArgs& a, const std::vector<render::BenchFrame>& frames,
                          const CameraIntrinsics& camera, const std::string& scenePath,
                          const gl::Context& ctx, const std::string& startedAt,
                          const std::string& loadBefore, const std::string& loadAfter) {
    double influenced = 0;
    for (const auto& f : frames) influenced += cv::countNonZero(f.influence);
    return fmt::format(
        "# mirage bench\n\n"
        "- command: `{}`\n"
        "- session: {} ({} frame(s), {}x{}), scene: {}\n"
        "- machine: {} CPU ({} cores), GL renderer {} ({}), started {}, load average (1/5/15 min) "
        "{} before, {} after\n"
        "- times: medians over frames (x{} repeats) of ms per pass: with `syncPasses` the wall "
        "time between a glFinish before and after each pass, else GL timer queries; wall ms = "
        "render() + composite readback on the CPU\n"
        "- errors: 8-bit sRGB composite vs the ground-truth composite, pooled over frames; "
        "\"infl.\" = pixels the virtual objects influence ({} pixel(s) in all at the session's "
        "size)\n",
        commandLine(a), a.session, frames.size(), camera.width, camera.height, scenePath,
        cpuModel(), std::max(1u, std::thread::hardware_concurrency()), ctx.rendererName(),
        ctx.versionString(), startedAt, loadBefore, loadAfter, a.repeats, influenced);
}

void runBench(const BenchArgs& a) {
    if (a.listKnobs) {
        for (const auto& k : render::benchKnobs())
            std::printf("%-16s %s\n", k.name.c_str(), k.help.c_str());
        return;
    }
    if (a.output.empty()) throw Error("mirage bench: -o OUTDIR is required");
    if (a.repeats < 1) throw Error("mirage bench: --repeat must be >= 1");
    const auto overrides = parseKnobs(a.knobs);

    const BenchInputs inputs = readBenchInputs(a);
    const Session& session = inputs.session;
    const render::GroundTruthInfo* gt = &inputs.gt;
    const CameraCalibration& calib = inputs.calib;
    const std::string& scenePath = inputs.scenePath;
    // The outputs are checked before the benchmark runs (core/OutputFile.h).
    const fs::path out(a.output);
    OutputRule rule{sessionInputs(session), a.force, "mirage bench"};
    rule.inputs.push_back(scenePath);
    checkOutput(out, OutputOrigin::Named, rule, /*outIsFolder=*/true);
    // A shard (--shard I/N) runs every N-th configuration of the grid from I and leaves the
    // tables to `mirage merge` (core/Shards.h).
    const bool split = !a.shard.empty();
    const ShardSpec shard = split ? parseShardSpec(a.shard) : ShardSpec{};
    if (split && fs::exists(shardFolder(out, shard) / "shard.json") && !a.force)
        throw FileError(shardFolder(out, shard).string(),
                        "this shard is already complete; pass --force to run it again");
    std::optional<OutputFile> csvOut, framesOut, mdOut;
    if (!split) {
        csvOut.emplace(out / "bench.csv", OutputOrigin::Derived, rule);
        framesOut.emplace(out / "bench_frames.csv", OutputOrigin::Derived, rule);
        mdOut.emplace(out / "bench.md", OutputOrigin::Derived, rule);
    }
    checkLooksLikeGltf(scenePath);
    const Scene scene = loadScene(scenePath);
    if (!scene.hasVirtual())
        throw FileError(scenePath, "the scene has no virtual object: nothing to judge");

    // The grid first: bad knobs fail before any frame is decoded.
    std::vector<render::BenchConfig> grid = render::benchGrid(calib.intrinsics, a.quick, overrides);
    for (auto& c : grid) c.options.composite.exposure = a.exposure;

    // Frames with a ground-truth pose and ground-truth composite, in session order.
    int skipped = 0;
    const std::vector<render::BenchFrame> frames =
        render::loadBenchFrames(session, *gt, calib.intrinsics, a.start, a.maxFrames, &skipped);
    if (skipped > 0)
        spdlog::warn("bench: {} frame(s) without a ground-truth pose or composite skipped",
                     skipped);
    if (frames.empty())
        throw FileError(a.session,
                        "no frame has both a ground-truth pose (frames.csv) and a "
                        "ground-truth composite to judge against");

    // The session's environment camera, for configurations with env_source=camera.
    std::optional<render::SessionEnvironment> env = benchEnvironment(grid, session, a);

    gl::ContextOptions copt;
    copt.width = calib.intrinsics.width;
    copt.height = calib.intrinsics.height;
    gl::Context ctx = gl::Context::headless(copt);

    const std::string loadBefore = loadAverage();
    const std::string startedAt = utcNow();
    spdlog::info("bench: {} configuration(s) over {} frame(s) of {} ({}x{}), load average {}",
                 grid.size(), frames.size(), a.session, calib.intrinsics.width,
                 calib.intrinsics.height, loadBefore);
    std::vector<render::BenchResult> results;
    std::set<std::pair<int, int>> sizes;  // of the whole grid, for the footage-only rows
    for (const auto& c : grid)
        sizes.insert({c.width > 0 ? c.width : calib.intrinsics.width,
                      c.height > 0 ? c.height : calib.intrinsics.height});
    const std::vector<int> chosen = selectItems(int(grid.size()), ItemRange{}, shard);
    if (chosen.empty())
        throw Error(
            fmt::format("mirage bench: shard {}/{} holds none of the {} configurations; "
                        "use at most as many shards as configurations",
                        shard.index, shard.count, grid.size()));
    for (int i : chosen) {
        const auto& c = grid[size_t(i)];
        render::BenchResult r = render::runBenchConfig(scene, calib.intrinsics, frames, c,
                                                       a.repeats, env ? &env->setup() : nullptr);
        spdlog::info(
            "bench [{}/{}] {}: {:.1f} GPU ms/frame (median), PSNR {:.2f} dB / "
            "influenced {:.2f} dB, SSIM {:.4f} / {:.4f}",
            results.size() + 1, chosen.size(), c.label(), r.medianGpuMs, r.error.psnrFrame,
            r.error.psnrInfluenced, r.error.ssimFrame, r.error.ssimInfluenced);
        results.push_back(std::move(r));
    }
    // The footage judged as the composite, once per resolution, after the configurations (in a
    // split bench, by the first shard).
    if (!a.noBaseline && shard.index == 0)
        for (auto it = sizes.rbegin(); it != sizes.rend(); ++it)
            results.push_back(render::footageBaseline(frames, it->first, it->second));
    const std::string loadAfter = loadAverage();

    const std::string preamble = benchPreamble(a, frames, calib.intrinsics, scenePath, ctx,
                                               startedAt, loadBefore, loadAfter);
    if (split) {
        BenchShard bs;
        bs.shard = shard;
        bs.gridSize = int(grid.size());
        bs.configurations = chosen;
        bs.results = &results;
        bs.preamble = preamble;
        bs.images = a.images;
        // Everything that decides the grid and the errors; not the timing repeats.
        std::string knobs;
        for (const auto& k : a.knobs) knobs += k + ";";
        bs.fingerprint = hex64(fingerprint64(fmt::format(
            "{} {} {} {} {} {} {:.9g} {} {} {}",
            fs::absolute(a.session).lexically_normal().string(), scenePath, a.quick, knobs, a.start,
            a.maxFrames, a.exposure, a.noBaseline, a.images, hex64(fileFingerprint(scenePath)))));
        writeBenchShard(out, bs, [&](const fs::path& dir) {
            if (a.images) writeBenchImages(dir / "images", results);
        });
        return;
    }
    render::writeBenchCsv(csvOut->temp().string(), results);
    render::writeBenchFramesCsv(framesOut->temp().string(), results);
    render::writeBenchMarkdown(mdOut->temp().string(), results, preamble);
    csvOut->commit();
    framesOut->commit();
    mdOut->commit();
    if (a.images) writeBenchImages(out / "images", results);
    if (a.budgetMs > 0) {
        const render::SpeedErrorTable table = speedErrorTable(results);
        double footage = std::numeric_limits<double>::quiet_NaN();
        for (const render::BenchResult& r : results)
            if (r.baseline) footage = r.error.psnrInfluenced;
        std::ofstream(out / "budget.svg") << render::budgetPlotSvg(table, a.budgetMs, footage);
        const std::string report = render::budgetReport(table, a.budgetMs);
        std::ofstream(out / "budget.md")
            << report << "\n![the settings' speed against error, the front the governor follows "
            << "and its choice at this budget](budget.svg)\n";
        spdlog::info("bench: {}", report.substr(0, report.find("\n\nThe speed")));
    }
    spdlog::info("bench: wrote {}, {}, {} (load average {} after)", (out / "bench.csv").string(),
                 (out / "bench_frames.csv").string(), (out / "bench.md").string(), loadAfter);
}

const CommandRegistrar reg("bench", [](CLI::App& parent) {
    auto a = std::make_shared<BenchArgs>();
    auto* cmd = parent.add_subcommand(
        "bench",
        "Speed against error: the real-time renderer over a synthetic session's frames, for a "
        "grid of knobs, judged against the ground-truth composite");
    cmd->add_option("session", a->session,
                    "Synthetic session made with `mirage synth --ground-truth-composite`");
    cmd->add_option("-o,--output", a->output, "Folder for bench.csv, bench_frames.csv, bench.md")
        ->check(outputPath(OutputShape::Folder));
    cmd->add_option("--scene", a->scene,
                    "Scene with the virtual objects (default: the one ground_truth.json names)");
    cmd->add_flag("--quick", a->quick, "A small grid (one resolution, 64/256 VPLs, gather 1/2)");
    cmd->add_option("--knob", a->knobs,
                    "NAME=V1,V2,...: the values of one knob (repeatable; see --list-knobs)")
        ->allow_extra_args(false);
    cmd->add_flag("--list-knobs", a->listKnobs, "List the knobs and exit");
    cmd->add_flag("--force", a->force, "Replace bench.csv, bench_frames.csv, bench.md in OUTDIR");
    cmd->add_option("--frames", a->maxFrames, "Use at most N frames")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("--start", a->start, "First frame")->check(wholeIn(0, 100000000));
    cmd->add_option("--budget-ms", a->budgetMs,
                    "Frame-time budget (ms): OUTDIR/budget.md says which setting of the grid a "
                    "frame-time governor holds there (the most accurate within it on the "
                    "speed-vs-error front of the grid's rows) and its error beside the most "
                    "accurate setting's")
        ->check(finiteIn(0, 60000));
    cmd->add_option("--repeat", a->repeats, "Run the frame sequence R times (timings pooled)")
        ->capture_default_str()
        ->check(wholeIn(1, 10000));
    cmd->add_option("--exposure", a->exposure,
                    "Rendered radiance -> camera linear units (the synth's --exposure)")
        ->capture_default_str()
        ->check(finiteIn(0, 1e6, true));
    cmd->add_flag("--no-baseline", a->noBaseline, "Leave out the footage-only rows");
    cmd->add_option("--shard", a->shard,
                    "Run part I of N of the grid (I/N, 0-based: every N-th configuration from I) "
                    "into OUTDIR.shards/; join the parts with `mirage merge OUTDIR` "
                    "(docs/scale.md)")
        ->check(shardSpecCheck());
    cmd->add_option("--suite", a->suite,
                    "Write the results page to OUTDIR/results.md: every effect's session "
                    "synthesised (or reused from OUTDIR/sessions), its knob sweeps, plots, crops "
                    "and scaling curves (docs/results.md; hours on 2 cores)");
    cmd->add_option("--suite-file", a->suiteFile,
                    "With --suite: the effects, sizes and sweeps from this JSON file instead of "
                    "the standard suite (docs/bench.md)");
    cmd->add_flag("--images", a->images,
                  "Also write each configuration's first composite and the ground truth to "
                  "OUTDIR/images/ (sRGB PNG)");
    cmd->callback([a] {
        if (!a->suiteFile.empty() && a->suite.empty())
            throw Error("mirage bench: --suite-file needs --suite OUTDIR");
        if (!a->suite.empty()) {
            if (!a->session.empty() || !a->output.empty())
                throw Error(
                    "mirage bench: --suite OUTDIR makes its own sessions; give no SESSION or "
                    "-o with it");
            const SuiteSpec spec = a->suiteFile.empty() ? defaultSuite() : loadSuite(a->suiteFile);
            std::string cmdLine = "mirage bench --suite " + a->suite;
            if (!a->suiteFile.empty()) cmdLine += " --suite-file " + a->suiteFile;
            runSuite(spec, a->suite, cmdLine);
            return;
        }
        if (!a->listKnobs && a->session.empty())
            throw Error(
                "mirage bench: SESSION is required (a folder made by `mirage synth "
                "--ground-truth-composite`)");
        runBench(*a);
    });
});

}  // namespace
}  // namespace mirage::app
