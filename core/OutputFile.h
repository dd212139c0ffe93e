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
//    truncated file where the old one was;
//  - only a regular file or a new path is ever replaced: a character or block device
//    (`-o /dev/full`), a socket, or a folder where a file is expected is refused before any
//    work; a FIFO, or the standard output given as /dev/stdout (/dev/fd/N, /proc/self/fd/N), is
//    written through when the output is finished (the bytes are copied into it, it stays what
//    it was), which is what `-o /dev/stdout | ...` means; a folder output must be a folder or a
//    new path;
//  - temporaries are removed when SIGINT, SIGTERM or SIGHUP stops the process (a command that
//    polls stopRequested() finishes its own way instead), and a later run removes temporaries
//    that a killed process (SIGKILL, a crash) left beside its output.
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

// What is at an output path, as checkOutput() found it.
enum class OutputTarget {
    New,           // nothing yet
    RegularFile,   // replaced by rename when the output is finished
    Folder,        // only for folder outputs
    WriteThrough,  // a FIFO or the standard output: the finished bytes are written into it
};

// Classifies `out`; throws mirage::Error naming the output and what to do for a device, a
// socket, a folder where a file is expected (or a file or FIFO where a folder is).
OutputTarget outputTarget(const std::filesystem::path& out, const std::string& command,
                          bool outIsFolder = false);

// True for the name of a temporary a writer keeps beside its output ("x.partial-123.png"):
// folder listings of inputs skip them, so a command never reads its own unfinished output.
bool isPartialOutputName(const std::filesystem::path& p);

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
    // fsync + rename (or the copy into a FIFO / standard output). Throws FileError ("disk
    // full?") if the data cannot be flushed.
    void commit();
    bool committed() const { return committed_; }
    bool writesThrough() const { return writeThrough_; }

private:
    std::filesystem::path path_, temp_;
    bool committed_ = false;
    bool writeThrough_ = false;
    int cleanupSlot_ = -1;  // the temporary's entry in the on-signal cleanup list
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
    // Replaces what is at the final path (the caller checked it may: a folder or a regular
    // file, never a special file) with the temporary.
    // Throws FileError saying where the complete result was left if the rename fails.
    void commit();

private:
    std::filesystem::path final_, temp_;
    bool committed_ = false;
    int cleanupSlot_ = -1;
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
