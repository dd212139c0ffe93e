#include "core/session/AviScanner.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <istream>
#include <map>
#include <optional>

#include "core/Error.h"

namespace mirage {

namespace {

uint32_t le32(const uint8_t* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

std::string fourccText(const uint8_t* p) {
    std::string s;
    for (int i = 0; i < 4; ++i) s += std::isprint(p[i]) ? char(p[i]) : '?';
    return s;
}

// FourCCs are printable ASCII (letters, digits, spaces); anything else is damage.
bool isFourcc(const uint8_t* p) {
    for (int i = 0; i < 4; ++i)
        if (!(std::isalnum(p[i]) || p[i] == ' ')) return false;
    return true;
}

struct ChunkHeader {
    uint64_t pos = 0;  // of the header
    std::string id;
    uint32_t size = 0;
    uint64_t payload() const { return pos + 8; }
    uint64_t next() const { return pos + 8 + size + (size & 1); }  // RIFF pads to even sizes
};

// A video chunk as the walk or the index found it, by chunk number.
struct VideoChunk {
    uint64_t pos = 0;
    uint32_t size = 0;
};

struct IndexEntry {
    uint32_t offset = 0, size = 0;
};

class AviWalker {
public:
    AviWalker(std::istream& in, uint64_t size, std::string name)
        : in_(in), fileSize_(size), name_(std::move(name)) {}

    AviScan scan() {
        std::array<uint8_t, 12> riff{};
        if (!read(0, riff.data(), 12) || std::string(riff.begin(), riff.begin() + 4) != "RIFF" ||
            std::string(riff.begin() + 8, riff.end()) != "AVI ")
            throw FileError(name_, "not an AVI file (no RIFF AVI header)");
        walkTopLevel();
        if (videoStream_ < 0 && result_.problem.empty())
            result_.problem = "no video stream in the AVI header";
        combine();
        return std::move(result_);
    }

private:
    bool read(uint64_t pos, uint8_t* out, uint64_t n) {
        if (pos + n > fileSize_) return false;
        in_.clear();
        in_.seekg(std::streamoff(pos));
        in_.read(reinterpret_cast<char*>(out), std::streamsize(n));
        return uint64_t(in_.gcount()) == n;
    }
    std::optional<ChunkHeader> header(uint64_t pos) {
        uint8_t b[8];
        if (!read(pos, b, 8)) return std::nullopt;
        return ChunkHeader{pos, std::string(reinterpret_cast<char*>(b), 4), le32(b + 4)};
    }
    std::string listType(const ChunkHeader& h) {
        uint8_t t[4];
        if (h.size < 4 || !read(h.payload(), t, 4)) return {};
        return std::string(reinterpret_cast<char*>(t), 4);
    }
    void note(const std::string& what) {
        if (result_.problem.empty()) result_.problem = what;
    }
    // The end of a chunk's payload, clamped to the file (a file cut short, or a recording whose
    // sizes were never filled in, reads to its end).
    uint64_t payloadEnd(const ChunkHeader& h) {
        const uint64_t end = h.payload() + h.size;
        if (end > fileSize_ || h.size == 0) {
            result_.truncated = result_.truncated || end > fileSize_;
            return fileSize_;
        }
        return end;
    }

    // RIFF 'AVI ' (then OpenDML's RIFF 'AVIX' parts): the header list, the movi lists, idx1.
    void walkTopLevel() {
        uint64_t pos = 0;
        while (pos + 12 <= fileSize_) {
            const auto riff = header(pos);
            if (!riff || riff->id != "RIFF") break;
            const std::string form = listType(*riff);
            if (form != "AVI " && form != "AVIX") break;
            const uint64_t end = payloadEnd(*riff);
            walkRiff(pos + 12, end, form == "AVI ");
            pos = end + (end & 1);
        }
    }
    void walkRiff(uint64_t pos, uint64_t end, bool first) {
        while (pos + 8 <= end) {
            const auto h = header(pos);
            if (!h || !isFourcc(reinterpret_cast<const uint8_t*>(h->id.data()))) {
                note("unreadable chunk header at byte " + std::to_string(pos));
                return;
            }
            if (h->id == "LIST") {
                const std::string type = listType(*h);
                if (type == "hdrl" && first) parseHeaderList(h->payload() + 4, payloadEnd(*h));
                if (type == "movi") {
                    if (first) moviBase_ = h->payload();
                    walkMovi(h->payload() + 4, payloadEnd(*h));
                }
            } else if (h->id == "idx1" && first) {
                readIndex(*h);
            }
            pos = h->next();
        }
    }

    void parseHeaderList(uint64_t pos, uint64_t end) {
        int stream = 0;
        while (pos + 8 <= end) {
            const auto h = header(pos);
            if (!h) return;
            if (h->id == "avih" && h->size >= 40) {
                uint8_t b[40];
                if (read(h->payload(), b, 40) && result_.secondsPerChunk <= 0)
                    result_.secondsPerChunk = le32(b) * 1e-6;  // dwMicroSecPerFrame
            } else if (h->id == "LIST" && listType(*h) == "strl") {
                parseStream(stream++, h->payload() + 4, std::min(end, h->payload() + h->size));
                streamCount_ = stream;
            }
            if (h->next() <= pos) return;
            pos = h->next();
        }
    }
    // One stream's strh (type, scale, rate) and strf (for video: BITMAPINFOHEADER).
    void parseStream(int stream, uint64_t pos, uint64_t end) {
        bool video = false;
        while (pos + 8 <= end) {
            const auto h = header(pos);
            if (!h) return;
            uint8_t b[40];
            if (h->id == "strh" && h->size >= 36 && read(h->payload(), b, 36)) {
                video = fourccText(b) == "vids" && videoStream_ < 0;
                const uint32_t scale = le32(b + 20), rate = le32(b + 24);
                if (video && scale > 0 && rate > 0) result_.secondsPerChunk = double(scale) / rate;
            } else if (h->id == "strf" && video && h->size >= 20 && read(h->payload(), b, 20)) {
                videoStream_ = stream;
                result_.width = int(le32(b + 4));
                const int32_t height = int32_t(le32(b + 8));  // negative: rows top-down
                result_.height = height < 0 ? -height : height;
                result_.compression = fourccText(b + 16);
                char digits[3];
                std::snprintf(digits, sizeof digits, "%02d", stream % 100);
                streamDigits_ = digits;
            }
            if (h->next() <= pos) return;
            pos = h->next();
        }
    }

    // Strict walk: a chunk that does not belong in a movi list, or runs past its list, stops it.
    void walkMovi(uint64_t pos, uint64_t end) {
        while (!walkBroken_ && pos + 8 <= end) {
            const auto h = header(pos);
            if (!h) break;
            const auto* id = reinterpret_cast<const uint8_t*>(h->id.data());
            if (!isFourcc(id) || (h->payload() + h->size > end && end < fileSize_)) {
                breakWalk(pos, isFourcc(id) ? "chunk '" + h->id + "' runs past its list"
                                            : "unreadable chunk header");
                return;
            }
            if (h->payload() + h->size > fileSize_) {
                result_.truncated = true;  // the last chunk is cut short
                return;
            }
            if (h->id == "idx1") {  // the movi list's size was wrong: it ends here
                readIndex(*h);
                return;
            }
            if (h->id == "LIST") {
                if (listType(*h) == "rec ") walkMovi(h->payload() + 4, h->payload() + h->size);
            } else if (isVideoChunk(h->id)) {
                walk_.push_back({h->pos, h->size});
            } else if (!isOtherChunk(h->id)) {
                breakWalk(pos, "unexpected chunk '" + h->id + "'");
                return;
            }
            pos = h->next();
        }
    }
    bool isVideoChunk(const std::string& id) const {
        return !streamDigits_.empty() && id.compare(0, 2, streamDigits_) == 0 &&
               (id.compare(2, 2, "dc") == 0 || id.compare(2, 2, "db") == 0);
    }
    // Chunks a movi list holds besides video frames: other streams' data, OpenDML index chunks,
    // padding, a video palette change.
    bool isOtherChunk(const std::string& id) const {
        if (id == "JUNK" || id.compare(0, 2, "ix") == 0) return true;
        if (!std::isdigit(static_cast<unsigned char>(id[0])) ||
            !std::isdigit(static_cast<unsigned char>(id[1])))
            return false;
        if (id.compare(0, 2, streamDigits_) == 0) return id.compare(2, 2, "pc") == 0;
        return true;
    }
    // An index entry of another stream that the header declares, or of a list; a FourCC of no
    // stream (damaged) is not.
    bool isIndexedOtherChunk(const std::string& id) const {
        if (id == "JUNK" || id == "LIST" || id == "rec " || id.compare(0, 2, "ix") == 0)
            return true;
        const auto* b = reinterpret_cast<const uint8_t*>(id.data());
        if (!isFourcc(b) || !std::isdigit(b[0]) || !std::isdigit(b[1])) return false;
        const int stream = (b[0] - '0') * 10 + (b[1] - '0');
        return stream != videoStream_ && stream < streamCount_;
    }
    void breakWalk(uint64_t pos, const std::string& what) {
        walkBroken_ = true;
        brokenAt_ = pos;
        note(what + " at byte " + std::to_string(pos));
    }

    void readIndex(const ChunkHeader& h) {
        const uint64_t avail = std::min<uint64_t>(h.size, fileSize_ - h.payload());
        if (avail < h.size) note("the index (idx1) is cut short");
        std::vector<uint8_t> bytes(size_t(avail / 16 * 16));
        if (!read(h.payload(), bytes.data(), bytes.size())) return;
        for (size_t i = 0; i < bytes.size(); i += 16) {
            const std::string id(reinterpret_cast<const char*>(&bytes[i]), 4);
            if (isVideoChunk(id)) {
                index_.push_back({le32(&bytes[i + 8]), le32(&bytes[i + 12])});
            } else if (!isIndexedOtherChunk(id)) {
                // A damaged entry keeps its place, so that the entries after it keep theirs;
                // it matches no chunk, and the walk or the loss decides for its frame.
                index_.push_back({~0u, ~0u});
            }
        }
        hasIdx1_ = true;
    }

    // idx1 offsets are relative to the 'movi' FourCC (most writers) or absolute (some): the base
    // that makes the first entries point at video chunk headers of their size.
    std::optional<uint64_t> indexBase() {
        for (const uint64_t base : {moviBase_, uint64_t(0)}) {
            int matches = 0, tried = 0;
            for (size_t k = 0; k < index_.size() && tried < 8; ++k, ++tried)
                matches += indexedChunkMatches(base, index_[k]);
            if (tried > 0 && matches * 2 > tried) return base;
        }
        return std::nullopt;
    }
    bool indexedChunkMatches(uint64_t base, const IndexEntry& e) {
        if (e.offset == ~0u) return false;  // a damaged entry
        const auto h = header(base + e.offset);
        return h && isVideoChunk(h->id) && h->size == e.size && h->payload() + h->size <= fileSize_;
    }

    // Frames by chunk number, from the walk checked against the index (see the header).
    void combine() {
        std::optional<uint64_t> base;
        if (hasIdx1_ && !index_.empty()) {
            base = indexBase();
            if (!base) note("the index (idx1) does not match the file; not used");
        }
        result_.hasIndex = base.has_value();
        const size_t chunks = std::max(walk_.size(), base ? index_.size() : 0);
        int position = 0;
        for (size_t k = 0; k < chunks; ++k) {
            std::string damaged;
            VideoChunk c;
            if (k < walk_.size() &&
                (!base || k >= index_.size() || index_[k].offset == ~0u ||
                 (*base + index_[k].offset == walk_[k].pos && index_[k].size == walk_[k].size))) {
                c = walk_[k];  // the walk found it, and the index (if any) agrees
            } else {
                // After a break in the walk, or where walk and index disagree (a damaged chunk
                // header, or a chunk the walk took for another stream's): the index locates the
                // chunk, and its header there must match.
                c = {*base + index_[k].offset, index_[k].size};
                if (!indexedChunkMatches(*base, index_[k])) {
                    damaged = k < walk_.size()
                                  ? "its chunk header and the index disagree (damaged bytes)"
                                  : "its chunk header is damaged (not what the index says)";
                    if (index_[k].offset == ~0u) {
                        damaged = "its index entry is damaged";
                    } else if (c.pos + 8 + c.size > fileSize_) {
                        damaged = "the index puts it past the end of the file";
                        ++result_.lostAtEnd;
                    }
                    // Whether it is a frame at all (or a zero-size place holder): the chunk's
                    // own header says, where it is still a video chunk header.
                    const auto h = header(c.pos);
                    if (h && isVideoChunk(h->id)) c.size = h->size;
                }
            }
            if (c.size == 0) continue;  // a place holder in time, not a frame
            result_.frames.push_back(
                {c.pos + 8, c.size, double(k) * result_.secondsPerChunk, position++, damaged});
        }
        if (walkBroken_ && !base) {
            result_.unnumberedFrom = position;
            result_.unnumberedAt = brokenAt_;
        }
        if (result_.lostAtEnd > 0)
            note(std::to_string(result_.lostAtEnd) +
                 " indexed frames are past the end of the file (cut short?)");
    }

    std::istream& in_;
    uint64_t fileSize_;
    std::string name_;
    AviScan result_;
    int videoStream_ = -1, streamCount_ = 0;
    std::string streamDigits_;
    uint64_t moviBase_ = 0;
    std::vector<VideoChunk> walk_;
    bool walkBroken_ = false;
    uint64_t brokenAt_ = 0;
    bool hasIdx1_ = false;
    std::vector<IndexEntry> index_;
};

}  // namespace

AviScan scanAvi(std::istream& in, uint64_t size, const std::string& name) {
    return AviWalker(in, size, name).scan();
}

AviScan scanAvi(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open video for reading");
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) throw FileError(path.string(), "cannot read the file size: " + ec.message());
    return scanAvi(in, size, path.string());
}

bool looksLikeAvi(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    char b[12] = {};
    if (!in.read(b, 12)) return false;
    return std::string(b, 4) == "RIFF" && std::string(b + 8, 4) == "AVI ";
}

}  // namespace mirage
