#pragma once
// Output safety, shared by every command that writes files (docs/conventions.md, "Outputs"):
//  - checked before any work: an output may not be one of the command's inputs (the same file
//    after resolving symbolic and hard links, or an input folder itself), its parent folders are
//    created (one rule everywhere), and it must be creatable there;
//  - a file the user did not name on the command line (a CSV written beside a video, a report
//    beside a calibration) is never replaced when it already exists, unless the user passes
//    --force;
//  - written to a temporary name beside the target and renamed over it only when the command
//    finishes it, so a failure (bad input found late, disk full, a crash) never leaves a
//    truncated file where the old one was.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace mirage {

// Whether a user named an output, or the command derived it from a named one.
enum class OutputOrigin { Named, Derived };

struct OutputRule {
    std::vector<std::filesystem::path> inputs;  // files and folders the command reads
    bool force = false;                         // --force: derived outputs may be replaced
    std::string command;                        // "mirage replay", for messages
};

// True if `a` and `b` name the same file or folder (symbolic links and hard links resolved;
// false if either does not exist).
bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b);

// Throws mirage::Error (naming the output, the input and what to do) if `out` would destroy an
// input: it is the same file as an input, an input folder, or a folder holding an input (when
// `outIsFolder`, its files may be written). Also refuses a derived output that exists unless
// rule.force. Does not touch the disk.
void checkOutput(const std::filesystem::path& out, OutputOrigin origin, const OutputRule& rule,
                 bool outIsFolder = false);

// Creates the parent folders of `out` (every command does, so `-o results/run1/x.png` works
// the same everywhere); throws FileError if that fails.
void createParentFolders(const std::filesystem::path& out);

// One output file: checkOutput, parent folders and a temporary file beside the target
// ("<name>.partial-<pid><ext>", keeping the extension for writers that choose by it) are
// done in the constructor, so a bad path fails before any work. Write to temp(); commit()
// flushes it to disk and renames it over path(). Destroyed without commit(), the temporary
// file is removed and the target is left as it was.
class OutputFile {
public:
    OutputFile(std::filesystem::path path, OutputOrigin origin, const OutputRule& rule);
    ~OutputFile();
    OutputFile(OutputFile&& other) noexcept;
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;
    OutputFile& operator=(OutputFile&&) = delete;

    const std::filesystem::path& path() const { return path_; }
    const std::filesystem::path& temp() const { return temp_; }
    // fsync + rename. Throws FileError ("disk full?") if the data cannot be flushed.
    void commit();
    bool committed() const { return committed_; }

private:
    std::filesystem::path path_, temp_;
    bool committed_ = false;
};

// A folder (or file) written under a temporary name beside its final path,
// "<name>.partial-<pid><ext>", and moved there only when complete: a failed or interrupted
// writer leaves nothing at the final path and its temporary is removed. Used for sessions,
// shards and merged outputs, whose checks happen before (checkOutput).
class StagedPath {
public:
    explicit StagedPath(std::filesystem::path finalPath);  // removes a stale temporary first
    ~StagedPath();                                         // removes the temporary unless moved
    StagedPath(const StagedPath&) = delete;
    StagedPath& operator=(const StagedPath&) = delete;

    const std::filesystem::path& temp() const { return temp_; }
    const std::filesystem::path& finalPath() const { return final_; }
    // Replaces whatever is at the final path (the caller checked it may) with the temporary.
    // Throws FileError saying where the complete result was left if the rename fails.
    void commit();

private:
    std::filesystem::path final_, temp_;
    bool committed_ = false;
};

// Closes a stream that wrote an OutputFile's temp() and throws FileError naming `out` if any
// write failed (full disk, I/O error): a stream drops failed writes silently otherwise.
void closeChecked(std::ofstream& stream, const std::filesystem::path& out);

// Exit status of a command stopped by SIGINT/SIGTERM (the shell's 128 + signal number), and the
// flag the command's loop polls. installStopSignals() routes both signals to the flag; the
// previous handlers come back with restoreStopSignals().
bool stopRequested();
int stopSignal();  // 0 if none arrived
void installStopSignals();
void restoreStopSignals();

}  // namespace mirage
