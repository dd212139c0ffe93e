// A small mutation fuzzer for compilers without libFuzzer (gcc), shared by every fuzz target
// (tests/fuzz/FuzzTarget.h names the target, its seed files and its format's tokens). It is not
// coverage-guided: it mutates the seed corpus with byte flips, insertions, deletions,
// truncations, crossover, GLB header edits and text-aware splices (numbers replaced by boundary
// values, the format's keys and tokens inserted), feeds each result to the target for a fixed
// time with a fixed seed, and keeps inputs that load successfully as new seeds.
//
//   <target> --seconds 20 [--runs N] --seed 1 --corpus DIR [--corpus DIR...] [--crash-dir DIR]
//   <target> FILE...          # replay inputs (e.g. a saved crash) once each
//
// On a crash (signal, uncaught exception, sanitizer report, or an input running longer than
// --input-timeout seconds) the offending input is written to --crash-dir as crash-<seed>-<n>.bin
// before the process dies, so it can be replayed and turned into a bad-file test.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "core/Log.h"
#include "tests/fuzz/FuzzTarget.h"

#if defined(__SANITIZE_ADDRESS__)
#define MIRAGE_FUZZ_HAS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MIRAGE_FUZZ_HAS_SANITIZER 1
#endif
#endif
#ifdef MIRAGE_FUZZ_HAS_SANITIZER
#include <sanitizer/common_interface_defs.h>
#endif

namespace {

namespace fs = std::filesystem;

// ---- crash capture: the input being run is written out from the signal/death handler --------

const std::string* gCurrentInput = nullptr;
char gCrashPath[4096] = {0};

void saveCurrentInput() {
    if (!gCurrentInput || !gCrashPath[0]) return;
    // Only async-signal-safe calls here.
    int fd = ::open(gCrashPath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) return;
    const char* p = gCurrentInput->data();
    size_t left = gCurrentInput->size();
    while (left > 0) {
        ssize_t n = ::write(fd, p, left);
        if (n <= 0) break;
        p += n;
        left -= static_cast<size_t>(n);
    }
    ::close(fd);
    static const char kMsg[] = "\nfuzz: crashing input saved to ";
    (void)!::write(2, kMsg, sizeof(kMsg) - 1);
    (void)!::write(2, gCrashPath, std::strlen(gCrashPath));
    (void)!::write(2, "\n", 1);
    gCurrentInput = nullptr;
}

void onFatalSignal(int sig) {
    if (sig == SIGALRM) {
        static const char kMsg[] = "\nfuzz: input exceeded the per-input timeout\n";
        (void)!::write(2, kMsg, sizeof(kMsg) - 1);
    }
    saveCurrentInput();
    ::signal(sig == SIGALRM ? SIGABRT : sig, SIG_DFL);
    ::raise(sig == SIGALRM ? SIGABRT : sig);
}

void installCrashHandlers() {
    for (int sig : {SIGSEGV, SIGABRT, SIGFPE, SIGBUS, SIGILL, SIGALRM})
        ::signal(sig, onFatalSignal);
#ifdef MIRAGE_FUZZ_HAS_SANITIZER
    __sanitizer_set_death_callback(saveCurrentInput);
#endif
}

// ---- mutations ------------------------------------------------------------------------------

using Rng = std::mt19937_64;

size_t pick(Rng& rng, size_t n) {
    return n == 0 ? 0 : std::uniform_int_distribution<size_t>(0, n - 1)(rng);
}

const std::vector<std::string> kNumbers = {"-1",
                                           "0",
                                           "1",
                                           "2",
                                           "3",
                                           "4",
                                           "5",
                                           "7",
                                           "8",
                                           "12",
                                           "255",
                                           "256",
                                           "65535",
                                           "65536",
                                           "2147483647",
                                           "2147483648",
                                           "-2147483648",
                                           "4294967295",
                                           "4294967296",
                                           "9223372036854775807",
                                           "18446744073709551615",
                                           "18446744073709551616",
                                           "1e308",
                                           "-1e308",
                                           "1e999",
                                           "-0",
                                           "0.5",
                                           "1e-320",
                                           "5120",
                                           "5121",
                                           "5123",
                                           "5125",
                                           "5126",
                                           "34962",
                                           "1.5e10"};

void mutateNumber(std::string& s, Rng& rng) {
    // Replace a random run of digits (a JSON number, most likely an index or size).
    std::vector<size_t> starts;
    for (size_t i = 0; i < s.size(); ++i)
        if (std::isdigit(static_cast<unsigned char>(s[i])) &&
            (i == 0 || !std::isdigit(static_cast<unsigned char>(s[i - 1]))))
            starts.push_back(i);
    if (starts.empty()) return;
    size_t begin = starts[pick(rng, starts.size())], end = begin;
    while (end < s.size() && (std::isdigit(static_cast<unsigned char>(s[end])) || s[end] == '.' ||
                              s[end] == 'e' || s[end] == '-'))
        ++end;
    s.replace(begin, end - begin, kNumbers[pick(rng, kNumbers.size())]);
}

void mutateGlbHeader(std::string& s, Rng& rng) {
    if (s.size() < 20 || s.compare(0, 4, "glTF") != 0) return;
    static const uint32_t kValues[] = {0,  1,          3,          4,          12,
                                       20, 0x7fffffff, 0x80000000, 0xffffffff, 0xfffffff0};
    uint32_t jsonLength = 0;
    std::memcpy(&jsonLength, s.data() + 12, 4);
    std::vector<size_t> fields = {8, 12};
    if (20ull + jsonLength + 8 <= s.size()) fields.push_back(20 + jsonLength);  // BIN chunk length
    uint32_t v = rng() % 3 == 0 ? static_cast<uint32_t>(s.size() + pick(rng, 9) - 4)
                                : kValues[pick(rng, std::size(kValues))];
    std::memcpy(s.data() + fields[pick(rng, fields.size())], &v, 4);
}

void mutate(std::string& s, const std::vector<std::string>& pool, Rng& rng, size_t maxLength) {
    const int rounds = 1 + static_cast<int>(pick(rng, 4));
    for (int r = 0; r < rounds; ++r) {
        switch (pick(rng, 10)) {
            case 0:  // bit flip
                if (!s.empty()) s[pick(rng, s.size())] ^= static_cast<char>(1u << pick(rng, 8));
                break;
            case 1: {  // interesting byte
                static const char kBytes[] = {0,   '\xff', '\x7f', '\x80', '"', '{', '[',
                                              ',', ':',    '-',    '0',    '9', '\\'};
                if (!s.empty()) s[pick(rng, s.size())] = kBytes[pick(rng, sizeof(kBytes))];
                break;
            }
            case 2: {  // insert random bytes
                std::string bytes(1 + pick(rng, 8), '\0');
                for (char& c : bytes) c = static_cast<char>(rng());
                s.insert(pick(rng, s.size() + 1), bytes);
                break;
            }
            case 3: {  // delete a range
                if (s.empty()) break;
                size_t at = pick(rng, s.size());
                s.erase(at, 1 + pick(rng, std::min<size_t>(64, s.size() - at)));
                break;
            }
            case 4:  // truncate
                s.resize(pick(rng, s.size() + 1));
                break;
            case 5: {  // duplicate a range somewhere else
                if (s.empty()) break;
                size_t at = pick(rng, s.size());
                std::string chunk = s.substr(at, 1 + pick(rng, 64));
                s.insert(pick(rng, s.size() + 1), chunk);
                break;
            }
            case 6:
            case 7:  // JSON numbers are where indices and sizes live
                mutateNumber(s, rng);
                break;
            case 8: {  // insert a token of the format, with a comma half of the time so that
                       // JSON and CSV may stay valid
                const std::vector<std::string>& tokens = mirage::fuzz::target().tokens;
                if (tokens.empty()) break;
                std::string token = tokens[pick(rng, tokens.size())];
                if (rng() % 2) token = token + ",";
                s.insert(pick(rng, s.size() + 1), token);
                break;
            }
            case 9:  // crossover with another input, or a GLB header edit
                if (rng() % 2 && !pool.empty()) {
                    const std::string& other = pool[pick(rng, pool.size())];
                    if (other.empty()) break;
                    size_t from = pick(rng, other.size());
                    std::string chunk = other.substr(from, 1 + pick(rng, 256));
                    size_t at = pick(rng, s.size() + 1);
                    s.replace(at, pick(rng, std::min<size_t>(256, s.size() - at) + 1), chunk);
                } else {
                    mutateGlbHeader(s, rng);
                }
                break;
        }
    }
    if (s.size() > maxLength) s.resize(maxLength);
}

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int usage() {
    const std::string name = mirage::fuzz::target().name;
    std::cerr << "usage: " << name
              << " [--seconds S] [--runs N] [--seed N] [--corpus DIR]... [--crash-dir DIR]\n"
                 "       [--max-length BYTES] [--input-timeout S]\n"
              << "       " << name << " FILE...   (replay inputs once)\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    double seconds = 20;
    uint64_t maxRuns = 0;  // 0: no limit; the run ends at --seconds or --runs, whichever is first
    uint64_t seed = 1;
    size_t maxLength = 256 * 1024;
    unsigned inputTimeout = 10;
    std::vector<fs::path> corpusDirs, replay;
    fs::path crashDir = fs::current_path();
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::cerr << a << " needs a value\n";
                std::exit(usage());
            }
            return argv[++i];
        };
        if (a == "--seconds")
            seconds = std::stod(next());
        else if (a == "--runs")
            maxRuns = std::stoull(next());
        else if (a == "--seed")
            seed = std::stoull(next());
        else if (a == "--corpus")
            corpusDirs.emplace_back(next());
        else if (a == "--crash-dir")
            crashDir = next();
        else if (a == "--max-length")
            maxLength = std::stoull(next());
        else if (a == "--input-timeout")
            inputTimeout = static_cast<unsigned>(std::stoul(next()));
        else if (a.rfind("--", 0) == 0)
            return usage();
        else
            replay.emplace_back(a);
    }
    installCrashHandlers();
    // Every rejected input would log its warnings; only errors are of interest here.
    spdlog::set_level(spdlog::level::err);

    if (!replay.empty()) {
        for (const fs::path& p : replay) {
            std::string input = readFile(p);
            bool loaded = mirage::fuzz::target().runOnce(
                reinterpret_cast<const uint8_t*>(input.data()), input.size());
            std::cout << p.string() << ": " << (loaded ? "loaded" : "rejected with mirage::Error")
                      << "\n";
        }
        return 0;
    }

    const mirage::fuzz::Target& target = mirage::fuzz::target();
    auto isSeed = [&](const fs::path& p) {
        if (target.seedExtensions.empty()) return true;
        for (const std::string& ext : target.seedExtensions)
            if (p.extension() == ext) return true;
        return false;
    };
    std::vector<std::string> pool;
    for (const fs::path& dir : corpusDirs) {
        std::vector<fs::path> files;
        for (const auto& e : fs::directory_iterator(dir))
            if (e.is_regular_file() && isSeed(e.path())) files.push_back(e.path());
        std::sort(files.begin(), files.end());  // directory order differs between machines
        for (const fs::path& f : files) pool.push_back(readFile(f));
    }
    if (pool.empty()) {
        std::cerr << target.name << ": no seed files found; pass --corpus DIR\n";
        return 2;
    }
    const size_t seeds = pool.size();
    fs::create_directories(crashDir);

    Rng rng(seed);
    const auto start = std::chrono::steady_clock::now();
    uint64_t runs = 0, loaded = 0;
    std::string input;
    while ((maxRuns == 0 || runs < maxRuns) &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
               seconds) {
        input = pool[pick(rng, pool.size())];
        mutate(input, pool, rng, maxLength);
        std::snprintf(gCrashPath, sizeof(gCrashPath), "%s/crash-%llu-%llu.bin",
                      crashDir.string().c_str(), static_cast<unsigned long long>(seed),
                      static_cast<unsigned long long>(runs));
        gCurrentInput = &input;
        ::alarm(inputTimeout);
        bool ok = target.runOnce(reinterpret_cast<const uint8_t*>(input.data()), input.size());
        ::alarm(0);
        gCurrentInput = nullptr;
        ++runs;
        if (ok) {
            ++loaded;
            // Inputs that still load are valid-but-different scenes: good starting points.
            if (pool.size() < seeds + 2000)
                pool.push_back(input);
            else
                pool[seeds + pick(rng, pool.size() - seeds)] = input;
        }
    }
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << target.name << ": " << runs << " inputs in " << elapsed << " s (" << runs / elapsed
              << "/s), seed " << seed << ", " << seeds << " seed files, " << loaded << " loaded, "
              << runs - loaded << " rejected with mirage::Error, no crash\n";
    return 0;
}
