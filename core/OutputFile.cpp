#include "core/OutputFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>

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
    std::error_code ec;
    if (origin == OutputOrigin::Derived && !rule.force && fs::exists(out, ec) &&
        !fs::is_directory(out, ec))
        throw Error(who + ": " + quoted(out) +
                    " exists and was not named on the command line (it is written beside the "
                    "named output); pass --force to replace it, or choose another output name");
    if (fs::is_directory(out, ec) && !outIsFolder)
        throw Error(who + ": the output " + quoted(out) + " is a folder; give a file name (e.g. " +
                    (out / "out").string() + ")");
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
    createParentFolders(path_);
    temp_ = path_;
    temp_.replace_filename(path_.stem().string() + ".partial-" + std::to_string(::getpid()) +
                           path_.extension().string());
    // Created now, so an unwritable folder fails before the work, not after it.
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        throw FileError(path_.string(), std::string("cannot create the output: ") +
                                            std::strerror(errno) + " (is the folder writable?)");
    ::close(fd);
}

OutputFile::OutputFile(OutputFile&& other) noexcept
    : path_(std::move(other.path_)), temp_(std::move(other.temp_)), committed_(other.committed_) {
    other.committed_ = true;  // the moved-from object owns no temporary file
}

OutputFile::~OutputFile() {
    if (committed_ || temp_.empty()) return;
    std::error_code ec;
    fs::remove(temp_, ec);
}

void OutputFile::commit() {
    if (committed_) return;
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
    temp_ = final_;
    temp_.replace_filename(final_.stem().string() + ".partial-" + std::to_string(::getpid()) +
                           final_.extension().string());
    std::error_code ec;
    std::filesystem::remove_all(temp_, ec);
    if (!final_.parent_path().empty()) std::filesystem::create_directories(final_.parent_path());
}

StagedPath::~StagedPath() {
    std::error_code ec;
    if (!committed_) std::filesystem::remove_all(temp_, ec);
}

void StagedPath::commit() {
    std::error_code ec;
    std::filesystem::remove_all(final_, ec);
    std::filesystem::rename(temp_, final_, ec);
    if (ec)
        throw FileError(final_.string(),
                        "cannot move the finished result into place: " + ec.message() +
                            " (it is complete in " + temp_.string() + ")");
    committed_ = true;
}

}  // namespace mirage
