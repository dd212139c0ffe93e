// `mirage proxies SESSION --scene VIRTUAL.gltf -o SCENE.gltf`: rebuilds the real proxies (the
// table, the objects on it, their albedo) and the real spot light from a session's footage and
// writes them, with the virtual objects of VIRTUAL.gltf, as a scene for `mirage replay` and
// `mirage live` (docs/reconstruction.md). Beside it: SCENE.report.json (what was found, sizes,
// residuals), SCENE.scan.svg (the scan seen from above), SCENE.proxies.bin and SCENE.table.png.
// The work is app/ProxiesBuild.h's, which `mirage live --scan` calls too.
//
// Camera poses, as the replay takes them: --poses POSES.csv (`mirage track`'s rows), else
// --ground-truth (the session's frames.csv), else the tracker on the session's board. Only frames
// whose tracking state is ok are used; the others are counted and named in the log.
#include "app/Command.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "app/ProxiesBuild.h"

namespace mirage::app {
namespace {

const CommandRegistrar registrar("proxies", [](CLI::App& parent) {
    auto a = std::make_shared<ProxiesRequest>();
    auto* cmd = parent.add_subcommand(
        "proxies", "Rebuild the real proxies and lights of a session's footage as a scene");
    cmd->add_option("session", a->session, "Session folder (tracked main camera, board)")
        ->required();
    cmd->add_option("--scene", a->scene, "Scene (.gltf) whose virtual objects to keep")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", a->output, "Scene to write (.gltf)")
        ->required()
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--poses", a->poses, "Camera poses (mirage track's CSV) instead of tracking")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--ground-truth", a->groundTruth, "Use the session's ground-truth poses");
    cmd->add_option("--max-frames", a->maxFrames, "Use at most this many frames (-1: all)")
        ->check(wholeIn(-1, 100000000));
    cmd->add_option("--min-frames", a->minFrames, "Tracked frames needed")
        ->capture_default_str()
        ->check(wholeIn(1, 100000));
    cmd->add_option("--min-parallax", a->minParallaxDeg,
                    "Camera positions must span this angle seen from the board (degrees)")
        ->capture_default_str()
        ->check(finiteIn(0, 180));
    cmd->add_option("--triangles", a->triangleBudget, "Triangle budget per object")
        ->capture_default_str()
        ->check(wholeIn(12, 1000000));
    cmd->add_option("--stereo-partners", a->stereo.partnersPerFrame,
                    "Stereo partners per frame (depth maps of each frame at different baselines)")
        ->capture_default_str()
        ->check(wholeIn(1, 8));
    cmd->add_option("--stereo-baseline", a->stereo.preferredBaselineM,
                    "Preferred stereo baseline (metres, within 0.035-0.14)")
        ->capture_default_str()
        ->check(finiteIn(0.035, 0.14));
    cmd->add_option("--stereo-pairs", a->stereo.maxPairs, "Depth maps computed at most")
        ->capture_default_str()
        ->check(wholeIn(1, 10000));
    cmd->add_option("--stereo-smoothness", a->stereo.smoothness,
                    "SGBM's penalty for a depth jump (P2 per channel and window pixel; P1 is 8)")
        ->capture_default_str()
        ->check(wholeIn(9, 10000));
    cmd->add_option("--stereo-uniqueness", a->stereo.uniquenessRatio,
                    "SGBM's margin (percent) by which the best match must beat the second")
        ->capture_default_str()
        ->check(wholeIn(0, 100));
    cmd->add_option("--agreeing-maps", a->stereo.minAgreeingMaps,
                    "Other depth maps that must agree with a depth to keep it (0: keep all)")
        ->capture_default_str()
        ->check(wholeIn(0, 64));
    cmd->add_option("--agreement", a->stereo.agreementDepthFraction,
                    "Depth agreement tolerance as a share of the depth (plus 6 mm)")
        ->capture_default_str()
        ->check(finiteIn(0, 0.5));
    cmd->add_flag("--no-carving", a->noCarving,
                  "Objects from the fused stereo depth alone (no space carving against the table)");
    cmd->add_option("--carving-frames", a->carving.maxFrames,
                    "Frames the space carving uses at most (spread over the footage)")
        ->capture_default_str()
        ->check(wholeIn(2, 10000));
    cmd->add_option("--carving-tolerance", a->carving.colourTolerance,
                    "A pixel shows the table when its colour is within this share of the "
                    "table's there")
        ->capture_default_str()
        ->check(finiteIn(0.01, 2));
    cmd->add_option("--table-quantile", a->carving.diffuseQuantile,
                    "The table's diffuse colour per cell: this quantile of what the frames see "
                    "there (low: a glossy table's reflections add light in some views)")
        ->capture_default_str()
        ->check(finiteIn(0, 1));
    cmd->add_option("--truth", a->truth,
                    "The scene a synthetic session was made from: compare the rebuilt scene "
                    "with it (report and console)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--force", a->force, "Overwrite an existing output");
    cmd->callback([a] { buildProxies(*a); });
});

}  // namespace
}  // namespace mirage::app
