#include "core/Shards.h"

#include <algorithm>
#include <cctype>
#include <ctime>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Timestamp.h"
#include "core/session/AtomicFile.h"

namespace mirage {

namespace fs = std::filesystem;

namespace {

constexpr int kMaxShards = 100000;

bool parseWhole(const std::string& s, int& out) {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos)
        return false;
    out = std::stoi(s);
    return true;
}

std::string joinItems(const std::vector<int>& items, size_t most = 12) {
    std::string s;
    for (size_t i = 0; i < items.size() && i < most; ++i)
        s += (i ? ", " : "") + std::to_string(items[i]);
    if (items.size() > most) s += fmt::format(" ... ({} in all)", items.size());
    return s;
}

// The data rows of a CSV text (after the header line), each as (first field, FNV-1a hash).
std::vector<std::pair<std::string, std::string>> csvRows(const std::string& text) {
    std::vector<std::pair<std::string, std::string>> rows;
    size_t start = text.find('\n');
    while (start != std::string::npos && start + 1 < text.size()) {
        const size_t end = text.find('\n', start + 1);
        const std::string line =
            text.substr(start + 1, end == std::string::npos ? std::string::npos : end - start - 1);
        if (!line.empty())
            rows.emplace_back(line.substr(0, line.find(',')), hex64(fingerprint64(line)));
        start = end;
    }
    return rows;
}

std::string readAll(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open for reading");
    return std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// "frame 12" for "main/000012.png" in a shard of frames; "" when the name holds no number.
std::string itemOfFile(const std::string& path, const std::string& unit) {
    const std::string stem = fs::path(path).stem().string();
    size_t i = stem.size();
    while (i > 0 && std::isdigit(static_cast<unsigned char>(stem[i - 1]))) --i;
    if (i == stem.size()) return "";
    const std::string one =
        !unit.empty() && unit.back() == 's' ? unit.substr(0, unit.size() - 1) : unit;
    return " (" + one + " " + std::to_string(std::stoll(stem.substr(i, 9))) + ")";
}

}  // namespace

ShardSpec parseShardSpec(const std::string& text) {
    const size_t slash = text.find('/');
    ShardSpec s;
    if (slash == std::string::npos || !parseWhole(text.substr(0, slash), s.index) ||
        !parseWhole(text.substr(slash + 1), s.count) || s.count < 1 || s.count > kMaxShards ||
        s.index >= s.count)
        throw Error(fmt::format(
            "--shard '{}' must be I/N: part I (0-based) of N, with 0 <= I < N <= {} (e.g. 0/4; "
            "under a Slurm job array: $SLURM_ARRAY_TASK_ID/N)",
            text, kMaxShards));
    return s;
}

ItemRange parseItemRange(const std::string& text, const std::string& option) {
    const size_t colon = text.find(':');
    ItemRange r;
    bool ok = colon != std::string::npos;
    if (ok) {
        const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
        if (!a.empty()) ok = parseWhole(a, r.begin);
        if (ok && !b.empty()) ok = parseWhole(b, r.end);
        if (ok && r.end >= 0 && r.end <= r.begin) ok = false;
    }
    if (!ok)
        throw Error(option + " '" + text +
                    "' must be A:B (items A to B-1, 0-based, A < B), A: (from A) or :B");
    return r;
}

std::vector<int> selectItems(int total, const ItemRange& range, const ShardSpec& shard,
                             const std::string& option, const std::string& unit) {
    const int end = range.end < 0 ? total : range.end;
    if (range.begin >= total || end > total)
        throw Error(fmt::format("{} {}:{} reaches beyond the {} {} of this run (0 to {})", option,
                                range.begin, end, total, unit, total - 1));
    std::vector<int> items;
    for (int i = range.begin + shard.index; i < end; i += shard.count) items.push_back(i);
    return items;
}

std::vector<int> selectBlock(int total, const ItemRange& range, const ShardSpec& shard,
                             const std::string& option, const std::string& unit) {
    const int end = range.end < 0 ? total : range.end;
    if (range.begin >= total || end > total)
        throw Error(fmt::format("{} {}:{} reaches beyond the {} {} of this run (0 to {})", option,
                                range.begin, end, total, unit, total - 1));
    const int64_t n = end - range.begin;
    const int first = range.begin + int(n * shard.index / shard.count);
    const int last = range.begin + int(n * (shard.index + 1) / shard.count);
    std::vector<int> items;
    for (int i = first; i < last; ++i) items.push_back(i);
    return items;
}

uint64_t fingerprint64(const std::string& bytes, uint64_t h) {
    for (unsigned char c : bytes) {
        h ^= c;
        h *= 0x100000001b3ull;
    }
    return h;
}

std::string hex64(uint64_t v) {
    return fmt::format("{:016x}", v);
}

uint64_t fileFingerprint(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open for reading");
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    return fingerprint64(bytes);
}

fs::path shardsFolder(const fs::path& output) {
    fs::path p = output;
    if (!p.has_filename()) p = p.parent_path();  // "out/" -> "out"
    p += ".shards";
    return p;
}

fs::path shardFolder(const fs::path& output, const ShardSpec& shard) {
    return shardsFolder(output) / fmt::format("{}-of-{}", shard.index, shard.count);
}

void writeShardManifest(const fs::path& dir, const ShardManifest& m) {
    nlohmann::json j;
    j["format"] = kShardFormat;
    j["version"] = kShardVersion;
    j["command"] = m.command;
    j["unit"] = m.unit;
    j["shard"] = {{"index", m.shard.index}, {"count", m.shard.count}};
    j["total"] = m.total;
    j["range"] = {m.range.begin, m.range.end < 0 ? m.total : m.range.end};
    j["items"] = m.items;
    j["split"] = m.blocks ? "blocks" : "interleaved";
    j["fingerprint"] = m.fingerprint;
    j["command_line"] = m.commandLine;
    std::string created = m.createdAt;
    if (created.empty()) created = utcTimestamp();
    j["created"] = created;
    j["payload"] = m.payload;
    nlohmann::json files = nlohmann::json::array();
    for (const ShardFile& f : listShardFiles(dir)) {
        nlohmann::json e = {{"path", f.path}, {"bytes", f.bytes}, {"fnv1a64", f.hash}};
        if (!f.rows.empty()) {
            nlohmann::json rows = nlohmann::json::array();
            for (const auto& [key, hash] : f.rows) rows.push_back({key, hash});
            e["rows"] = std::move(rows);
        }
        files.push_back(std::move(e));
    }
    j["files"] = std::move(files);
    writeFileAtomically(dir / "shard.json", j.dump(1));
}

std::vector<ShardFile> listShardFiles(const fs::path& dir) {
    std::vector<ShardFile> files;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        const std::string rel = fs::relative(e.path(), dir).generic_string();
        if (rel == "shard.json") continue;
        const std::string bytes = readAll(e.path());
        ShardFile f;
        f.path = rel;
        f.bytes = bytes.size();
        f.hash = hex64(fingerprint64(bytes));
        if (e.path().extension() == ".csv") f.rows = csvRows(bytes);
        files.push_back(std::move(f));
    }
    std::sort(files.begin(), files.end(),
              [](const ShardFile& a, const ShardFile& b) { return a.path < b.path; });
    return files;
}

namespace {

// Names the first difference between the rows a CSV had when the shard was written and now.
std::string csvDifference(const ShardFile& was, const ShardFile& now, const std::string& unit) {
    const std::string one =
        !unit.empty() && unit.back() == 's' ? unit.substr(0, unit.size() - 1) : unit;
    std::map<std::string, std::string> current(now.rows.begin(), now.rows.end());
    for (const auto& [key, hash] : was.rows) {
        const auto it = current.find(key);
        if (it == current.end()) return "the row of " + one + " " + key + " was deleted";
        if (it->second != hash) return "the row of " + one + " " + key + " was changed";
        current.erase(it);
    }
    if (!current.empty())
        return "it holds a row for " + one + " " + current.begin()->first +
               " that the shard did not write";
    return "its rows are as written but in another order or with other bytes between them";
}

}  // namespace

void verifyShardFiles(const fs::path& dir, const ShardManifest& m) {
    if (m.files.empty()) return;  // a version-1 shard: nothing recorded to check against
    const std::vector<ShardFile> now = listShardFiles(dir);
    std::map<std::string, const ShardFile*> byPath;
    for (const ShardFile& f : now) byPath[f.path] = &f;
    const std::string shardName = dir.filename().string();
    for (const ShardFile& was : m.files) {
        const auto it = byPath.find(was.path);
        const std::string where = (dir / was.path).string();
        if (it == byPath.end())
            throw FileError(
                where,
                "shard " + shardName + ": missing" + itemOfFile(was.path, m.unit) +
                    "; the shard is damaged, rerun it: " + rerunCommand(m.commandLine, m.shard));
        const ShardFile& f = *it->second;
        if (f.hash != was.hash) {
            const std::string what =
                !was.rows.empty() || !f.rows.empty()
                    ? csvDifference(was, f, m.unit)
                    : "changed since the shard wrote it" + itemOfFile(was.path, m.unit);
            throw FileError(where, "shard " + shardName + ": " + what +
                                       "; the shard is damaged, rerun it: " +
                                       rerunCommand(m.commandLine, m.shard));
        }
        byPath.erase(it);
    }
    if (!byPath.empty()) {
        const std::string extra = byPath.begin()->first;
        throw FileError((dir / extra).string(),
                        "shard " + shardName + ": holds a file the shard did not write" +
                            itemOfFile(extra, m.unit) +
                            " (copied in from another shard?); remove it or rerun the shard: " +
                            rerunCommand(m.commandLine, m.shard));
    }
}

ShardManifest readShardManifest(const fs::path& dir) {
    const fs::path file = dir / "shard.json";
    std::ifstream in(file, std::ios::binary);
    if (!in) throw FileError(file.string(), "missing: the shard is incomplete (rerun it)");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
        throw FileError(file.string(), std::string("not valid JSON: ") + e.what());
    }
    auto field = [&](const char* key) -> const nlohmann::json& {
        if (!j.is_object() || !j.contains(key))
            throw FileError(file.string(), std::string("field '") + key + "' is missing");
        return j[key];
    };
    ShardManifest m;
    try {
        if (field("format") != kShardFormat)
            throw FileError(file.string(), "field 'format' is not \"mirage-shard\"");
        if (field("version").get<int>() > kShardVersion)
            throw FileError(file.string(), "written by a newer mirage (version " +
                                               std::to_string(field("version").get<int>()) +
                                               "); merge with that version");
        m.command = field("command").get<std::string>();
        m.unit = field("unit").get<std::string>();
        m.shard.index = field("shard").at("index").get<int>();
        m.shard.count = field("shard").at("count").get<int>();
        m.total = field("total").get<int>();
        m.range.begin = field("range").at(0).get<int>();
        m.range.end = field("range").at(1).get<int>();
        m.items = field("items").get<std::vector<int>>();
        const std::string split = field("split").get<std::string>();
        if (split != "blocks" && split != "interleaved")
            throw FileError(file.string(), "field 'split' must be \"blocks\" or \"interleaved\"");
        m.blocks = split == "blocks";
        m.fingerprint = field("fingerprint").get<std::string>();
        m.commandLine = field("command_line").get<std::vector<std::string>>();
        m.createdAt = field("created").get<std::string>();
        m.payload = field("payload");
        if (j.contains("files"))
            for (const auto& e : j["files"]) {
                ShardFile f;
                f.path = e.at("path").get<std::string>();
                f.bytes = e.at("bytes").get<uint64_t>();
                f.hash = e.at("fnv1a64").get<std::string>();
                if (e.contains("rows"))
                    for (const auto& r : e["rows"])
                        f.rows.emplace_back(r.at(0).get<std::string>(), r.at(1).get<std::string>());
                if (f.path.empty() || fs::path(f.path).is_absolute() ||
                    f.path.find("..") != std::string::npos)
                    throw FileError(file.string(), "field 'files' names '" + f.path +
                                                       "', outside the shard folder");
                m.files.push_back(std::move(f));
            }
    } catch (const nlohmann::json::exception& e) {
        throw FileError(file.string(), std::string("a field has the wrong type: ") + e.what());
    }
    if (m.shard.count < 1 || m.shard.index < 0 || m.shard.index >= m.shard.count || m.total < 1 ||
        m.range.begin < 0 || m.range.end > m.total || m.range.begin >= m.range.end)
        throw FileError(file.string(), "fields 'shard', 'total' or 'range' are out of range");
    for (int item : m.items)
        if (item < m.range.begin || item >= m.range.end)
            throw FileError(file.string(),
                            "field 'items' holds " + std::to_string(item) + ", outside 'range'");
    return m;
}

std::string rerunCommand(const std::vector<std::string>& commandLine, const ShardSpec& shard) {
    std::string s;
    for (size_t i = 0; i < commandLine.size(); ++i) {
        std::string arg = commandLine[i];
        if (i > 0 && commandLine[i - 1] == "--shard")
            arg = fmt::format("{}/{}", shard.index, shard.count);
        else if (arg.rfind("--shard=", 0) == 0)
            arg = fmt::format("--shard={}/{}", shard.index, shard.count);
        const bool plain =
            !arg.empty() && arg.find_first_of(" \t'\"$\\;&|<>*?") == std::string::npos;
        s += (i ? " " : "") + (plain ? arg : "'" + arg + "'");
    }
    return s;
}

ShardSet collectShards(const fs::path& output) {
    const fs::path folder = shardsFolder(output);
    if (!fs::is_directory(folder))
        throw FileError(folder.string(),
                        "no shards here: run the command with --shard I/N and the same -o first");
    ShardSet set;
    std::vector<std::string> incomplete;
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(folder)) {
        if (!e.is_directory()) continue;
        if (!fs::exists(e.path() / "shard.json")) {
            incomplete.push_back(e.path().filename().string());
            continue;
        }
        dirs.push_back(e.path());
    }
    std::sort(dirs.begin(), dirs.end());
    for (const fs::path& d : dirs) {
        set.shards.push_back(readShardManifest(d));
        set.folders.push_back(d);
        verifyShardFiles(d, set.shards.back());
    }
    if (set.shards.empty())
        throw FileError(folder.string(),
                        "holds no complete shard" +
                            (incomplete.empty() ? std::string()
                                                : " (incomplete: " + incomplete.front() + "...)"));
    // Order by shard index; one run only.
    std::vector<size_t> order(set.shards.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return set.shards[a].shard.index < set.shards[b].shard.index;
    });
    ShardSet sorted;
    for (size_t i : order) {
        sorted.shards.push_back(set.shards[i]);
        sorted.folders.push_back(set.folders[i]);
    }
    set = std::move(sorted);
    const ShardManifest& first = set.shards.front();
    for (size_t i = 1; i < set.shards.size(); ++i) {
        const ShardManifest& m = set.shards[i];
        if (m.command != first.command || m.fingerprint != first.fingerprint ||
            m.shard.count != first.shard.count || m.total != first.total ||
            m.range.begin != first.range.begin || m.range.end != first.range.end ||
            m.blocks != first.blocks)
            throw FileError(
                set.folders[i].string(),
                fmt::format("is from another run than {} (command, options, shard count or "
                            "range differ): remove the shards of the old run and rerun",
                            set.folders.front().filename().string()));
        if (m.shard.index == set.shards[i - 1].shard.index)
            throw FileError(set.folders[i].string(),
                            "repeats shard " + std::to_string(m.shard.index));
    }
    set.owner.assign(size_t(first.total), -1);
    for (size_t s = 0; s < set.shards.size(); ++s)
        for (int item : set.shards[s].items) {
            if (set.owner[size_t(item)] >= 0)
                throw FileError(set.folders[s].string(),
                                fmt::format("{} {} is also in {}", first.unit, item,
                                            set.folders[size_t(set.owner[size_t(item)])].string()));
            set.owner[size_t(item)] = int(s);
        }
    std::vector<int> missing;
    std::set<int> missingShards;
    for (int item = first.range.begin; item < first.range.end; ++item)
        if (set.owner[size_t(item)] < 0) {
            missing.push_back(item);
            const int64_t offset = item - first.range.begin,
                          n = first.range.end - first.range.begin;
            // Block k holds offsets [n k / N, n (k + 1) / N).
            int k = int(offset % first.shard.count);
            if (first.blocks)
                for (k = 0; k + 1 < first.shard.count && n * (k + 1) / first.shard.count <= offset;)
                    ++k;
            missingShards.insert(k);
        }
    if (!missing.empty()) {
        std::string msg =
            fmt::format("{} of {} {} are missing ({})", missing.size(),
                        first.range.end - first.range.begin, first.unit, joinItems(missing));
        std::vector<int> shardList(missingShards.begin(), missingShards.end());
        msg += fmt::format("; rerun shard(s) {} of {}", joinItems(shardList), first.shard.count);
        if (!incomplete.empty()) msg += " (incomplete folders: " + incomplete.front() + ")";
        msg += ", e.g.: " + rerunCommand(first.commandLine,
                                         ShardSpec{*missingShards.begin(), first.shard.count});
        throw FileError(folder.string(), msg);
    }
    return set;
}

}  // namespace mirage
