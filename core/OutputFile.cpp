#include "core/OutputFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <string>

#include "core/Error.h"

namespace mirage {

namespace fs = std::filesystem;

namespace {

std::string quoted(const fs::path& p) {
    return "'" + p.string() + "'";
}

// `inner` is `outer` or lies somewhere below it (both resolved).
bool isWithin(const fs::path& inner, const fs::path& outer) {
    std::error_code ec;
    const fs::path a = fs::weakly_canonical(inner, ec);
    if (ec) return false;
    const fs::path b = fs::weakly_canonical(outer, ec);
    if (ec) return false;
    auto ai = a.begin();
    for (auto bi = b.begin(); bi != b.end(); ++bi, ++ai) {
        if (bi->empty()) continue;  // trailing separator
        if (ai == a.end() || *ai != *bi) return false;
    }
    return true;
}

std::atomic<int> gStopSignal{0};
using Handler = void (*)(int);
Handler gPrevInt = SIG_DFL, gPrevTerm = SIG_DFL;

extern "C" void onStopSignal(int sig) {
    // A second signal while stopping: the user insists; die the default way.
    if (gStopSignal.exchange(sig) != 0) {
        std::signal(sig, SIG_DFL);
        std::raise(sig);
    }
}

// Temporaries to remove when a signal ends the process. A fixed table of plain characters,
// because the signal handler may only read memory and make system calls (no allocation).
struct CleanupEntry {
    std::atomic<bool> used{false};
    bool folder = false;
    char path[4096] = {};
};
constexpr int kCleanupSlots = 64;
CleanupEntry gCleanup[kCleanupSlots];
std::mutex gCleanupMutex;

// Removes `name` in `dirFd` and, for a folder, everything in it, with system calls only
// (async-signal-safe). Folders a writer fills meanwhile are emptied again, a few times.
void removeTreeAt(int dirFd, const char* name, int depth) {
    if (::unlinkat(dirFd, name, 0) == 0 || errno == ENOENT) return;
    if (depth > 16) return;
    for (int attempt = 0; attempt < 3; ++attempt) {
        const int fd = ::openat(dirFd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        if (fd < 0) return;
        alignas(8) char buf[8192];
        for (;;) {
            const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
            if (n <= 0) break;
            for (long off = 0; off < n;) {
                // struct linux_dirent64: ino (8), off (8), reclen (2), type (1), name.
                unsigned short reclen;
                std::memcpy(&reclen, buf + off + 16, sizeof reclen);
                const char* child = buf + off + 19;
                off += reclen;
                if (std::strcmp(child, ".") == 0 || std::strcmp(child, "..") == 0) continue;
                removeTreeAt(fd, child, depth + 1);
            }
        }
        ::close(fd);
        if (::unlinkat(dirFd, name, AT_REMOVEDIR) == 0 || errno == ENOENT) return;
    }
}

void removeRegisteredTemporaries() {
    for (CleanupEntry& e : gCleanup)
        if (e.used.load()) removeTreeAt(AT_FDCWD, e.path, 0);
}

extern "C" void onFatalSignal(int sig) {
    removeRegisteredTemporaries();
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

// Installs the cleanup handler for SIGINT, SIGTERM and SIGHUP once, where the process still has
// the default action (a command's own handler, installStopSignals(), takes precedence while set).
void installCleanupHandler() {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
        struct sigaction old {};
        if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_DFL)
            std::signal(sig, onFatalSignal);
    }
}

int registerTemporary(const fs::path& p, bool folder) {
    installCleanupHandler();
    std::error_code ec;
    const std::string abs = fs::absolute(p, ec).string();
    if (ec || abs.size() >= sizeof(CleanupEntry::path)) return -1;
    std::lock_guard lock(gCleanupMutex);
    for (int i = 0; i < kCleanupSlots; ++i) {
        CleanupEntry& e = gCleanup[i];
        if (e.used.load()) continue;
        std::memcpy(e.path, abs.c_str(), abs.size() + 1);
        e.folder = folder;
        e.used.store(true);
        return i;
    }
    return -1;  // table full: the temporary is still removed by destructors and later runs
}

void unregisterTemporary(int slot) {
    if (slot < 0) return;
    std::lock_guard lock(gCleanupMutex);
    gCleanup[slot].used.store(false);
}

// "<stem>.partial-<pid><ext>" beside `target`.
fs::path partialName(const fs::path& target, long pid) {
    fs::path p = target;
    p.replace_filename(target.stem().string() + ".partial-" + std::to_string(pid) +
                       target.extension().string());
    return p;
}

// Removes temporaries of `target` left by processes that no longer run (killed with SIGKILL,
// crashed): "<stem>.partial-<pid><ext>" with a pid that kill(pid, 0) does not find.
void removeStaleTemporaries(const fs::path& target) {
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    const std::string prefix = target.stem().string() + ".partial-";
    const std::string ext = target.extension().string();
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(folder, ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind(prefix, 0) != 0 || name.size() <= prefix.size() + ext.size() ||
            name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
            continue;
        const std::string digits =
            name.substr(prefix.size(), name.size() - prefix.size() - ext.size());
        if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos ||
            digits.size() > 9)
            continue;
        const long pid = std::stol(digits);
        if (pid == ::getpid() || pid <= 0 || ::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;
        std::error_code rmEc;
        fs::remove_all(e.path(), rmEc);
    }
}

// A path that reaches an open file descriptor (/dev/stdout, /dev/fd/1, /proc/self/fd/1): the
// link's target is the shell's redirection; renaming would replace the link, not write the file.
bool reachesFileDescriptor(const fs::path& out) {
    std::error_code ec;
    fs::path p = fs::absolute(out, ec);
    for (int hop = 0; hop < 16 && !ec; ++hop) {
        const fs::path parent = fs::canonical(p.parent_path(), ec);
        if (ec) return false;
        if (parent.string().rfind("/proc/", 0) == 0) return true;
        if (!fs::is_symlink(parent / p.filename(), ec)) return false;
        const fs::path target = fs::read_symlink(parent / p.filename(), ec);
        p = target.is_absolute() ? target : parent / target;
    }
    return false;
}

const char* specialKind(mode_t mode) {
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "a special file";
}

}  // namespace

bool sameFile(const fs::path& a, const fs::path& b) {
    std::error_code ec;
    const bool same = fs::equivalent(a, b, ec);  // stat(): links resolved, hard links compared
    return !ec && same;
}

void checkOutput(const fs::path& out, OutputOrigin origin, const OutputRule& rule,
                 bool outIsFolder) {
    const std::string who = rule.command.empty() ? "mirage" : rule.command;
    if (out.empty()) throw Error(who + ": the output path is empty");
    for (const fs::path& in : rule.inputs) {
        if (in.empty()) continue;
        std::error_code ec;
        const bool inputIsFolder = fs::is_directory(in, ec);
        if (sameFile(out, in))
            throw Error(who + ": the output " + quoted(out) + " is the input " + quoted(in) +
                        (inputIsFolder ? " (a folder the command reads)" : "") +
                        "; writing it would destroy the input. Choose another output path.");
        if (outIsFolder && isWithin(in, out))
            throw Error(who + ": the output folder " + quoted(out) + " holds the input " +
                        quoted(in) +
                        "; writing into it could destroy the input. Choose another folder.");
    }
    const OutputTarget target = outputTarget(out, who, outIsFolder);
    if (origin == OutputOrigin::Derived && !rule.force && target == OutputTarget::RegularFile)
        throw Error(who + ": " + quoted(out) +
                    " exists and was not named on the command line (it is written beside the "
                    "named output); pass --force to replace it, or choose another output name");
}

OutputTarget outputTarget(const fs::path& out, const std::string& command, bool outIsFolder) {
    const std::string who = command.empty() ? "mirage" : command;
    struct stat st {};
    if (::stat(out.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) return OutputTarget::New;
        throw FileError(out.string(), std::string("cannot use as output: ") + std::strerror(errno));
    }
    if (S_ISDIR(st.st_mode)) {
        if (outIsFolder) return OutputTarget::Folder;
        throw Error(who + ": the output " + quoted(out) + " is a folder; give a file name (e.g. " +
                    (out / "out").string() + ")");
    }
    if (S_ISREG(st.st_mode)) {
        if (outIsFolder)
            throw Error(who + ": the output " + quoted(out) +
                        " is a file, but this output is a folder; give a folder or a new path");
        return reachesFileDescriptor(out) ? OutputTarget::WriteThrough : OutputTarget::RegularFile;
    }
    if (S_ISFIFO(st.st_mode)) {
        if (outIsFolder)
            throw Error(who + ": the output " + quoted(out) +
                        " is a FIFO (named pipe), but this output is a folder; give a folder or "
                        "a new path");
        return OutputTarget::WriteThrough;
    }
    // The process's own standard output on a terminal (/dev/stdout -> /dev/pts/N): CSV to the
    // screen is what `-o /dev/stdout` means there. A device named directly is refused.
    if (S_ISCHR(st.st_mode) && !outIsFolder && reachesFileDescriptor(out))
        return OutputTarget::WriteThrough;
    throw Error(who + ": the output " + quoted(out) + " is " + specialKind(st.st_mode) +
                ", not a file; mirage writes a regular file or a new path (or writes a FIFO or "
                "/dev/stdout through). Choose a file name.");
}

bool isPartialOutputName(const fs::path& p) {
    return p.filename().string().find(".partial-") != std::string::npos;
}

void createParentFolders(const fs::path& out) {
    const fs::path parent = out.parent_path();
    if (parent.empty()) return;
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec || !fs::is_directory(parent))
        throw FileError(out.string(), "cannot create the output folder " + quoted(parent) + ": " +
                                          (ec ? ec.message() : "a file of that name exists"));
}

OutputFile::OutputFile(fs::path path, OutputOrigin origin, const OutputRule& rule)
    : path_(std::move(path)) {
    checkOutput(path_, origin, rule);
    writeThrough_ = outputTarget(path_, rule.command) == OutputTarget::WriteThrough;
    if (writeThrough_) {
        // Beside a FIFO or /dev/stdout there may be no writable folder (/dev, /proc/self/fd).
        std::error_code ec;
        const fs::path tmp = fs::temp_directory_path(ec);
        temp_ = partialName((ec ? fs::path("/tmp") : tmp) / ("mirage-" + path_.filename().string()),
                            ::getpid());
    } else {
        createParentFolders(path_);
        removeStaleTemporaries(path_);
        temp_ = partialName(path_, ::getpid());
    }
    // Created now, so an unwritable folder fails before the work, not after it.
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        throw FileError(path_.string(), std::string("cannot create the output: ") +
                                            std::strerror(errno) + " (is the folder writable?)");
    ::close(fd);
    cleanupSlot_ = registerTemporary(temp_, false);
}

OutputFile::OutputFile(OutputFile&& other) noexcept
    : path_(std::move(other.path_)),
      temp_(std::move(other.temp_)),
      committed_(other.committed_),
      writeThrough_(other.writeThrough_),
      cleanupSlot_(other.cleanupSlot_) {
    other.committed_ = true;  // the moved-from object owns no temporary file
    other.cleanupSlot_ = -1;
}

OutputFile::~OutputFile() {
    unregisterTemporary(cleanupSlot_);
    if (committed_ || temp_.empty()) return;
    std::error_code ec;
    fs::remove(temp_, ec);
}

namespace {

// Copies the finished temporary into a FIFO or the standard output (which stays what it is).
void writeThrough(const fs::path& temp, const fs::path& target) {
    const int in = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC);
    if (in < 0)
        throw FileError(target.string(), std::string("the output vanished while being written: ") +
                                             std::strerror(errno));
    // O_APPEND: a redirected standard output keeps what the shell and the process wrote before.
    const int out = ::open(target.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (out < 0) {
        const int err = errno;
        ::close(in);
        throw FileError(target.string(),
                        std::string("cannot open the output for writing: ") + std::strerror(err));
    }
    char buf[1 << 16];
    std::string problem;
    for (;;) {
        const ssize_t n = ::read(in, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n < 0) problem = std::strerror(errno);
            break;
        }
        for (ssize_t done = 0; done < n && problem.empty();) {
            const ssize_t w = ::write(out, buf + done, size_t(n - done));
            if (w < 0 && errno == EINTR) continue;
            if (w < 0) problem = std::strerror(errno);
            done += w < 0 ? 0 : w;
        }
        if (!problem.empty()) break;
    }
    ::close(in);
    ::close(out);
    if (!problem.empty()) throw FileError(target.string(), "writing the output failed: " + problem);
}

}  // namespace

void OutputFile::commit() {
    if (committed_) return;
    if (writeThrough_) {
        writeThrough(temp_, path_);
        std::error_code ec;
        fs::remove(temp_, ec);
        committed_ = true;
        unregisterTemporary(cleanupSlot_);
        cleanupSlot_ = -1;
        return;
    }
    const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        throw FileError(path_.string(), std::string("the output vanished while being written: ") +
                                            std::strerror(errno));
    const bool synced = ::fsync(fd) == 0;
    const int syncErrno = errno;
    ::close(fd);
    if (!synced)
        throw FileError(path_.string(), std::string("cannot flush the output to disk: ") +
                                            std::strerror(syncErrno) + " (disk full?)");
    std::error_code ec;
    fs::rename(temp_, path_, ec);
    if (ec)
        throw FileError(path_.string(),
                        "cannot move the finished output into place: " + ec.message());
    committed_ = true;
    unregisterTemporary(cleanupSlot_);
    cleanupSlot_ = -1;
}

void closeChecked(std::ofstream& stream, const fs::path& out) {
    stream.flush();
    const bool ok = stream.good();
    stream.close();
    if (!ok || stream.fail())
        throw FileError(out.string(),
                        "writing failed (disk full?); the previous file, if any, is unchanged");
}

bool stopRequested() {
    return gStopSignal.load() != 0;
}

int stopSignal() {
    return gStopSignal.load();
}

void installStopSignals() {
    gStopSignal = 0;
    gPrevInt = std::signal(SIGINT, onStopSignal);
    gPrevTerm = std::signal(SIGTERM, onStopSignal);
}

void restoreStopSignals() {
    std::signal(SIGINT, gPrevInt == SIG_ERR ? SIG_DFL : gPrevInt);
    std::signal(SIGTERM, gPrevTerm == SIG_ERR ? SIG_DFL : gPrevTerm);
}

StagedPath::StagedPath(std::filesystem::path finalPath) : final_(std::move(finalPath)) {
    if (!final_.has_filename()) final_ = final_.parent_path();
    temp_ = partialName(final_, ::getpid());
    std::error_code ec;
    std::filesystem::remove_all(temp_, ec);
    if (!final_.parent_path().empty()) std::filesystem::create_directories(final_.parent_path());
    removeStaleTemporaries(final_);
    cleanupSlot_ = registerTemporary(temp_, true);
}

StagedPath::~StagedPath() {
    unregisterTemporary(cleanupSlot_);
    std::error_code ec;
    if (!committed_) std::filesystem::remove_all(temp_, ec);
}

void StagedPath::commit() {
    std::error_code ec;
    // Never a special file: what is replaced must be a folder or a regular file.
    const auto st = std::filesystem::symlink_status(final_, ec);
    if (!ec && st.type() != fs::file_type::not_found && st.type() != fs::file_type::directory &&
        st.type() != fs::file_type::regular && st.type() != fs::file_type::symlink)
        throw FileError(final_.string(), "is a special file; not replaced (the result is in " +
                                             temp_.string() + ")");
    ec.clear();
    std::filesystem::remove_all(final_, ec);
    std::filesystem::rename(temp_, final_, ec);
    if (ec)
        throw FileError(final_.string(),
                        "cannot move the finished result into place: " + ec.message() +
                            " (it is complete in " + temp_.string() + ")");
    committed_ = true;
    unregisterTemporary(cleanupSlot_);
    cleanupSlot_ = -1;
}

}  // namespace mirage
