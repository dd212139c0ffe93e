#include "app/live/LiveScan.h"

#include <filesystem>

#include <fmt/format.h>

#include "app/ProxiesBuild.h"
#include "app/live/LiveInputs.h"
#include "app/live/LiveSession.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/capture/LiveRecording.h"
#include "core/scene/ScenePlacement.h"

namespace mirage::app {

namespace fs = std::filesystem;

std::string scanFolder(const LiveOptions& o) {
    if (!o.scanDir.empty()) return o.scanDir;
    if (!o.output.empty()) {
        fs::path out(o.output);
        if (out.has_extension()) out.replace_extension();
        return out.string() + ".scan";
    }
    return timestampName("live-scan-", "");
}

int runLiveWithScan(const LiveOptions& options) {
    const fs::path dir = scanFolder(options);
    LiveRecording::checkFolder(dir);  // before any frame: never mixed with earlier files
    LiveOptions scan = options;
    scan.scanSeconds = 0;
    scan.maxSeconds = options.scanSeconds;
    scan.maxFrames = -1;
    scan.output.clear();
    scan.screenshot.clear();  // a window's screenshot is of the live part
    scan.record = dir.string();
    scan.hideVirtual = true;  // nothing to composite yet: every frame the loop takes is tracked
    spdlog::info(
        "live: scanning for {:g} s into {}: walk the camera slowly around the table in an arc "
        "of 30 degrees or more, 20-40 degrees down, keeping the board in view",
        options.scanSeconds, dir.string());
    {
        LiveSession session(scan);
        if (const int code = session.run(); code != 0) return code;
    }
    if (!fs::exists(dir / "session.json"))
        throw Error(fmt::format(
            "mirage live --scan: the scan recorded no frame in {:.1f} s (the camera delivered "
            "none, or the environment camera had not started); scan for longer",
            options.scanSeconds));
    ProxiesRequest rebuild;
    rebuild.session = dir.string();
    rebuild.scene = options.scene;
    rebuild.output = (dir / "scene.gltf").string();
    rebuild.poses = (dir / "poses.csv").string();
    spdlog::info("live: rebuilding the real proxies and lights from the scan");
    try {
        buildProxies(rebuild);
    } catch (const reconstruction::FootageRefused& e) {
        throw Error(std::string(e.what()) + "; the scan is kept in " + dir.string() +
                    " (scan again with --scan, or rebuild it with `mirage proxies " + dir.string() +
                    " --scene " + options.scene + " --poses " + rebuild.poses + " -o " +
                    rebuild.output + "`)");
    }
    LiveOptions live = options;
    live.scanSeconds = 0;
    live.scene = rebuild.output;
    // The virtual objects stay where the user placed them in the original scene.
    if (live.placement.empty()) live.placement = placementPath(options.scene).string();
    spdlog::info("live: going on live with the rebuilt scene {} (edit it by hand: docs/scene.md)",
                 live.scene);
    LiveSession session(live);
    return session.run();
}

}  // namespace mirage::app
