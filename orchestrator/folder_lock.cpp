#include "orchestrator/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace demcal::orchestrator {

FolderLock::FolderLock(const std::filesystem::path& folder, const std::string& what) : file_(folder / ".lock") {
    std::error_code ec;
    made_file_ = !std::filesystem::exists(std::filesystem::symlink_status(file_, ec));
    // O_CLOEXEC: children must not inherit the lock, or a resume right after kill -9 of the holder finds the folder
    // "in use" until the last orphan has died
    fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) {
        const int why = errno;
        // a folder the user may not write (a campaign copied read-only from a cluster): bad input, named as such
        if (why == EACCES || why == EROFS || why == EPERM)
            throw std::invalid_argument(what + " " + folder.string() + " is not writable (" + std::strerror(why) +
                                        "): running or resuming a campaign writes into its folder (demcal status "
                                        "reads one as it is)");
        throw std::runtime_error(what + " " + folder.string() + ": cannot open its lock " + file_.string() + " (" +
                                 std::strerror(why) + ")");
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd_);
        fd_ = -1;
        // refused at once, as bad input (exit 2) whatever the command: a shear campaign's said "failed" (exit 1), a
        // silo run's "error" (2)
        throw std::invalid_argument(what + " " + folder.string() + " is in use by another demcal process");
    }
}

bool FolderLock::held(const std::filesystem::path& folder) {
    const int fd = ::open((folder / ".lock").c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;  // never locked here (or not readable: nothing to say)
    const bool free = ::flock(fd, LOCK_SH | LOCK_NB) == 0;
    ::close(fd);  // (closing drops the shared lock taken to test)
    return !free;
}

FolderLock::~FolderLock() {
    if (fd_ >= 0) ::close(fd_);
}

void FolderLock::release_and_forget() {
    if (fd_ < 0) return;
    if (made_file_) ::unlink(file_.c_str());
    ::close(fd_);
    fd_ = -1;
}

}  // namespace demcal::orchestrator
