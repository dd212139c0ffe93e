#include "core/session/AtomicFile.h"

#include <fcntl.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "core/Error.h"

namespace mirage {

namespace {
std::string errnoText() {
    return std::strerror(errno);
}

// fsync on a folder makes a rename inside it durable; failure is not fatal (some file systems
// do not support it) because the rename itself has already happened atomically.
void syncFolder(const std::filesystem::path& folder) {
    const int fd = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}
}  // namespace

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
    auto tmp = path;
    tmp += ".tmp-" + std::to_string(::getpid());
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        throw FileError(path.string(), "cannot create temporary file " + tmp.string() + ": " +
                                           errnoText() + " (is the folder writable?)");
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            const std::string why = errnoText();
            ::close(fd);
            ::unlink(tmp.c_str());
            throw FileError(path.string(), "write failed: " + why + " (disk full?)");
        }
        done += size_t(n);
    }
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
        const std::string why = errnoText();
        ::unlink(tmp.c_str());
        throw FileError(path.string(), "cannot flush to disk: " + why);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string why = errnoText();
        ::unlink(tmp.c_str());
        throw FileError(path.string(), "cannot move the finished file into place: " + why);
    }
    syncFolder(path.parent_path());
}

std::string readFileBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open for reading (does it exist?)");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw FileError(path.string(), "read failed");
    return ss.str();
}

}  // namespace mirage
