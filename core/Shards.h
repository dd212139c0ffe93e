#pragma once
// Work split across processes (docs/scale.md). A long command (`mirage synth`, `mirage render`,
// `mirage bench`) given `--shard I/N` does the I-th of N parts of its work and writes it, with a
// manifest, into OUT.shards/I-of-N/ beside its output OUT; `mirage merge OUT` joins the parts
// into OUT and names any that are missing. Each part is deterministic on its own (seeds per item,
// never per process), so a merged output equals the unsplit run's bit for bit.
//
// Items are frames (synth), image rows (render) or grid configurations (bench). A shard takes
// every N-th item starting at I ("interleaved": each shard gets early and late frames alike, so
// shards of a camera path whose cost changes along it finish together); `--frames A:B` first
// narrows the items to [A, B).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mirage {

struct ShardSpec {
    int index = 0;  // I, 0-based
    int count = 1;  // N
    bool whole() const { return count == 1; }
};
// "I/N" with 0 <= I < N <= 100000. Throws mirage::Error saying the accepted form.
ShardSpec parseShardSpec(const std::string& text);

struct ItemRange {
    int begin = 0;
    int end = -1;  // exclusive; -1 = to the last item
};
// "A:B" (items A to B-1), "A:" (from A), ":B". Throws mirage::Error for another form or A >= B;
// the message names `option`, the command-line option the text came from.
ItemRange parseItemRange(const std::string& text, const std::string& option = "--frames");

// The items of [0, total) that a shard handles: those in `range` whose offset from the range's
// start is index mod count, ascending. Throws mirage::Error (naming `option` and `unit`) if the
// range leaves [0, total).
std::vector<int> selectItems(int total, const ItemRange& range, const ShardSpec& shard,
                             const std::string& option = "--frames",
                             const std::string& unit = "items");
// The same for work that runs in order (a replay's temporal history): shard I takes the I-th of N
// contiguous blocks of the range, [begin + n I / N, begin + n (I + 1) / N) with n items in it.
std::vector<int> selectBlock(int total, const ItemRange& range, const ShardSpec& shard,
                             const std::string& option = "--frames",
                             const std::string& unit = "items");

// FNV-1a, 64 bits: the fingerprint of a command's options, so that shards of different runs are
// never merged. Not cryptographic.
uint64_t fingerprint64(const std::string& bytes, uint64_t seed = 0xcbf29ce484222325ull);
std::string hex64(uint64_t v);
// Fingerprint of a file's bytes (for the scene a run reads). Throws FileError if unreadable.
uint64_t fileFingerprint(const std::filesystem::path& path);

inline constexpr const char* kShardFormat = "mirage-shard";
// Version 2 added "files": what the shard wrote, checked by collectShards().
inline constexpr int kShardVersion = 2;

// A file a shard wrote, as its manifest records it: path relative to the shard folder, size,
// FNV-1a hash of the bytes, and for a CSV file each data row's first field (the frame, row or
// configuration it belongs to) with the row's hash, so that a deleted or changed row is named.
struct ShardFile {
    std::string path;
    uint64_t bytes = 0;
    std::string hash;
    std::vector<std::pair<std::string, std::string>> rows;  // CSV only: (first field, hash)
};

struct ShardManifest {
    std::string command;      // "synth", "render", "bench"
    std::string unit;         // "frames", "rows", "configurations"
    ShardSpec shard;          // which part this is
    int total = 0;            // items of the whole run
    ItemRange range;          // --frames, as given (end resolved to total)
    std::vector<int> items;   // the items this shard holds, ascending
    bool blocks = false;      // split into contiguous blocks (selectBlock), else interleaved
    std::string fingerprint;  // options of the run (hex); equal for every shard of one run
    std::vector<std::string> commandLine;  // argv of the run that wrote the shard
    std::string createdAt;                 // UTC, ISO 8601
    nlohmann::json payload;                // command-specific (per-item data, output settings)
    std::vector<ShardFile> files;          // what the shard wrote (empty in version 1)
};

// OUT.shards: the folder the shards of output OUT are written to.
std::filesystem::path shardsFolder(const std::filesystem::path& output);
// OUT.shards/I-of-N.
std::filesystem::path shardFolder(const std::filesystem::path& output, const ShardSpec& shard);

// Writes shard.json into `dir` atomically, with the list of every file in `dir` (hashed now:
// manifest.files is filled here). Written last: a folder without it is incomplete.
void writeShardManifest(const std::filesystem::path& dir, const ShardManifest& manifest);
// The files of a shard folder (all but shard.json), hashed, in path order.
std::vector<ShardFile> listShardFiles(const std::filesystem::path& dir);
// Throws FileError naming the shard folder, the file and the item (a frame, a row) when a file
// the manifest lists is missing or changed, a CSV row was deleted, changed or added, or the
// folder holds a file the shard did not write (a PNG swapped in from another shard).
void verifyShardFiles(const std::filesystem::path& dir, const ShardManifest& manifest);
// Throws FileError naming the file and field on a malformed manifest.
ShardManifest readShardManifest(const std::filesystem::path& dir);

struct ShardSet {
    std::vector<ShardManifest> shards;           // complete shards, by index
    std::vector<std::filesystem::path> folders;  // same order
    std::vector<int> owner;                      // item -> position in `shards`, or -1
};
// Reads every complete shard of OUT and checks they form one whole run: the same command,
// fingerprint, shard count and item total; no item twice; every item of the range present;
// every shard's files as its manifest lists them (verifyShardFiles).
// Throws mirage::Error naming the missing items, the shards that should hold them and the
// command that reruns one (its --shard changed), or the conflicting shards.
ShardSet collectShards(const std::filesystem::path& output);

// The command line of a shard with its --shard value replaced (to rerun another shard).
std::string rerunCommand(const std::vector<std::string>& commandLine, const ShardSpec& shard);

}  // namespace mirage
