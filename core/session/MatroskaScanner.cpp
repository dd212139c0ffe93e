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

MatroskaScan scanMatroska(std::istream& in, uint64_t fileSize, const std::string& name) {
    const std::filesystem::path path(name);  // for messages only
    MatroskaScan r;
    if (fileSize == 0) {
        r.problem = "the file is empty (recording stopped before the first frame)";
        r.truncated = true;
        return r;
    }
    Cursor c(in, fileSize);

    const auto ebml = c.header(0);
    if (!ebml || ebml->id != kEbml || ebml->size == kUnknown)
        throw FileError(path.string(), "not a Matroska file (no EBML header)");
    std::string docType;
    for (uint64_t p = ebml->dataStart; p < ebml->end(fileSize);) {
        const auto e = c.header(p);
        if (!e || e->size == kUnknown) break;
        if (e->id == kDocType) docType = c.readString(*e);
        p = e->end(fileSize);
    }
    if (docType != "matroska" && docType != "webm")
        throw FileError(path.string(), "not a Matroska file (DocType '" + docType + "')");

    const auto segment = c.header(ebml->end(fileSize));
    if (!segment || segment->id != kSegment) {
        r.problem = "no Segment after the EBML header";
        r.truncated = !segment.has_value();
        return r;
    }
    const uint64_t segEnd = std::min(segment->end(fileSize), fileSize);
    // A Segment of known size that runs past the end: the file was cut (checked at the end, so
    // that the complete clusters before the cut are still counted).
    const bool segmentCut = segment->size != kUnknown && segment->end(fileSize) > fileSize;

    uint64_t videoTrack = 0;  // 0 = not known yet: count every block
    std::set<uint64_t> knownTracks;
    uint64_t p = segment->dataStart;
    uint64_t timestampScaleNs = 1'000'000;
    uint64_t clusterTicks = 0;
    bool afterGap = false;  // the next block follows damaged bytes
    // Damage: skip to the next Cluster whose header and first child parse, and record the gap.
    // Returns false if no cluster follows (the damage runs to the end of the file).
    auto resync = [&](uint64_t damagedAt, const std::string& what) {
        const auto next = nextCluster(c, damagedAt + 1, segEnd);
        MatroskaGap g;
        g.begin = damagedAt;
        g.end = next.value_or(fileSize);
        g.what = what;
        r.gaps.push_back(g);
        afterGap = true;
        if (!next) return false;
        p = *next;
        return true;
    };
    auto addBlock = [&](const Element& b, uint64_t track, uint64_t headerBytes, int16_t relTicks,
                        uint8_t flags) {
        MatroskaBlock blk;
        blk.offset = b.dataStart + headerBytes;
        blk.size = b.size > headerBytes ? b.size - headerBytes : 0;
        blk.laced = (flags & 0x06) != 0;
        const int64_t ticks = int64_t(clusterTicks) + relTicks;
        blk.seconds = double(ticks) * double(timestampScaleNs) * 1e-9;
        blk.afterGap = afterGap;
        afterGap = false;
        (void)track;
        r.blocks.push_back(blk);
    };

    while (p < segEnd) {
        const auto e = c.header(p);
        if (!e) {
            // Too few bytes left for a header: the file was cut. Otherwise the bytes are damaged.
            if (fileSize - p < 12 || !resync(p, "unreadable element header")) {
                if (fileSize - p < 12) r.truncated = true;
                break;
            }
            continue;
        }
        if (!isTopLevel(e->id) && e->id != 0xEC /*Void*/ && e->id != 0xBF /*CRC-32*/) {
            char idHex[16];
            std::snprintf(idHex, sizeof idHex, "0x%X", unsigned(e->id));
            if (!resync(p, std::string("unknown element ") + idHex + " at segment level")) break;
            continue;
        }
        if (e->id == 0x1549A966 /*Info*/ && e->size != kUnknown) {
            for (uint64_t q = e->dataStart; q < std::min(e->end(segEnd), segEnd);) {
                const auto f = c.header(q);
                if (!f || f->size == kUnknown) break;
                if (f->id == 0x2AD7B1 /*TimestampScale*/) {
                    const uint64_t v = c.readUint(*f);
                    if (v > 0 && v <= 1'000'000'000) timestampScaleNs = v;
                }
                q = f->end(segEnd);
            }
        }
        if (e->id == kTracks) {
            for (uint64_t q = e->dataStart; q < std::min(e->end(segEnd), segEnd);) {
                const auto t = c.header(q);
                if (!t || t->size == kUnknown) break;
                if (t->id == kTrackEntry) {
                    uint64_t number = 0, type = 0;
                    std::string codec;
                    int w = 0, h = 0;
                    for (uint64_t s = t->dataStart; s < t->end(segEnd);) {
                        const auto f = c.header(s);
                        if (!f || f->size == kUnknown) break;
                        if (f->id == kTrackNumber) number = c.readUint(*f);
                        if (f->id == kTrackType) type = c.readUint(*f);
                        if (f->id == kCodecId) codec = c.readString(*f);
                        if (f->id == kVideo) {
                            for (uint64_t v = f->dataStart; v < f->end(segEnd);) {
                                const auto g = c.header(v);
                                if (!g || g->size == kUnknown) break;
                                if (g->id == kPixelWidth) w = int(c.readUint(*g));
                                if (g->id == kPixelHeight) h = int(c.readUint(*g));
                                v = g->end(segEnd);
                            }
                        }
                        s = f->end(segEnd);
                    }
                    if (number != 0) knownTracks.insert(number);
                    if (type == 1 && videoTrack == 0) {
                        videoTrack = number;
                        r.codecId = codec;
                        r.width = w;
                        r.height = h;
                    }
                }
                q = t->end(segEnd);
            }
        }
        if (e->id == kCluster) {
            // Children until the cluster's end, or for an unknown size until the next
            // top-level element.
            const uint64_t clusterEnd = e->end(segEnd);
            uint64_t q = e->dataStart;
            bool damaged = false;
            std::optional<uint32_t> clusterCrc;
            std::pair<uint64_t, uint64_t> crcRange{0, 0};
            const size_t firstBlock = r.blocks.size();
            while (q < std::min(clusterEnd, segEnd)) {
                const auto b = c.header(q);
                if (!b) {
                    if (fileSize - q < 12) {
                        r.truncated = true;
                    } else {
                        damaged = true;
                    }
                    break;
                }
                if (e->size == kUnknown && isTopLevel(b->id)) break;
                if (!isClusterChild(b->id) || b->size == kUnknown) {
                    damaged = true;
                    break;
                }
                if (b->end(segEnd) > fileSize) {
                    // Runs past the end: cut short, unless a cluster follows (a damaged size).
                    if (nextCluster(c, q + 1, segEnd)) {
                        damaged = true;
                    } else {
                        r.truncated = true;
                    }
                    break;
                }
                if (e->size != kUnknown && b->end(segEnd) > clusterEnd) {
                    damaged = true;
                    break;
                }
                if (b->id == kClusterTimestamp) clusterTicks = c.readUint(*b);
                // A CRC-32 first in a cluster of known size covers the rest of the cluster.
                if (b->id == 0xBF && q == e->dataStart && b->size == 4 && e->size != kUnknown) {
                    uint8_t v[4];
                    if (c.read(b->dataStart, v, 4)) {
                        clusterCrc = uint32_t(v[0]) | uint32_t(v[1]) << 8 | uint32_t(v[2]) << 16 |
                                     uint32_t(v[3]) << 24;
                        crcRange = {b->end(segEnd), clusterEnd};
                    }
                }
                const Element* blockElement = nullptr;
                std::optional<Element> inner;
                if (b->id == kSimpleBlock) blockElement = &*b;
                if (b->id == kBlockGroup) {
                    for (uint64_t s = b->dataStart; s < b->end(segEnd);) {
                        const auto f = c.header(s);
                        if (!f || f->size == kUnknown) break;
                        if (f->id == kBlock) inner = f;
                        s = f->end(segEnd);
                    }
                    if (inner) blockElement = &*inner;
                }
                if (blockElement) {
                    const BlockHead h = c.blockHead(*blockElement);
                    if (h.track != 0 && (videoTrack == 0 || h.track == videoTrack)) {
                        ++r.completeFrames;
                        addBlock(*blockElement, h.track, h.headerBytes, h.relTicks, h.flags);
                    } else if (videoTrack != 0 && !knownTracks.count(h.track)) {
                        // A block of no track: its track number was damaged. It still takes
                        // its place in the video (a lost frame), so later frames keep theirs.
                        ++r.completeFrames;
                        addBlock(*blockElement, h.track, h.headerBytes, h.relTicks, h.flags);
                        r.blocks.back().damaged = "its track number is damaged";
                    }
                }
                q = b->end(segEnd);
            }
            if (clusterCrc)
                for (size_t k = firstBlock; k < r.blocks.size(); ++k) {
                    r.blocks[k].hasCrc = true;
                    r.blocks[k].crc = *clusterCrc;
                    r.blocks[k].crcBegin = crcRange.first;
                    r.blocks[k].crcEnd = crcRange.second;
                }
            if (damaged) {
                if (!resync(q, "damaged cluster")) break;
                continue;
            }
            // A cluster of known size that runs past the end of the file was cut, even when
            // the cut falls between two of its children.
            if (e->size != kUnknown && clusterEnd > fileSize) r.truncated = true;
            if (r.truncated) break;
            p = e->size == kUnknown ? q : clusterEnd;
            continue;
        }
        if (e->size == kUnknown) {
            char idHex[16];
            std::snprintf(idHex, sizeof idHex, "0x%X", unsigned(e->id));
            r.problem =
                std::string("element ") + idHex + " of unknown size at byte " + std::to_string(p);
            break;
        }
        if (e->end(segEnd) > fileSize) {
            if (nextCluster(c, p + 1, segEnd)) {
                if (!resync(p, "element size runs past the end of the file")) break;
                continue;
            }
            r.truncated = true;
            break;
        }
        p = e->end(segEnd);
    }
    assignPositions(r);
    for (const MatroskaGap& g : r.gaps) {
        std::string lost = "no frame lost";
        if (g.lastLost >= g.firstLost)
            lost = g.firstLost == g.lastLost ? "frame " + std::to_string(g.firstLost) + " lost"
                                             : "frames " + std::to_string(g.firstLost) + "-" +
                                                   std::to_string(g.lastLost) + " lost";
        else if (g.end >= fileSize)
            lost = "the frames after frame " + std::to_string(g.firstLost - 1) + " lost";
        r.problem += std::string(r.problem.empty() ? "" : "; ") + "bytes " +
                     std::to_string(g.begin) + "-" + std::to_string(g.end) + " damaged (" + g.what +
                     ")" + (g.end < fileSize ? ", resumed at the next cluster" : "") + ": " + lost;
    }
    r.truncated = r.truncated || segmentCut;
    if (r.truncated && r.problem.empty())
        r.problem = "the file ends in the middle of an element (cut short, e.g. by a crash)";
    return r;
}

}  // namespace mirage
