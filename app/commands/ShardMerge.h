#pragma once
// The parts of split runs (core/Shards.h) that belong to one command each: how a shard of
// `mirage render` is written, and how `mirage merge` joins those of render (rows of one image).
// Synth shards live with the synthetic session (render/raytrace/SyntheticSession.h).
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/Shards.h"

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
void mergeRenderShards(const ShardSet& shards, const std::filesystem::path& out,
                       const std::filesystem::path& temp);

}  // namespace mirage::app
