#include "core/session/MatroskaScanner.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <istream>
#include <optional>
#include <set>
#include <vector>

#include "core/Error.h"

namespace mirage {

namespace {

constexpr uint32_t kEbml = 0x1A45DFA3, kDocType = 0x4282, kSegment = 0x18538067,
                   kTracks = 0x1654AE6B, kTrackEntry = 0xAE, kTrackNumber = 0xD7, kTrackType = 0x83,
                   kCodecId = 0x86, kVideo = 0xE0, kPixelWidth = 0xB0, kPixelHeight = 0xBA,
                   kCluster = 0x1F43B675, kSimpleBlock = 0xA3, kBlockGroup = 0xA0, kBlock = 0xA1,
                   kClusterTimestamp = 0xE7;
constexpr uint64_t kUnknown = ~uint64_t(0);

// IDs that may follow a Cluster at Segment level; they end an unknown-size Cluster.
bool isTopLevel(uint32_t id) {
    return id == kCluster || id == 0x1549A966 /*Info*/ || id == kTracks ||
           id == 0x1C53BB6B /*Cues*/ || id == 0x114D9B74 /*SeekHead*/ ||
           id == 0x1254C367 /*Tags*/ || id == 0x1941A469 /*Attachments*/ ||
           id == 0x1043A770 /*Chapters*/ || id == kSegment || id == kEbml;
}

// IDs a Cluster may hold (Matroska spec): Timestamp, SilentTracks, Position, PrevSize,
// SimpleBlock, BlockGroup, EncryptedBlock, and the global Void and CRC-32.
bool isClusterChild(uint32_t id) {
    return id == kClusterTimestamp || id == 0x5854 || id == 0xA7 || id == 0xAB ||
           id == kSimpleBlock || id == kBlockGroup || id == 0xAF || id == 0xEC || id == 0xBF;
}

struct BlockHead {
    uint64_t track = 0;
    uint64_t headerBytes = 0;  // track number vint + int16 time + flags
    int16_t relTicks = 0;
    uint8_t flags = 0;
};

struct Element {
    uint32_t id = 0;
    uint64_t dataStart = 0;
    uint64_t size = 0;  // kUnknown for "unknown size"
    uint64_t end(uint64_t limit) const { return size == kUnknown ? limit : dataStart + size; }
};

class Cursor {
public:
    Cursor(std::istream& in, uint64_t fileSize) : in_(in), fileSize_(fileSize) {}
    uint64_t fileSize() const { return fileSize_; }

    // Reads an element header at `pos`; nullopt if it does not fit in the file or is invalid.
    std::optional<Element> header(uint64_t pos) {
        uint8_t b[12];
        const uint64_t avail = std::min<uint64_t>(12, fileSize_ > pos ? fileSize_ - pos : 0);
        if (avail < 2) return std::nullopt;
        if (!read(pos, b, avail)) return std::nullopt;
        const int idLen = vintLength(b[0]);
        if (idLen < 1 || idLen > 4 || uint64_t(idLen) >= avail) return std::nullopt;
        uint32_t id = 0;
        for (int i = 0; i < idLen; ++i) id = (id << 8) | b[i];
        const int sizeLen = vintLength(b[idLen]);
        if (sizeLen < 1 || sizeLen > 8 || uint64_t(idLen + sizeLen) > avail) return std::nullopt;
        uint64_t size = b[idLen] & (0xFF >> sizeLen);
        bool allOnes = size == uint64_t(0xFF >> sizeLen);
        for (int i = 1; i < sizeLen; ++i) {
            size = (size << 8) | b[idLen + i];
            allOnes = allOnes && b[idLen + i] == 0xFF;
        }
        return Element{id, pos + uint64_t(idLen + sizeLen), allOnes ? kUnknown : size};
    }

    bool read(uint64_t pos, uint8_t* out, uint64_t n) {
        in_.clear();
        in_.seekg(std::streamoff(pos));
        in_.read(reinterpret_cast<char*>(out), std::streamsize(n));
        return uint64_t(in_.gcount()) == n;
    }

    uint64_t readUint(const Element& e) {
        uint8_t b[8];
        if (e.size == 0 || e.size > 8 || !read(e.dataStart, b, e.size)) return 0;
        uint64_t v = 0;
        for (uint64_t i = 0; i < e.size; ++i) v = (v << 8) | b[i];
        return v;
    }

    std::string readString(const Element& e) {
        if (e.size > 4096) return {};
        std::string s(e.size, '\0');
        if (!read(e.dataStart, reinterpret_cast<uint8_t*>(s.data()), e.size)) return {};
        return s.substr(0, s.find('\0'));
    }

    // Track number, relative time and flags at the start of a (Simple)Block.
    BlockHead blockHead(const Element& e) {
        uint8_t b[11];
        const uint64_t n = std::min<uint64_t>(11, e.size);
        if (n == 0 || !read(e.dataStart, b, n)) return {};
        const int len = vintLength(b[0]);
        if (len < 1 || uint64_t(len) + 3 > n) return {};
        uint64_t v = b[0] & (0xFF >> len);
        for (int i = 1; i < len; ++i) v = (v << 8) | b[i];
        BlockHead h;
        h.track = v;
        h.headerBytes = uint64_t(len) + 3;
        h.relTicks = int16_t(uint16_t(b[len] << 8 | b[len + 1]));
        h.flags = b[len + 2];
        return h;
    }

private:
    static int vintLength(uint8_t first) {
        for (int i = 0; i < 8; ++i)
            if (first & (0x80 >> i)) return i + 1;
        return 0;
    }
    std::istream& in_;
    uint64_t fileSize_;
};

// The first Cluster at or after `from` whose header parses and whose first child is a Timestamp
// or a CRC-32:
// where reading resumes after damaged bytes.
std::optional<uint64_t> nextCluster(Cursor& c, uint64_t from, uint64_t limit) {
    constexpr uint64_t kChunk = 1 << 16;
    std::vector<uint8_t> buf(kChunk + 3);
    for (uint64_t pos = from; pos + 4 <= limit; pos += kChunk) {
        const uint64_t n = std::min<uint64_t>(kChunk + 3, limit - pos);
        if (!c.read(pos, buf.data(), n)) return std::nullopt;
        for (uint64_t i = 0; i + 4 <= n; ++i) {
            if (buf[i] != 0x1F || buf[i + 1] != 0x43 || buf[i + 2] != 0xB6 || buf[i + 3] != 0x75)
                continue;
            const auto e = c.header(pos + i);
            if (!e || e->id != kCluster) continue;
            const auto first = c.header(e->dataStart);
            if (first && first->id == kClusterTimestamp && first->size >= 1 && first->size <= 8)
                return pos + i;
            if (first && first->id == 0xBF /*CRC-32*/ && first->size == 4) return pos + i;
        }
    }
    return std::nullopt;
}

// Frame numbers: one after the other, and across damaged bytes as many as the time between the
// blocks either side holds (at the median frame period of the undamaged stretches).
void assignPositions(MatroskaScan& r) {
    std::vector<double> periods;
    for (size_t i = 1; i < r.blocks.size(); ++i)
        if (!r.blocks[i].afterGap) periods.push_back(r.blocks[i].seconds - r.blocks[i - 1].seconds);
    double period = 0;
    if (!periods.empty()) {
        std::nth_element(periods.begin(), periods.begin() + long(periods.size() / 2),
                         periods.end());
        period = periods[periods.size() / 2];
    }
    int next = 0;
    for (size_t i = 0; i < r.blocks.size(); ++i) {
        MatroskaBlock& b = r.blocks[i];
        int position = next;
        if (b.afterGap && i > 0 && period > 0) {
            const double steps = (b.seconds - r.blocks[i - 1].seconds) / period;
            // A damaged time would move every later frame; then only one step is assumed.
            if (std::isfinite(steps) && steps >= 1 && steps < 1e6)
                position = r.blocks[i - 1].position + int(std::lround(steps));
        }
        b.position = position;
        next = position + 1;
    }
    // What each gap cost, in frames, for the report.
    size_t bi = 0;
    for (MatroskaGap& g : r.gaps) {
        while (bi < r.blocks.size() && r.blocks[bi].offset < g.begin) ++bi;
        g.firstLost = bi > 0 ? r.blocks[bi - 1].position + 1 : 0;
        g.lastLost = bi < r.blocks.size() ? r.blocks[bi].position - 1 : -1;
    }
}

}  // namespace

uint32_t crc32Ieee(const uint8_t* data, size_t size) {
    static const auto table = [] {
        std::array<uint32_t, 256> t{};
        for (uint32_t i = 0; i < 256; ++i) {
            uint32_t c = i;
            for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            t[i] = c;
        }
        return t;
    }();
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

MatroskaScan scanMatroska(const std::filesystem::path& path) {
    std::error_code ec;
    const uint64_t fileSize = std::filesystem::file_size(path, ec);
    if (ec) throw FileError(path.string(), "cannot open video: " + ec.message());
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open video for reading");
    return scanMatroska(in, fileSize, path.string());
}

namespace {

// One pass over a Matroska file: the header, then the Segment's elements in order, resynchronising
// at the next Cluster after damaged bytes.
class MatroskaWalker {
public:
    MatroskaWalker(std::istream& in, uint64_t fileSize, const std::string& name)
        : c_(in, fileSize), fileSize_(fileSize), path_(name) {}

    MatroskaScan scan() {
        if (fileSize_ == 0) {
            r_.problem = "the file is empty (recording stopped before the first frame)";
            r_.truncated = true;
            return r_;
        }
        const auto segment = readHeader();
        if (!segment || segment->id != kSegment) {
            r_.problem = "no Segment after the EBML header";
            r_.truncated = !segment.has_value();
            return r_;
        }
        segEnd_ = std::min(segment->end(fileSize_), fileSize_);
        // A Segment of known size that runs past the end: the file was cut (checked at the end,
        // so that the complete clusters before the cut are still counted).
        const bool segmentCut = segment->size != kUnknown && segment->end(fileSize_) > fileSize_;
        p_ = segment->dataStart;
        while (p_ < segEnd_ && step()) {
        }
        assignPositions(r_);
        describeGaps();
        r_.truncated = r_.truncated || segmentCut;
        if (r_.truncated && r_.problem.empty())
            r_.problem = "the file ends in the middle of an element (cut short, e.g. by a crash)";
        return r_;
    }

private:
    // The EBML header (DocType matroska or webm), and the element after it.
    std::optional<Element> readHeader() {
        const auto ebml = c_.header(0);
        if (!ebml || ebml->id != kEbml || ebml->size == kUnknown)
            throw FileError(path_.string(), "not a Matroska file (no EBML header)");
        std::string docType;
        for (uint64_t p = ebml->dataStart; p < ebml->end(fileSize_);) {
            const auto e = c_.header(p);
            if (!e || e->size == kUnknown) break;
            if (e->id == kDocType) docType = c_.readString(*e);
            p = e->end(fileSize_);
        }
        if (docType != "matroska" && docType != "webm")
            throw FileError(path_.string(), "not a Matroska file (DocType '" + docType + "')");
        return c_.header(ebml->end(fileSize_));
    }

    static std::string hexId(uint32_t id) {
        char idHex[16];
        std::snprintf(idHex, sizeof idHex, "0x%X", unsigned(id));
        return idHex;
    }

    // One Segment-level element at p_; false when the walk ends.
    bool step() {
        const auto e = c_.header(p_);
        if (!e) {
            // Too few bytes left for a header: the file was cut. Otherwise the bytes are damaged.
            if (fileSize_ - p_ < 12) {
                r_.truncated = true;
                return false;
            }
            return resync(p_, "unreadable element header");
        }
        if (!isTopLevel(e->id) && e->id != 0xEC /*Void*/ && e->id != 0xBF /*CRC-32*/)
            return resync(p_, "unknown element " + hexId(e->id) + " at segment level");
        if (e->id == 0x1549A966 /*Info*/ && e->size != kUnknown) readInfo(*e);
        if (e->id == kTracks) readTracks(*e);
        if (e->id == kCluster) return walkCluster(*e);
        if (e->size == kUnknown) {
            r_.problem =
                "element " + hexId(e->id) + " of unknown size at byte " + std::to_string(p_);
            return false;
        }
        if (e->end(segEnd_) > fileSize_) {
            if (nextCluster(c_, p_ + 1, segEnd_))
                return resync(p_, "element size runs past the end of the file");
            r_.truncated = true;
            return false;
        }
        p_ = e->end(segEnd_);
        return true;
    }

    // Damage: skip to the next Cluster whose header and first child parse, and record the gap.
    // Returns false if no cluster follows (the damage runs to the end of the file).
    bool resync(uint64_t damagedAt, const std::string& what) {
        const auto next = nextCluster(c_, damagedAt + 1, segEnd_);
        MatroskaGap g;
        g.begin = damagedAt;
        g.end = next.value_or(fileSize_);
        g.what = what;
        r_.gaps.push_back(g);
        afterGap_ = true;
        if (!next) return false;
        p_ = *next;
        return true;
    }

    void readInfo(const Element& e) {
        for (uint64_t q = e.dataStart; q < std::min(e.end(segEnd_), segEnd_);) {
            const auto f = c_.header(q);
            if (!f || f->size == kUnknown) break;
            if (f->id == 0x2AD7B1 /*TimestampScale*/) {
                const uint64_t v = c_.readUint(*f);
                if (v > 0 && v <= 1'000'000'000) timestampScaleNs_ = v;
            }
            q = f->end(segEnd_);
        }
    }

    void readTracks(const Element& e) {
        for (uint64_t q = e.dataStart; q < std::min(e.end(segEnd_), segEnd_);) {
            const auto t = c_.header(q);
            if (!t || t->size == kUnknown) break;
            if (t->id == kTrackEntry) readTrackEntry(*t);
            q = t->end(segEnd_);
        }
    }

    // The first video track is the one whose frames are listed.
    void readTrackEntry(const Element& t) {
        uint64_t number = 0, type = 0;
        std::string codec;
        int w = 0, h = 0;
        for (uint64_t s = t.dataStart; s < t.end(segEnd_);) {
            const auto f = c_.header(s);
            if (!f || f->size == kUnknown) break;
            if (f->id == kTrackNumber) number = c_.readUint(*f);
            if (f->id == kTrackType) type = c_.readUint(*f);
            if (f->id == kCodecId) codec = c_.readString(*f);
            if (f->id == kVideo) {
                for (uint64_t v = f->dataStart; v < f->end(segEnd_);) {
                    const auto g = c_.header(v);
                    if (!g || g->size == kUnknown) break;
                    if (g->id == kPixelWidth) w = int(c_.readUint(*g));
                    if (g->id == kPixelHeight) h = int(c_.readUint(*g));
                    v = g->end(segEnd_);
                }
            }
            s = f->end(segEnd_);
        }
        if (number != 0) knownTracks_.insert(number);
        if (type == 1 && videoTrack_ == 0) {
            videoTrack_ = number;
            r_.codecId = codec;
            r_.width = w;
            r_.height = h;
        }
    }

    // A Cluster's children until its end, or for an unknown size until the next top-level
    // element; false when the walk ends.
    bool walkCluster(const Element& e) {
        const uint64_t clusterEnd = e.end(segEnd_);
        uint64_t q = e.dataStart;
        bool damaged = false;
        std::optional<uint32_t> clusterCrc;
        std::pair<uint64_t, uint64_t> crcRange{0, 0};
        const size_t firstBlock = r_.blocks.size();
        while (q < std::min(clusterEnd, segEnd_)) {
            const auto b = c_.header(q);
            if (!b) {
                if (fileSize_ - q < 12)
                    r_.truncated = true;
                else
                    damaged = true;
                break;
            }
            if (e.size == kUnknown && isTopLevel(b->id)) break;
            if (!isClusterChild(b->id) || b->size == kUnknown) {
                damaged = true;
                break;
            }
            if (b->end(segEnd_) > fileSize_) {
                // Runs past the end: cut short, unless a cluster follows (a damaged size).
                if (nextCluster(c_, q + 1, segEnd_))
                    damaged = true;
                else
                    r_.truncated = true;
                break;
            }
            if (e.size != kUnknown && b->end(segEnd_) > clusterEnd) {
                damaged = true;
                break;
            }
            if (b->id == kClusterTimestamp) clusterTicks_ = c_.readUint(*b);
            // A CRC-32 first in a cluster of known size covers the rest of the cluster.
            if (b->id == 0xBF && q == e.dataStart && b->size == 4 && e.size != kUnknown) {
                uint8_t v[4];
                if (c_.read(b->dataStart, v, 4)) {
                    clusterCrc = uint32_t(v[0]) | uint32_t(v[1]) << 8 | uint32_t(v[2]) << 16 |
                                 uint32_t(v[3]) << 24;
                    crcRange = {b->end(segEnd_), clusterEnd};
                }
            }
            clusterChild(*b);
            q = b->end(segEnd_);
        }
        if (clusterCrc)
            for (size_t k = firstBlock; k < r_.blocks.size(); ++k) {
                r_.blocks[k].hasCrc = true;
                r_.blocks[k].crc = *clusterCrc;
                r_.blocks[k].crcBegin = crcRange.first;
                r_.blocks[k].crcEnd = crcRange.second;
            }
        if (damaged) return resync(q, "damaged cluster");
        // A cluster of known size that runs past the end of the file was cut, even when the cut
        // falls between two of its children.
        if (e.size != kUnknown && clusterEnd > fileSize_) r_.truncated = true;
        if (r_.truncated) return false;
        p_ = e.size == kUnknown ? q : clusterEnd;
        return true;
    }

    // A SimpleBlock, or a BlockGroup's Block, of the video track becomes a frame.
    void clusterChild(const Element& b) {
        const Element* blockElement = nullptr;
        std::optional<Element> inner;
        if (b.id == kSimpleBlock) blockElement = &b;
        if (b.id == kBlockGroup) {
            for (uint64_t s = b.dataStart; s < b.end(segEnd_);) {
                const auto f = c_.header(s);
                if (!f || f->size == kUnknown) break;
                if (f->id == kBlock) inner = f;
                s = f->end(segEnd_);
            }
            if (inner) blockElement = &*inner;
        }
        if (!blockElement) return;
        const BlockHead h = c_.blockHead(*blockElement);
        if (h.track != 0 && (videoTrack_ == 0 || h.track == videoTrack_)) {
            ++r_.completeFrames;
            addBlock(*blockElement, h);
        } else if (videoTrack_ != 0 && !knownTracks_.count(h.track)) {
            // A block of no track: its track number was damaged. It still takes its place in
            // the video (a lost frame), so later frames keep theirs.
            ++r_.completeFrames;
            addBlock(*blockElement, h);
            r_.blocks.back().damaged = "its track number is damaged";
        }
    }

    void addBlock(const Element& b, const BlockHead& h) {
        MatroskaBlock blk;
        blk.offset = b.dataStart + h.headerBytes;
        blk.size = b.size > h.headerBytes ? b.size - h.headerBytes : 0;
        blk.laced = (h.flags & 0x06) != 0;
        const int64_t ticks = int64_t(clusterTicks_) + h.relTicks;
        blk.seconds = double(ticks) * double(timestampScaleNs_) * 1e-9;
        blk.afterGap = afterGap_;
        afterGap_ = false;
        r_.blocks.push_back(blk);
    }

    void describeGaps() {
        for (const MatroskaGap& g : r_.gaps) {
            std::string lost = "no frame lost";
            if (g.lastLost >= g.firstLost)
                lost = g.firstLost == g.lastLost ? "frame " + std::to_string(g.firstLost) + " lost"
                                                 : "frames " + std::to_string(g.firstLost) + "-" +
                                                       std::to_string(g.lastLost) + " lost";
            else if (g.end >= fileSize_)
                lost = "the frames after frame " + std::to_string(g.firstLost - 1) + " lost";
            r_.problem += std::string(r_.problem.empty() ? "" : "; ") + "bytes " +
                          std::to_string(g.begin) + "-" + std::to_string(g.end) + " damaged (" +
                          g.what + ")" +
                          (g.end < fileSize_ ? ", resumed at the next cluster" : "") + ": " + lost;
        }
    }

    Cursor c_;
    uint64_t fileSize_;
    std::filesystem::path path_;  // for messages only
    MatroskaScan r_;
    uint64_t segEnd_ = 0, p_ = 0;
    uint64_t videoTrack_ = 0;  // 0 = not known yet: count every block
    std::set<uint64_t> knownTracks_;
    uint64_t timestampScaleNs_ = 1'000'000;
    uint64_t clusterTicks_ = 0;
    bool afterGap_ = false;  // the next block follows damaged bytes
};

}  // namespace

MatroskaScan scanMatroska(std::istream& in, uint64_t fileSize, const std::string& name) {
    return MatroskaWalker(in, fileSize, name).scan();
}

}  // namespace mirage
