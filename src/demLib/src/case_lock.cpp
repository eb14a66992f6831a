#include "demLib/case_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace dem {

namespace fs = std::filesystem;

namespace {

struct Holder {
    std::string pid, command, started;
};

Holder holderOf(const fs::path& lockFile) {
    std::ifstream in(lockFile);
    Holder h;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("pid ", 0) == 0) h.pid = line.substr(4);
        else if (line.rfind("command ", 0) == 0) h.command = line.substr(8);
        else if (line.rfind("started ", 0) == 0) h.started = line.substr(8);
    }
    return h;
}

std::string describeHolder(const fs::path& lockFile) {
    const Holder h = holderOf(lockFile);
    if (h.pid.empty()) return "another process (it has not yet written its pid)";
    std::string text = "process " + h.pid + (h.command.empty() ? "" : " (" + h.command + ")");
    if (!h.started.empty()) text += ", started " + h.started;
    return text;
}

// The lock a parent script holds for this case, from DIEFILL_CASE_LOCK=<file>:<pid>.
bool heldByParentScript(const fs::path& lockFile) {
    const char* env = std::getenv("DIEFILL_CASE_LOCK");
    if (!env) return false;
    const std::string value = env;
    const std::size_t colon = value.rfind(':');
    if (colon == std::string::npos) return false;
    std::error_code error;
    if (!fs::equivalent(value.substr(0, colon), lockFile, error) || error) return false;
    return holderOf(lockFile).pid == value.substr(colon + 1);
}

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
    return text;
}

}  // namespace

CaseLock::CaseLock(const std::string& caseDir, const std::string& tool) {
    const fs::path lockFile = fs::path(caseDir) / fileName;
    const int fd = ::open(lockFile.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0)
        throw RuntimeError("cannot create the case lock '" + lockFile.string() + "': " + std::strerror(errno) +
                           " (a case folder must be writable to run in it)");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int error = errno;
        ::close(fd);
        if (error == EWOULDBLOCK) {
            if (heldByParentScript(lockFile)) return;  // runs under its script's lock
            throw CaseBusyError("case '" + caseDir + "' is in use by " + describeHolder(lockFile) +
                                " (lock '" + lockFile.string() + "'); a second run in it would cut the first one's "
                                "results. Wait for it to end (or stop it: kill <pid>), or run in a copy of the case");
        }
        throw RuntimeError("cannot lock '" + lockFile.string() + "': " + std::strerror(error));
    }
    fd_ = fd;
    std::ostringstream text;
    text << "pid " << ::getpid() << "\ncommand " << tool << "\nstarted " << utcNow() << "\n";
    const std::string s = text.str();
    // The file names the holder; a failure to write it leaves the lock itself intact.
    if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, s.data(), s.size(), 0) == static_cast<ssize_t>(s.size())) ::fsync(fd_);
}

CaseLock::~CaseLock() {
    // The file stays (removing it would race with a run that just opened it); the lock goes.
    if (fd_ >= 0) ::close(fd_);
}

}  // namespace dem
