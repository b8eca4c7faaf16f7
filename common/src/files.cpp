#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

#include <coredem/common/check.h>
#include <coredem/common/files.h>

namespace fs = std::filesystem;

namespace coredem {

void fsyncPath(const fs::path& p, bool directory) {
  const int fd = ::open(p.c_str(), directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) {
    return; // best effort for directories on file systems that refuse O_DIRECTORY
  }
  ::fsync(fd);
  ::close(fd);
}

void syncFile(const fs::path& p) {
  const int fd = ::open(p.c_str(), O_RDONLY);
  COREDEM_CHECK(fd >= 0, "cannot open {} to flush it: {}", p.string(), std::strerror(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  COREDEM_CHECK(rc == 0, "fsync of {} failed: {}", p.string(), std::strerror(err));
}

void writeFileAtomic(const fs::path& path, const std::string& content) {
  const fs::path tmp =
      path.parent_path() / (path.filename().string() + ".tmp." + std::to_string(::getpid()));
  {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    COREDEM_CHECK(fd >= 0, "cannot create '{}': {}", tmp.string(), std::strerror(errno));
    std::size_t done = 0;
    while (done < content.size()) {
      const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
      if (n < 0 && errno == EINTR) {
        continue;
      }
      if (n < 0) {
        const int err = errno;
        ::close(fd);
        ::unlink(tmp.c_str());
        COREDEM_CHECK(false, "cannot write '{}': {}", tmp.string(), std::strerror(err));
      }
      done += std::size_t(n);
    }
    const bool synced = ::fsync(fd) == 0;
    ::close(fd);
    if (!synced) {
      ::unlink(tmp.c_str());
      COREDEM_CHECK(false, "fsync of '{}' failed: {}", tmp.string(), std::strerror(errno));
    }
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    COREDEM_CHECK(false, "cannot rename '{}' to '{}': {}", tmp.string(), path.string(),
                  std::strerror(err));
  }
  fsyncPath(path.parent_path().empty() ? fs::path(".") : path.parent_path(), true);
}

} // namespace coredem
