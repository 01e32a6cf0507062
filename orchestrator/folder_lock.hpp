// A folder held by one demcal at a time: flock on FOLDER/.lock, released by the kernel when the holder exits, even by
// kill -9. Campaign folders (shear and silo campaigns) and the output folder of a silo run take it, so that a second
// demcal on the same folder stops at once instead of computing the same runs into the same files.
#pragma once
#include <filesystem>
#include <string>

namespace demcal::orchestrator {

class FolderLock {
public:
    // Takes the lock of an existing `folder`; throws std::runtime_error naming `what` and the folder when another
    // process holds it, or when the lock file cannot be made (the reason given); std::invalid_argument (bad input)
    // when the folder is not the user's to write (permission denied, a read-only file system).
    FolderLock(const std::filesystem::path& folder, const std::string& what);
    ~FolderLock();
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

    // Whether a process holds `folder`'s lock now; reads only (no lock file is made), for a report such as status.
    static bool held(const std::filesystem::path& folder);

    // Gives the lock up and removes the lock file if this lock made it (a folder refused after its lock was taken is
    // left as it was found).
    void release_and_forget();

private:
    std::filesystem::path file_;
    int fd_ = -1;
    bool made_file_ = false;
};

}  // namespace demcal::orchestrator
