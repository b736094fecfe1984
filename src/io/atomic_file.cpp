#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.hpp"

namespace ibrod::io {

std::string io_error_text(int err) {
  std::string s = std::strerror(err);
  if (err == ENOSPC || err == EDQUOT || err == EFBIG)
    s += " (disk full or over a file-size quota?)";
  if (err == EACCES || err == EPERM || err == EROFS) s += " (no permission to write there?)";
  return s;
}

AtomicFile::AtomicFile(std::filesystem::path target)
    : target_(std::move(target)), tmp_(target_.string() + ".tmp") {
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw RunError("output: cannot create " + tmp_.string() + ": " + io_error_text(errno));
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) ::unlink(tmp_.c_str());
}

void AtomicFile::write(const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t w = ::write(fd_, p, bytes);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw RunError("output: cannot write " + tmp_.string() + ": " + io_error_text(errno) + "; " +
                     target_.filename().string() + " was left as it was");
    }
    p += w;
    bytes -= std::size_t(w);
  }
}

void AtomicFile::write_at(std::uint64_t offset, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t w = ::pwrite(fd_, p, bytes, off_t(offset));
    if (w < 0) {
      if (errno == EINTR) continue;
      throw RunError("output: cannot write " + tmp_.string() + ": " + io_error_text(errno));
    }
    p += w;
    offset += std::uint64_t(w);
    bytes -= std::size_t(w);
  }
}

void AtomicFile::commit(bool durable) {
  // fsync before the rename: otherwise a crash may leave the new name on an empty file
  if (durable && ::fsync(fd_) != 0)
    throw RunError("output: cannot sync " + tmp_.string() + ": " + io_error_text(errno));
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0)  // NFS and quotas may report a failed write only here
    throw RunError("output: cannot write " + tmp_.string() + ": " + io_error_text(errno));
  if (std::rename(tmp_.c_str(), target_.c_str()) != 0)
    throw RunError("output: cannot rename " + tmp_.string() + " to " + target_.string() + ": " +
                   io_error_text(errno));
  committed_ = true;
  if (durable) {
    // the rename itself is durable only once the directory is synced
    const std::filesystem::path parent =
        target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
    const int dfd = ::open(parent.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      ::fsync(dfd);
      ::close(dfd);
    }
  }
}

void write_file_atomic(const std::filesystem::path& path, std::string_view text, bool durable) {
  AtomicFile f(path);
  f.write(text);
  f.commit(durable);
}

}  // namespace ibrod::io
