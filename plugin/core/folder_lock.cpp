#include <vfield/core/folder_lock.h>

#include <vfield/core/error.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// What the lock file says of its holder, one line.
std::string holderOf(int fd)
{
    char text[512] = {};
    const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
    std::string holder(text, n > 0 ? std::size_t(n) : 0);
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\0')) holder.pop_back();
    return holder.empty() ? "a process that has not said who it is yet" : holder;
}

std::string describeThisProcess(const std::string& what)
{
    char host[256] = "unknown host";
    ::gethostname(host, sizeof host - 1);
    const std::time_t now = std::time(nullptr);
    char since[32];
    std::strftime(since, sizeof since, "%Y-%m-%d %H:%M:%S", std::localtime(&now));
    return what + ", pid " + std::to_string(::getpid()) + " on " + host + ", since " + since + "\n";
}

} // namespace

FolderLock::FolderLock(const std::string& dir, const std::string& what, const Waiting& waiting)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw FileError(dir, "cannot create the folder: " + ec.message());
    const std::string path = (fs::path(dir) / kFileName).string();
    mFd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (mFd < 0) throw FileError(path, std::string("cannot open the folder's lock: ") + std::strerror(errno));
    if (::flock(mFd, LOCK_EX | LOCK_NB) != 0) {
        if (errno != EWOULDBLOCK) {
            const std::string why = std::strerror(errno);
            ::close(mFd);
            throw FileError(path, "cannot lock the folder: " + why);
        }
        const std::string holder = holderOf(mFd);
        if (!waiting) {
            ::close(mFd);
            throw FileError(dir, "another vfield is writing here (" + holder +
                                     "): wait for it to finish, or write into another folder");
        }
        waiting(holder);
        while (::flock(mFd, LOCK_EX) != 0)
            if (errno != EINTR) {
                const std::string why = std::strerror(errno);
                ::close(mFd);
                throw FileError(path, "cannot lock the folder: " + why);
            }
    }
    const std::string me = describeThisProcess(what);
    // Who holds the lock is for messages only: failing to write it leaves the lock held.
    const bool told = ::ftruncate(mFd, 0) == 0 && ::pwrite(mFd, me.data(), me.size(), 0) == ssize_t(me.size());
    static_cast<void>(told);
}

FolderLock::~FolderLock()
{
    if (mFd >= 0) ::close(mFd); // releases the lock
}

} // namespace vfield
