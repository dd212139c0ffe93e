#pragma once
// `mirage bench --suite OUTDIR`: the results page (docs/results.md). For every effect of a suite
// (a scene, the nodes left out of it, and knob sweeps), a synthetic session is made with the
// reference renderer's ground truth (or reused: cached by scene and settings), the real-time
// renderer is run once per knob setting (one knob varied at a time from the default), and
// OUTDIR/results.md is written with, per effect, a speed-against-error plot (Pareto front, the
// default marked, the footage-only baseline), side-by-side crops (real-time | ground truth |
// difference x4) of the default and the cheapest setting, a stacked bar of the default frame's
// passes and scaling curves (pixels, VPLs, triangles).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace mirage::app {

struct SuiteEffect {
    std::string name;                    // file names and headings ("glass")
    std::string title;                   // one line saying what it shows
    std::vector<std::string> hideNodes;  // node names of the scene left out (their meshes)
    // Each sweep varies one knob from the default (`mirage bench --list-knobs`).
    std::vector<std::pair<std::string, std::vector<std::string>>> sweeps;
    std::filesystem::path scene;  // its own glTF (empty: the suite's scene)
    // The session films the room with a fish-eye environment camera too, for the knobs
    // env_source and env_resolution (docs/environment.md).
    bool environmentCamera = false;
};

struct SuiteSpec {
    std::filesystem::path scene;  // glTF with real and virtual parts
    std::filesystem::path board;  // empty: board.json beside each effect's scene
    int width = 640, height = 480;
    double fps = 6.0, seconds = 1.0;  // session length: fps x seconds frames
    int samplesPerPixel = 32;         // reference renderer passes per frame (ground truth)
    int repeats = 2;                  // timing repeats of the frame sequence per setting
    std::vector<SuiteEffect> effects;
    // Scaling curves (empty: none): frame time of the first effect's default against these
    // resolutions ("WxH", at most the session's) and VPL counts; triangles: a virtual sphere of
    // about this many triangles added to the first effect's scene.
    std::vector<std::string> scalingResolutions, scalingVpls;
    std::vector<int> scalingTriangles;
    // The tracker against OpenCV ArUco (tracking/ArucoComparison.h) at these image widths (640
    // and/or 1280; empty: no such section).
    std::vector<int> trackingWidths;
};

// The standard suite: the bundled tabletop scene as diffuse, mirror, glass, both and caustics,
// and its rough and translucent variants.
SuiteSpec defaultSuite();
// A suite file (JSON, docs/results.md); relative paths are relative to the file. Throws
// FileError naming the file and the field.
SuiteSpec loadSuite(const std::filesystem::path& file);

// Runs the suite into `out` (created; sessions cached under out/sessions/) and writes
// out/results.md with its SVG plots and PNG crops in out/results/ (so that results.md and
// results/ copied side by side, as docs/results.md is, keep their links). `commandLine` is quoted
// on the page.
void runSuite(const SuiteSpec& spec, const std::filesystem::path& out,
              const std::string& commandLine);

}  // namespace mirage::app
