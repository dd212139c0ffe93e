// Splitting work into shards: the specs, the item selection, and the checks that a set of
// shards is one whole run (core/Shards.h).
#include "core/Shards.h"

#include <fstream>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

TEST(Shards, SpecsParseAndBadOnesSayTheForm) {
    const ShardSpec s = parseShardSpec("2/5");
    EXPECT_EQ(s.index, 2);
    EXPECT_EQ(s.count, 5);
    for (const char* bad : {"5/5", "-1/4", "1/0", "1", "a/b", "1/4/2", "", "1/"}) {
        try {
            parseShardSpec(bad);
            ADD_FAILURE() << bad << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("I/N"), std::string::npos) << e.what();
        }
    }
    EXPECT_EQ(parseItemRange("3:7").begin, 3);
    EXPECT_EQ(parseItemRange("3:7").end, 7);
    EXPECT_EQ(parseItemRange("4:").end, -1);
    EXPECT_EQ(parseItemRange(":4").begin, 0);
    for (const char* bad : {"7:3", "3:3", "3", "a:b", "-1:4"})
        EXPECT_THROW(parseItemRange(bad), Error) << bad;
}

TEST(Shards, InterleavedSelectionCoversEveryItemOnce) {
    for (int count : {1, 2, 3, 7, 11}) {
        std::vector<int> seen(23, 0);
        for (int i = 0; i < count; ++i)
            for (int item : selectItems(23, ItemRange{}, ShardSpec{i, count})) ++seen[size_t(item)];
        for (int n : seen) EXPECT_EQ(n, 1) << count;
    }
    EXPECT_EQ(selectItems(10, ItemRange{4, 9}, ShardSpec{1, 2}), (std::vector<int>{5, 7}));
    EXPECT_THROW(selectItems(10, ItemRange{4, 11}, ShardSpec{}), Error);
    EXPECT_THROW(selectItems(10, ItemRange{10, -1}, ShardSpec{}), Error);
}

TEST(Shards, BlocksAreContiguousAndCoverEveryItemOnce) {
    for (int count : {1, 2, 3, 7}) {
        std::vector<int> seen(17, 0);
        int next = 3;
        for (int i = 0; i < count; ++i)
            for (int item : selectBlock(17, ItemRange{3, 17}, ShardSpec{i, count})) {
                EXPECT_EQ(item, next++) << count;  // in order, no gap between blocks
                ++seen[size_t(item)];
            }
        for (int item = 3; item < 17; ++item) EXPECT_EQ(seen[size_t(item)], 1) << count;
    }
}

TEST(Shards, MissingBlockIsNamed) {
    const fs::path out = test::outputDir("shards_blocks") / "out";
    fs::remove_all(shardsFolder(out));
    for (int i : {0, 2}) {
        ShardManifest m;
        m.command = "replay";
        m.unit = "frames";
        m.shard = {i, 3};
        m.total = 10;
        m.range = {0, 10};
        m.blocks = true;
        m.items = selectBlock(10, ItemRange{}, m.shard);
        m.fingerprint = "f";
        m.commandLine = {"mirage", "replay", "--shard", "0/3"};
        const fs::path dir = shardFolder(out, m.shard);
        fs::create_directories(dir);
        writeShardManifest(dir, m);
    }
    try {
        collectShards(out);
        FAIL() << "a missing block was not noticed";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("(3, 4, 5); rerun shard(s) 1 of 3"), std::string::npos)
            << e.what();
    }
}

ShardManifest manifest(int index, int count, int total, const std::string& fingerprint = "f") {
    ShardManifest m;
    m.command = "synth";
    m.unit = "frames";
    m.shard = {index, count};
    m.total = total;
    m.range = {0, total};
    m.items = selectItems(total, ItemRange{}, m.shard);
    m.fingerprint = fingerprint;
    m.commandLine = {"mirage", "synth", "scene.gltf", "-o", "out", "--shard", "0/3"};
    m.payload = {{"x", 1}};
    return m;
}

void writeShard(const fs::path& out, const ShardManifest& m) {
    const fs::path dir = shardFolder(out, m.shard);
    fs::create_directories(dir);
    writeShardManifest(dir, m);
}

TEST(Shards, CompleteSetIsCollectedInShardOrder) {
    const fs::path out = test::outputDir("shards_complete") / "out";
    fs::remove_all(shardsFolder(out));
    for (int i : {2, 0, 1}) writeShard(out, manifest(i, 3, 8));
    const ShardSet set = collectShards(out);
    ASSERT_EQ(set.shards.size(), 3u);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(set.shards[size_t(i)].shard.index, i);
    for (int item = 0; item < 8; ++item) EXPECT_EQ(set.owner[size_t(item)], item % 3);
    EXPECT_EQ(set.shards[0].payload["x"], 1);
}

TEST(Shards, MissingShardIsNamedWithItsRerunCommand) {
    const fs::path out = test::outputDir("shards_missing") / "out";
    fs::remove_all(shardsFolder(out));
    writeShard(out, manifest(0, 3, 8));
    writeShard(out, manifest(2, 3, 8));
    fs::create_directories(shardFolder(out, {1, 3}));  // started, never finished
    try {
        collectShards(out);
        FAIL() << "an incomplete set was accepted";
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("3 of 8 frames are missing (1, 4, 7)"), std::string::npos) << msg;
        EXPECT_NE(msg.find("rerun shard(s) 1 of 3"), std::string::npos) << msg;
        EXPECT_NE(msg.find("--shard 1/3"), std::string::npos) << msg;
        EXPECT_NE(msg.find("incomplete folders: 1-of-3"), std::string::npos) << msg;
    }
}

TEST(Shards, ShardsOfAnotherRunAreRefused) {
    const fs::path out = test::outputDir("shards_mixed") / "out";
    fs::remove_all(shardsFolder(out));
    writeShard(out, manifest(0, 2, 6, "aaaa"));
    writeShard(out, manifest(1, 2, 6, "bbbb"));
    try {
        collectShards(out);
        FAIL() << "shards of two runs were merged";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("another run"), std::string::npos) << e.what();
    }
    EXPECT_THROW(collectShards(test::outputDir("shards_none") / "nothing"), FileError);
}

TEST(Shards, DamagedManifestNamesTheField) {
    const fs::path dir = test::outputDir("shards_damaged") / "m";
    fs::create_directories(dir);
    ShardManifest m = manifest(0, 1, 4);
    m.items = {0, 1, 9};
    writeShardManifest(dir, m);
    try {
        readShardManifest(dir);
        FAIL() << "an item outside the range was accepted";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("'items' holds 9"), std::string::npos) << e.what();
    }
}

TEST(Shards, RerunCommandReplacesTheShardOnly) {
    EXPECT_EQ(rerunCommand({"mirage", "synth", "my scene.gltf", "--shard", "0/4", "-o", "x"},
                           ShardSpec{3, 4}),
              "mirage synth 'my scene.gltf' --shard 3/4 -o x");
    EXPECT_EQ(fingerprint64("a"), fingerprint64("a"));
    EXPECT_NE(fingerprint64("a"), fingerprint64("b"));
}

// The manifest lists the shard's files: a deleted CSV row, a changed or swapped image, a missing
// file or one the shard did not write is named with the shard and the frame.
TEST(Shards, ManifestCatchesDamagedFiles) {
    const fs::path out = test::outputDir("shards_files") / "out";
    auto build = [&] {
        fs::remove_all(shardsFolder(out));
        for (int i : {0, 1}) {
            const ShardManifest m = manifest(i, 2, 4);
            const fs::path dir = shardFolder(out, m.shard);
            fs::create_directories(dir / "main");
            std::ofstream csv(dir / "frames.csv");
            csv << "frame,t\n";
            for (int item : m.items) {
                csv << item << "," << item * 0.25 << "\n";
                std::ofstream(dir / "main" / (std::to_string(100000 + item).substr(1) + ".png"))
                    << "pixels of frame " << item;
            }
            csv.close();
            writeShardManifest(dir, m);
        }
    };
    auto errorOf = [&] {
        try {
            collectShards(out);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    build();
    EXPECT_EQ(errorOf(), "");
    // A deleted row.
    std::ofstream(shardFolder(out, {1, 2}) / "frames.csv") << "frame,t\n3,0.75\n";
    std::string e = errorOf();
    EXPECT_NE(e.find("1-of-2"), std::string::npos) << e;
    EXPECT_NE(e.find("row of frame 1 was deleted"), std::string::npos) << e;
    // A frame swapped in from the other shard.
    build();
    fs::copy_file(shardFolder(out, {1, 2}) / "main" / "00001.png",
                  shardFolder(out, {0, 2}) / "main" / "00000.png",
                  fs::copy_options::overwrite_existing);
    e = errorOf();
    EXPECT_NE(e.find("0-of-2"), std::string::npos) << e;
    EXPECT_NE(e.find("(frame 0)"), std::string::npos) << e;
    // A missing file, and an extra one.
    build();
    fs::remove(shardFolder(out, {0, 2}) / "main" / "00002.png");
    EXPECT_NE(errorOf().find("missing (frame 2)"), std::string::npos) << errorOf();
    build();
    fs::copy_file(shardFolder(out, {1, 2}) / "main" / "00003.png",
                  shardFolder(out, {0, 2}) / "main" / "00003.png");
    EXPECT_NE(errorOf().find("did not write (frame 3)"), std::string::npos) << errorOf();
}

}  // namespace
}  // namespace mirage
