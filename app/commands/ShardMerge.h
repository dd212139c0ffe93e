#pragma once
// The parts of split runs (core/Shards.h) that belong to one command each: how a shard of
// `mirage render` or `mirage bench` is written, and how `mirage merge` joins them: the rows of
// one image, the configurations of one grid.
// Synth shards live with the synthetic session (render/raytrace/SyntheticSession.h).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/OutputFile.h"
#include "core/Shards.h"
#include "render/evaluation/RealtimeBench.h"

namespace mirage::app {

struct RenderShard {
    ShardSpec shard;
    ItemRange range;        // --rows, as given
    std::vector<int> rows;  // image rows this shard rendered, ascending
    float exposure = 1.0f;  // for a .png output
    cv::Mat image;          // the whole image size; only `rows` are filled (linear RGB float)
    std::vector<cv::Mat> buffers;  // --save-buffers of a composite: L_r, L_rv, coverage (same)
    std::string fingerprint;
};

// Writes the shard's rows (linear float EXR, exact) and manifest into OUT.shards/I-of-N.
void writeRenderShard(const std::filesystem::path& out, const RenderShard& shard);

// Joins the rows of every shard into one image written to `temp` (named like `out`, whose
// extension chooses the format), and the --save-buffers images beside `out`.
// Files beside `out` (--save-buffers, a video's CSV) are replaced only with `force`.
void mergeRenderShards(const ShardSet& shards, const std::filesystem::path& out,
                       const std::filesystem::path& temp, bool force);

struct BenchShard {
    ShardSpec shard;
    int gridSize = 0;
    std::vector<int> configurations;                  // grid positions run, ascending
    const std::vector<render::BenchResult>* results;  // those, then footage-only rows (shard 0)
    std::string preamble;                             // bench.md's header of this shard's run
    bool images = false;
    std::string fingerprint;
};

// Writes the shard's results (JSON, exact) and manifest into OUTDIR.shards/I-of-N; `extraFiles`
// adds files to the shard's folder before it is marked complete (the --images).
void writeBenchShard(const std::filesystem::path& out, const BenchShard& shard,
                     const std::function<void(const std::filesystem::path& dir)>& extraFiles);

// Writes bench.csv, bench_frames.csv and bench.md (and images/) of the whole grid into the
// folder `temp`: the rows in grid order, as one run writes them; bench.md's header names every
// shard's machine and load.
void mergeBenchShards(const ShardSet& shards, const std::filesystem::path& temp);

struct ReplayShard {
    ShardSpec shard;
    int listed = 0;                // frames the session lists
    ItemRange range;               // the frames asked for (--start, --frames)
    std::vector<int> frames;       // this shard's block of them (positions in the session's list)
    std::filesystem::path output;  // OUT as given
    bool video = false;            // the merged output is OUT.mkv (else a PNG folder)
    double fps = 30.0;
    int jpegQuality = 92;
    int warmup = 0;  // frames rendered before the block and not written
    std::vector<std::pair<int, double>> written;  // frames with an image (index, seconds)
    std::string fingerprint;
};

// Writes the manifest into the replay's folder (staged.temp(), staged for OUT.shards/I-of-N)
// and moves it into place.
void finishReplayShard(StagedPath& staged, const ReplayShard& shard);

// Writes OUT (an MJPEG .mkv with its .csv beside it, or a folder of PNG frames with frames.csv)
// from the shards' frames in order, to `temp` named like `out`.
void mergeReplayShards(const ShardSet& shards, const std::filesystem::path& out,
                       const std::filesystem::path& temp, bool force);

}  // namespace mirage::app
