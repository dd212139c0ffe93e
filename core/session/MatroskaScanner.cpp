#include "core/session/MatroskaScanner.h"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <istream>
#include <optional>

#include "core/Error.h"

namespace mirage {

namespace {

constexpr uint32_t kEbml = 0x1A45DFA3, kDocType = 0x4282, kSegment = 0x18538067,
                   kTracks = 0x1654AE6B, kTrackEntry = 0xAE, kTrackNumber = 0xD7, kTrackType = 0x83,
                   kCodecId = 0x86, kVideo = 0xE0, kPixelWidth = 0xB0, kPixelHeight = 0xBA,
                   kCluster = 0x1F43B675, kSimpleBlock = 0xA3, kBlockGroup = 0xA0, kBlock = 0xA1;
constexpr uint64_t kUnknown = ~uint64_t(0);

// IDs that may follow a Cluster at Segment level; they end an unknown-size Cluster.
bool isTopLevel(uint32_t id) {
    return id == kCluster || id == 0x1549A966 /*Info*/ || id == kTracks ||
           id == 0x1C53BB6B /*Cues*/ || id == 0x114D9B74 /*SeekHead*/ ||
           id == 0x1254C367 /*Tags*/ || id == 0x1941A469 /*Attachments*/ ||
           id == 0x1043A770 /*Chapters*/ || id == kSegment || id == kEbml;
}

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

    // Track number at the start of a (Simple)Block.
    uint64_t blockTrack(const Element& e) {
        uint8_t b[8];
        const uint64_t n = std::min<uint64_t>(8, e.size);
        if (n == 0 || !read(e.dataStart, b, n)) return 0;
        const int len = vintLength(b[0]);
        if (len < 1 || uint64_t(len) > n) return 0;
        uint64_t v = b[0] & (0xFF >> len);
        for (int i = 1; i < len; ++i) v = (v << 8) | b[i];
        return v;
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

}  // namespace

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
    uint64_t p = segment->dataStart;
    while (p < segEnd) {
        const auto e = c.header(p);
        if (!e) {
            r.truncated = true;
            break;
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
            while (q < std::min(clusterEnd, segEnd)) {
                const auto b = c.header(q);
                if (!b) {
                    r.truncated = true;
                    break;
                }
                if (e->size == kUnknown && isTopLevel(b->id)) break;
                if (b->size == kUnknown) {
                    r.problem = "block of unknown size at byte " + std::to_string(q);
                    return r;
                }
                if (b->end(segEnd) > fileSize) {
                    r.truncated = true;
                    break;
                }
                uint64_t track = 0;
                if (b->id == kSimpleBlock) track = c.blockTrack(*b);
                if (b->id == kBlockGroup) {
                    for (uint64_t s = b->dataStart; s < b->end(segEnd);) {
                        const auto f = c.header(s);
                        if (!f || f->size == kUnknown) break;
                        if (f->id == kBlock) track = c.blockTrack(*f);
                        s = f->end(segEnd);
                    }
                }
                if (track != 0 && (videoTrack == 0 || track == videoTrack)) ++r.completeFrames;
                q = b->end(segEnd);
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
            r.truncated = true;
            break;
        }
        p = e->end(segEnd);
    }
    r.truncated = r.truncated || segmentCut;
    if (r.truncated && r.problem.empty())
        r.problem = "the file ends in the middle of an element (cut short, e.g. by a crash)";
    return r;
}

}  // namespace mirage
