#pragma once
// Files that are either complete or absent: written to "<target>.tmp", then renamed over the
// target (rename is atomic on POSIX), so a reader, a killed run or a full disk never leaves a
// half-written target; the previous version stays in place until the new one is complete.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace ibrod::io {

class AtomicFile {
 public:
  /// Opens "<target>.tmp" for writing (truncating it). Throws RunError.
  explicit AtomicFile(std::filesystem::path target);
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends bytes. Throws RunError naming the file and the cause (disk full, file too large, …).
  void write(const void* data, std::size_t bytes);
  void write(std::string_view text) { write(text.data(), text.size()); }
  /// Overwrites bytes already written at `offset` (a header filled in last).
  void write_at(std::uint64_t offset, const void* data, std::size_t bytes);
  /// Closes and renames over the target. durable: fsync the file before and the directory after
  /// the rename, so that the new version survives a power cut (checkpoints).
  void commit(bool durable);

  const std::filesystem::path& target() const { return target_; }

 private:
  std::filesystem::path target_, tmp_;
  int fd_ = -1;
  bool committed_ = false;
};

/// Writes `text` to `path` atomically (AtomicFile).
void write_file_atomic(const std::filesystem::path& path, std::string_view text,
                       bool durable = false);

/// "No space left on device (disk full?)" and the like: strerror(err) with a hint for the causes a
/// user can act on.
std::string io_error_text(int err);

}  // namespace ibrod::io
