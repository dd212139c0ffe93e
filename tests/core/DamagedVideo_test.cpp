// Fault injection on recorded footage: flipped bytes, damaged clusters, random blocks in the
// middle of the sample session's main.mkv. Every frame a reader delivers must be the frame that
// was recorded (compared with the undamaged file's frame at the same number), every other frame
// must be reported lost with a reason, and every frame whose bytes are intact must be delivered.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/image/StrictJpeg.h"
#include "core/session/AtomicFile.h"
#include "core/session/AviScanner.h"
#include "core/session/FrameInventory.h"
#include "core/session/MatroskaFrames.h"
#include "core/session/MatroskaScanner.h"
#include "core/session/MatroskaWriter.h"
#include "core/session/Session.h"
#include "tests/support/TestSupport.h"

namespace mirage {
namespace {

namespace fs = std::filesystem;

fs::path sampleVideo() {
    return test::dataDir() / "sessions" / "sample" / "main.mkv";
}

struct Decoded {
    std::vector<cv::Mat> frames;  // by frame number; empty = lost
    std::vector<std::string> problems;
};

Decoded readAllFrames(const fs::path& video) {
    Decoded d;
    auto src = openFrames(video);
    cv::Mat f;
    while (src->read(f)) {
        d.frames.push_back(f.clone());
        d.problems.push_back(src->lastProblem());
    }
    return d;
}

// The original's frames, and for each the bytes of its block (to know which frames a damage
// left intact).
struct Original {
    std::string bytes;
    MatroskaScan scan;
    Decoded decoded;
};

const Original& original() {
    static const Original o = [] {
        // Without the checksums: the JPEG checks alone must find the damage, as in other
        // recorders' files (ChecksummedRecordingGivesRightFramesOrLostOnes tests the checksums).
        const fs::path video = test::outputDirForThisTest("damaged_video_original") / "main.mkv";
        std::ofstream(video, std::ios::binary)
            << test::withoutMatroskaClusterChecksums(readFileBytes(sampleVideo()));
        Original r;
        r.bytes = readFileBytes(video);
        r.scan = scanMatroska(video);
        r.decoded = readAllFrames(video);
        EXPECT_EQ(r.bytes.size(), fs::file_size(sampleVideo()));
        return r;
    }();
    return o;
}

// Which original frames have every byte of their cluster unchanged in `damaged` (the cluster
// runs from the block's cluster start to the next block's; approximated by the bytes from the
// end of the previous block to the end of this one, which covers its headers).
std::vector<bool> intactFrames(const std::string& damaged) {
    const Original& o = original();
    std::vector<bool> intact;
    uint64_t from = o.scan.blocks.empty() ? 0 : o.scan.blocks.front().offset - 64;
    for (const MatroskaBlock& b : o.scan.blocks) {
        const uint64_t to = b.offset + b.size;
        intact.push_back(to <= damaged.size() &&
                         o.bytes.compare(size_t(from), size_t(to - from), damaged, size_t(from),
                                         size_t(to - from)) == 0);
        from = to;
    }
    return intact;
}

struct Outcome {
    int delivered = 0, lost = 0, wrong = 0, intactMissing = 0;
    int valueDamage = 0;  // delivered, damaged only in coefficient value bits (undetectable)
};

// The bytes of the original frame `b` that differ in `damaged` all lie between the end of the
// JPEG's start-of-scan header and its end-of-image marker.
bool changedOnlyInEntropyCodedData(const std::string& damaged, const MatroskaBlock& b) {
    const std::string& orig = original().bytes;
    const std::string jpeg = orig.substr(size_t(b.offset), size_t(b.size));
    const size_t sos = jpeg.find("\xFF\xDA");
    if (sos == std::string::npos || sos + 4 > jpeg.size()) return false;
    const size_t dataStart =
        sos + 2 + (size_t(uint8_t(jpeg[sos + 2])) << 8 | uint8_t(jpeg[sos + 3]));
    const size_t eoi = jpeg.rfind("\xFF\xD9");
    for (size_t k = 0; k < jpeg.size(); ++k)
        if (damaged[size_t(b.offset) + k] != jpeg[k] && (k < dataStart || k >= eoi)) return false;
    return true;
}

Outcome check(const std::string& damaged, const std::string& name) {
    const fs::path path = test::outputDir("damaged_video_" + name) / "main.mkv";
    std::ofstream(path, std::ios::binary) << damaged;
    const Original& o = original();
    const Decoded d = readAllFrames(path);
    const std::vector<bool> intact = intactFrames(damaged);
    Outcome r;
    EXPECT_LE(d.frames.size(), o.decoded.frames.size()) << name;
    for (size_t i = 0; i < d.frames.size() && i < o.decoded.frames.size(); ++i) {
        if (d.frames[i].empty()) {
            ++r.lost;
            EXPECT_FALSE(d.problems[i].empty()) << name << ": frame " << i << " lost silently";
            if (intact[i]) ++r.intactMissing;
            continue;
        }
        ++r.delivered;
        // The same JPEG bytes decode to the same image; anything else is a wrong frame, unless
        // every changed byte lies inside the entropy-coded data: a changed coefficient value
        // bit decodes cleanly (no Huffman or marker error follows from it), which no JPEG check
        // can reveal, only a checksum (mirage's recordings carry one per cluster: see
        // ChecksummedRecordingGivesRightFramesOrLostOnes).
        const double diff = test::percentileAbsDiff(d.frames[i], o.decoded.frames[i], 1.0);
        if (diff > 1.0) {
            if (changedOnlyInEntropyCodedData(damaged, o.scan.blocks[i])) {
                ++r.valueDamage;
                continue;
            }
            ++r.wrong;
            ADD_FAILURE() << name << ": frame " << i << " delivered but differs from the "
                          << "recording (max difference " << diff << ")";
        }
    }
    // Intact frames past the end of what was read are missing too.
    for (size_t i = d.frames.size(); i < intact.size(); ++i) r.intactMissing += intact[i];
    return r;
}

std::string flipBytes(std::string bytes, int flips, uint32_t seed) {
    std::mt19937 rng(seed);
    for (int k = 0; k < flips; ++k) {
        const size_t i = std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng);
        bytes[i] =
            char(uint8_t(bytes[i]) ^ uint8_t(std::uniform_int_distribution<int>(1, 255)(rng)));
    }
    return bytes;
}

TEST(DamagedVideo, SampleDecodesCompletely) {
    const Original& o = original();
    ASSERT_EQ(o.decoded.frames.size(), 36u);
    for (size_t i = 0; i < o.decoded.frames.size(); ++i) {
        ASSERT_FALSE(o.decoded.frames[i].empty()) << o.decoded.problems[i];
        EXPECT_TRUE(o.decoded.problems[i].empty()) << o.decoded.problems[i];
    }
}

TEST(DamagedVideo, TwoHundredByteFlipsGiveRightFramesOrLostOnes) {
    for (uint32_t seed : {1u, 2u, 3u}) {
        const Outcome r =
            check(flipBytes(original().bytes, 200, seed), "flip200_" + std::to_string(seed));
        EXPECT_EQ(r.wrong, 0) << "seed " << seed;
        EXPECT_EQ(r.intactMissing, 0) << "seed " << seed;
        EXPECT_GT(r.lost, 0) << "seed " << seed;  // 200 flips hit most of the 36 frames
        // Most damage desynchronises the entropy decoder and is caught; what is left are
        // changed coefficient values (measured: 3 to 6 frames per seed).
        EXPECT_LT(r.valueDamage, r.lost) << "seed " << seed;
        std::printf("200 flips, seed %u: %d delivered, %d lost, %d damaged in value bits only\n",
                    seed, r.delivered, r.lost, r.valueDamage);
    }
}

TEST(DamagedVideo, RandomBlockMidFileLosesOnlyTheFramesItHits) {
    for (uint32_t seed : {1u, 2u, 3u, 4u}) {
        std::string bytes = original().bytes;
        std::mt19937 rng(seed);
        // 4 KiB of random bytes at and around the middle (the seed moves it by up to 100 KB so
        // that some runs hit a cluster header).
        const size_t at = bytes.size() / 2 + size_t(seed) * 25'000;
        for (size_t i = at; i < at + 4096; ++i) bytes[i] = char(rng() & 0xFF);
        const Outcome r = check(bytes, "mid4k_" + std::to_string(seed));
        EXPECT_EQ(r.wrong, 0) << "seed " << seed;
        EXPECT_EQ(r.intactMissing, 0) << "seed " << seed;
        EXPECT_GE(r.delivered, 34) << "seed " << seed;  // 4 KiB spans at most two frames
    }
}

TEST(DamagedVideo, DamagedClusterHeaderResynchronisesAndReportsTheLostRange) {
    const Original& o = original();
    std::string bytes = o.bytes;
    // Overwrite the headers of frame 20's cluster (its timestamp and block header: the 16
    // bytes before the JPEG).
    const uint64_t blockStart = o.scan.blocks[20].offset;
    for (uint64_t i = blockStart - 16; i < blockStart; ++i) bytes[size_t(i)] = char(0x00);
    const fs::path path = test::outputDir("damaged_video_cluster") / "main.mkv";
    std::ofstream(path, std::ios::binary) << bytes;
    const MatroskaScan scan = scanMatroska(path);
    EXPECT_FALSE(scan.truncated);
    ASSERT_EQ(scan.gaps.size(), 1u) << scan.problem;
    EXPECT_NE(scan.problem.find("frame 20 lost"), std::string::npos) << scan.problem;
    EXPECT_NE(scan.problem.find("resumed at the next cluster"), std::string::npos);
    const Outcome r = check(bytes, "cluster20");
    EXPECT_EQ(r.wrong, 0);
    EXPECT_EQ(r.lost, 1);
    EXPECT_EQ(r.delivered, 35);
    // A session keeps every row after the damage on its own frame.
    FrameInventory inv = inventoryFrames(path);
    EXPECT_EQ(inv.videoFrames, 36);
    ASSERT_EQ(inv.problems.size(), 1u);
    EXPECT_NE(inv.problems[0].find("frame 20 lost"), std::string::npos) << inv.problems[0];
}

TEST(DamagedVideo, TruncationAtEveryTenthOfTheFileKeepsRightFrames) {
    const std::string& bytes = original().bytes;
    for (int k = 1; k < 10; ++k) {
        const Outcome r =
            check(bytes.substr(0, bytes.size() * size_t(k) / 10), "cut" + std::to_string(k));
        EXPECT_EQ(r.wrong, 0) << k;
        EXPECT_EQ(r.lost, 0) << k;  // a cut file simply ends earlier
    }
}

TEST(DamagedVideo, CorruptJpegIsLostWhereOpenCvConcealsIt) {
    // The old path (OpenCV/libjpeg with concealment) returned an image for damaged entropy-coded
    // data; the strict decoder refuses it.
    const Original& o = original();
    const MatroskaBlock& b = o.scan.blocks[5];
    std::string jpeg = o.bytes.substr(size_t(b.offset), size_t(b.size));
    std::string damaged = jpeg;
    for (size_t i = damaged.size() / 2; i < damaged.size() / 2 + 64; ++i) damaged[i] = char(0x5A);
    const std::vector<uchar> buf(damaged.begin(), damaged.end());
    EXPECT_FALSE(cv::imdecode(buf, cv::IMREAD_COLOR).empty());  // concealed
    std::string why;
    EXPECT_TRUE(
        decodeJpegStrict(reinterpret_cast<const uint8_t*>(damaged.data()), damaged.size(), &why)
            .empty());
    EXPECT_NE(why.find("corrupt JPEG"), std::string::npos) << why;
    EXPECT_FALSE(
        decodeJpegStrict(reinterpret_cast<const uint8_t*>(jpeg.data()), jpeg.size()).empty());
    // Cut JPEG data.
    EXPECT_TRUE(
        decodeJpegStrict(reinterpret_cast<const uint8_t*>(jpeg.data()), jpeg.size() / 2).empty());
}

TEST(DamagedVideo, ChecksummedRecordingGivesRightFramesOrLostOnes) {
    // mirage's own recordings carry a CRC-32 per cluster: there, even a changed coefficient
    // value is found, so every frame delivered is exactly the recorded one.
    const fs::path dir = test::outputDir("damaged_video_crc");
    std::vector<cv::Mat> written;
    {
        MatroskaWriter w(dir / "rec.mkv", 30, 90);
        for (int i = 0; i < 12; ++i) {
            cv::Mat m(96, 128, CV_8UC3);
            cv::RNG rng(uint64_t(i) + 1);
            rng.fill(m, cv::RNG::UNIFORM, 0, 256);
            w.append(m, i / 30.0);
        }
    }
    const Decoded clean = readAllFrames(dir / "rec.mkv");
    ASSERT_EQ(clean.frames.size(), 12u);
    for (const std::string& p : clean.problems) EXPECT_TRUE(p.empty()) << p;
    const std::string bytes = readFileBytes(dir / "rec.mkv");
    int lost = 0, delivered = 0;
    for (uint32_t seed = 1; seed <= 20; ++seed) {
        const std::string damaged = flipBytes(bytes, 6, seed);
        std::ofstream(dir / "damaged.mkv", std::ios::binary | std::ios::trunc) << damaged;
        const Decoded d = readAllFrames(dir / "damaged.mkv");
        for (size_t i = 0; i < d.frames.size() && i < clean.frames.size(); ++i) {
            if (d.frames[i].empty()) {
                ++lost;
                EXPECT_FALSE(d.problems[i].empty());
                continue;
            }
            ++delivered;
            EXPECT_LE(test::percentileAbsDiff(d.frames[i], clean.frames[i], 1.0), 0.0)
                << "seed " << seed << ", frame " << i << " delivered but damaged";
        }
    }
    EXPECT_GT(lost, 20);
    EXPECT_GT(delivered, 100);
}

TEST(DamagedVideo, ExactRepeatIsFlagged) {
    const fs::path dir = test::outputDir("damaged_video_repeat");
    cv::Mat a(32, 48, CV_8UC3), b(32, 48, CV_8UC3);
    cv::randu(a, 0, 256);
    cv::randu(b, 0, 256);
    std::vector<uint8_t> ja, jb;
    cv::imencode(".jpg", a, ja);
    cv::imencode(".jpg", b, jb);
    {
        MatroskaWriter w(dir / "v.mkv", 30, 90);
        w.appendJpeg(ja, 48, 32, 0.0);
        w.appendJpeg(jb, 48, 32, 1 / 30.0);
        w.appendJpeg(jb, 48, 32, 2 / 30.0);  // a duplicated frame
        w.appendJpeg(ja, 48, 32, 3 / 30.0);
    }
    const Decoded d = readAllFrames(dir / "v.mkv");
    ASSERT_EQ(d.frames.size(), 4u);
    for (const auto& f : d.frames) EXPECT_FALSE(f.empty());
    EXPECT_TRUE(d.problems[1].empty());
    EXPECT_NE(d.problems[2].find("repeats frame 1 exactly"), std::string::npos) << d.problems[2];
    EXPECT_TRUE(d.problems[3].empty()) << d.problems[3];
}

// ---- AVI: no checksums, no per-frame times; the same promise ----------------------------------

// The sample's JPEGs (without the cluster checksums: those are Matroska's) in an AVI.
struct AviOriginal {
    std::vector<std::string> jpegs;
    std::string bytes;
    AviScan scan;
    Decoded decoded;
};

const AviOriginal& aviOriginal() {
    static const AviOriginal o = [] {
        AviOriginal r;
        r.jpegs = test::matroskaJpegs(sampleVideo());
        r.bytes = test::mjpegAviBytes(r.jpegs, 640, 480, 12.0);
        const fs::path path = test::outputDirForThisTest("damaged_avi_original") / "main.avi";
        std::ofstream(path, std::ios::binary) << r.bytes;
        r.scan = scanAvi(path);
        r.decoded = readAllFrames(path);
        return r;
    }();
    return o;
}

struct AviOutcome {
    int delivered = 0, lost = 0, wrong = 0, valueDamage = 0, intactMissing = 0;
    std::vector<std::string> problems;  // of the intact frames that were lost
};

// Every frame delivered must be the recorded one (or differ only by changed coefficient values
// inside its entropy-coded data, which no JPEG check can see), every other frame lost with a
// reason; a frame whose chunk and index entry are untouched must be delivered.
AviOutcome checkAvi(const std::string& damaged, const std::string& name) {
    const AviOriginal& o = aviOriginal();
    const fs::path path = test::outputDir("damaged_avi_" + name) / "main.avi";
    std::ofstream(path, std::ios::binary) << damaged;
    const Decoded d = readAllFrames(path);
    AviOutcome r;
    EXPECT_LE(d.frames.size(), o.decoded.frames.size()) << name;
    const size_t moviFourcc = o.bytes.find("movi");
    const size_t idx1 = o.bytes.rfind("idx1");
    for (size_t i = 0; i < d.frames.size() && i < o.decoded.frames.size(); ++i) {
        const AviFrame& c = o.scan.frames[i];
        const size_t entry = idx1 + 8 + 16 * i;
        const bool intact =
            c.offset + c.size <= damaged.size() &&
            o.bytes.compare(size_t(c.offset - 8), size_t(c.size + 8), damaged, size_t(c.offset - 8),
                            size_t(c.size + 8)) == 0 &&
            (entry + 16 > damaged.size() || o.bytes.compare(entry, 16, damaged, entry, 16) == 0) &&
            o.bytes.compare(0, moviFourcc + 4, damaged, 0, moviFourcc + 4) == 0;
        if (d.frames[i].empty()) {
            ++r.lost;
            EXPECT_FALSE(d.problems[i].empty()) << name << ": frame " << i << " lost silently";
            r.intactMissing += intact;
            if (intact) r.problems.push_back(d.problems[i]);
            continue;
        }
        ++r.delivered;
        if (test::percentileAbsDiff(d.frames[i], o.decoded.frames[i], 1.0) > 1.0) {
            const std::string jpeg = o.jpegs[i];
            const size_t sos = jpeg.find("\xFF\xDA");
            const size_t dataStart =
                sos + 2 + (size_t(uint8_t(jpeg[sos + 2])) << 8 | uint8_t(jpeg[sos + 3]));
            const size_t eoi = jpeg.rfind("\xFF\xD9");
            bool onlyValues = true;
            for (size_t k = 0; k < jpeg.size(); ++k)
                if (damaged[size_t(c.offset) + k] != jpeg[k] && (k < dataStart || k >= eoi))
                    onlyValues = false;
            if (onlyValues) {
                ++r.valueDamage;
                continue;
            }
            ++r.wrong;
            ADD_FAILURE() << name << ": frame " << i << " delivered but differs from the recording";
        }
    }
    return r;
}

TEST(DamagedVideo, AviCopyOfTheSampleDecodesExactly) {
    const AviOriginal& o = aviOriginal();
    EXPECT_TRUE(o.scan.hasIndex);
    EXPECT_TRUE(o.scan.problem.empty()) << o.scan.problem;
    ASSERT_EQ(o.decoded.frames.size(), 36u);
    for (size_t i = 0; i < 36; ++i) {
        ASSERT_FALSE(o.decoded.frames[i].empty()) << o.decoded.problems[i];
        EXPECT_LE(test::percentileAbsDiff(o.decoded.frames[i], original().decoded.frames[i], 1.0),
                  0.0);
    }
    EXPECT_NEAR(o.scan.frames[12].seconds, 1.0, 1e-9);  // 12 fps
    // FFmpeg reads the file as the same 36 frames: the layout is AVI as others write it.
    const fs::path copy = test::outputDirForThisTest("damaged_avi_ffmpeg") / "main.avi";
    std::ofstream(copy, std::ios::binary) << o.bytes;
    cv::VideoCapture cap(copy.string(), cv::CAP_FFMPEG);
    int n = 0;
    for (cv::Mat m; cap.read(m);) ++n;
    EXPECT_EQ(n, 36);
}

TEST(DamagedVideo, AviByteFlipsGiveRightFramesOrLostOnes) {
    // FFmpeg conceals damaged MJPEG and can repeat the previous picture for a frame it cannot
    // decode: tracking then reported confident wrong poses. Now AVI frames go through the same
    // strict path as Matroska ones.
    for (uint32_t seed : {1u, 2u, 3u}) {
        const AviOutcome r =
            checkAvi(flipBytes(aviOriginal().bytes, 200, seed), "flip200_" + std::to_string(seed));
        EXPECT_EQ(r.wrong, 0) << "seed " << seed;
        EXPECT_EQ(r.intactMissing, 0) << "seed " << seed;
        EXPECT_GT(r.lost, 0) << "seed " << seed;
        EXPECT_LT(r.valueDamage, r.lost) << "seed " << seed;
        std::printf("AVI, 200 flips, seed %u: %d delivered, %d lost, %d damaged in value bits\n",
                    seed, r.delivered, r.lost, r.valueDamage);
    }
    // Fewer flips, more seeds: single damaged frames among intact ones.
    int lost = 0, delivered = 0;
    for (uint32_t seed = 10; seed < 15; ++seed) {
        const AviOutcome r =
            checkAvi(flipBytes(aviOriginal().bytes, 4, seed), "flip4_" + std::to_string(seed));
        EXPECT_EQ(r.wrong, 0) << "seed " << seed;
        EXPECT_EQ(r.intactMissing, 0) << "seed " << seed;
        for (const std::string& p : r.problems) std::printf("seed %u: %s\n", seed, p.c_str());
        lost += r.lost;
        delivered += r.delivered;
    }
    EXPECT_GT(delivered, 5 * 30);
    EXPECT_GT(lost, 0);
}

TEST(DamagedVideo, AviDamagedChunkHeaderKeepsLaterFramesOnTheirNumbers) {
    const AviOriginal& o = aviOriginal();
    std::string bytes = o.bytes;
    const uint64_t at = o.scan.frames[20].offset - 8;  // frame 20's chunk header
    for (uint64_t i = at; i < at + 8; ++i) bytes[size_t(i)] = char(0x00);
    const AviOutcome r = checkAvi(bytes, "header20");
    EXPECT_EQ(r.wrong, 0);
    EXPECT_EQ(r.lost, 1);
    EXPECT_EQ(r.delivered, 35);  // frames 21..35 found through the index, on their numbers
    const fs::path copy = test::outputDir("damaged_avi_header20_read") / "main.avi";
    std::ofstream(copy, std::ios::binary) << bytes;
    const Decoded d = readAllFrames(copy);
    ASSERT_EQ(d.frames.size(), 36u);
    EXPECT_TRUE(d.frames[20].empty());
    EXPECT_NE(d.problems[20].find("frame 20 lost"), std::string::npos) << d.problems[20];

    // Without an index nothing after the damage can be numbered: lost, with the reason.
    std::string noIndex = test::mjpegAviBytes(o.jpegs, 640, 480, 12.0, false);
    for (uint64_t i = at; i < at + 8; ++i) noIndex[size_t(i)] = char(0x00);
    const fs::path path = test::outputDir("damaged_avi_noindex") / "main.avi";
    std::ofstream(path, std::ios::binary) << noIndex;
    const FrameInventory inv = inventoryFrames(path);
    EXPECT_EQ(inv.videoFrames, 20);
    const Decoded n = readAllFrames(path);
    ASSERT_EQ(n.frames.size(), 20u);
    for (size_t i = 0; i < 20; ++i)
        EXPECT_LE(test::percentileAbsDiff(n.frames[i], o.decoded.frames[i], 1.0), 0.0);
}

TEST(DamagedVideo, AviCutAtEveryTenthKeepsRightFrames) {
    const AviOriginal& o = aviOriginal();
    for (int k = 1; k < 10; ++k) {
        const AviOutcome r =
            checkAvi(o.bytes.substr(0, o.bytes.size() * size_t(k) / 10), "cut" + std::to_string(k));
        EXPECT_EQ(r.wrong, 0) << k;
        EXPECT_EQ(r.lost, 0) << k;  // a cut file simply ends earlier (its index is gone)
        EXPECT_GE(r.delivered, 36 * (k - 1) / 10) << k;
    }
}

}  // namespace
}  // namespace mirage
