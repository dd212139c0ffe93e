// `mirage merge OUT`: joins the shards of a split run (OUT.shards/I-of-N, written by
// `mirage synth|render|bench --shard I/N -o OUT`) into OUT, as the unsplit run would have written
// it (docs/scale.md). Checks first that every item is there exactly once and names what is
// missing with the command that reruns it; writes OUT under a temporary name and moves it into
// place; removes the shards afterwards unless --keep-shards.
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/commands/ShardMerge.h"
#include "app/commands/TerminalProgress.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/Shards.h"
#include "render/raytrace/SyntheticSession.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;

struct MergeArgs {
    std::string output;
    bool keepShards = false, force = false;
};

void run(const MergeArgs& a) {
    fs::path out(a.output);
    if (!out.has_filename()) out = out.parent_path();
    // OUT is replaced by a folder or file moved into place: a device, a socket or a FIFO cannot
    // be (core/OutputFile.h), and is refused before the shards are read.
    if (outputTarget(out, "mirage merge", fs::is_directory(out)) == OutputTarget::WriteThrough)
        throw Error("mirage merge: '" + out.string() +
                    "' is a FIFO or the standard output; the merge is written to the -o OUT the "
                    "shards were run with, as a file or folder");
    const ShardSet set = collectShards(out);
    const ShardManifest& first = set.shards.front();
    if (fs::exists(out) && !a.force)
        throw FileError(out.string(),
                        "exists already; remove it or pass --force to replace it with the merge");
    StagedPath staged(out);
    const fs::path& temp = staged.temp();

    TerminalProgress bar("merge");
    if (first.command == "synth") {
        raytrace::mergeSyntheticShards(set, temp, [&](int done, int total, const std::string&) {
            bar.update(done, total, fmt::format("frame {}/{}", done, total));
        });
    } else if (first.command == "render") {
        mergeRenderShards(set, out, temp, a.force);
    } else if (first.command == "bench") {
        mergeBenchShards(set, temp);
    } else if (first.command == "replay") {
        mergeReplayShards(set, out, temp, a.force);
    } else {
        throw FileError((set.folders.front() / "shard.json").string(),
                        "command '" + first.command +
                            "' cannot be merged by this mirage (synth, render, bench, replay)");
    }
    bar.finish();
    staged.commit();
    spdlog::info("merged {} shards ({} {}) of `mirage {}` into {}", set.shards.size(),
                 first.range.end - first.range.begin, first.unit, first.command, out.string());
    if (!a.keepShards) {
        std::error_code ec;
        fs::remove_all(shardsFolder(out), ec);
        if (ec) spdlog::warn("could not remove {}: {}", shardsFolder(out).string(), ec.message());
    }
}

const CommandRegistrar reg("merge", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand(
        "merge",
        "Join the shards of `mirage synth|render|bench --shard I/N -o OUT` into OUT "
        "(docs/scale.md)");
    auto a = std::make_shared<MergeArgs>();
    cmd->add_option("output", a->output, "The -o OUT the shards were run with")->required();
    cmd->add_flag("--keep-shards", a->keepShards, "Keep OUT.shards/ after a successful merge");
    cmd->add_flag("--force", a->force, "Replace OUT if it exists");
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
