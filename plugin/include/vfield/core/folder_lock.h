#pragma once
/// @file folder_lock.h
/// One writer per output folder. A FolderLock holds an exclusive flock(2) on
/// DIR/.vfield-lock for as long as it lives; the operating system releases
/// it when its process ends, however it ends (kill -9 included), so a lock
/// is never stale and a crashed writer never needs cleaning up. The file
/// names its holder (process id, host, what it does, since when) for the
/// message a second writer gets. flock works on local file systems and on NFS
/// version 4.

#include <functional>
#include <string>

namespace vfield {

class FolderLock {
public:
    /// Who holds a lock, as its file says: "vfield simulate, pid 1234 on host, since 2026-11-25 20:01:02".
    using Waiting = std::function<void(const std::string& holder)>;

    /// Locks dir (created if missing) for `what` ("vfield simulate"). When
    /// another process holds it: throws FileError(dir, "another vfield is
    /// writing here: ... (pid N ...)"), or, when waiting is set, calls it
    /// once with the holder and blocks until the lock is free.
    FolderLock(const std::string& dir, const std::string& what, const Waiting& waiting = {});
    ~FolderLock();
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

    /// The lock file's name inside a folder.
    static constexpr const char* kFileName = ".vfield-lock";

private:
    int mFd = -1;
};

} // namespace vfield
