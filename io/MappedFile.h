// Files read in place (POSIX): an open file and its size, its first bytes, a byte range of it
// memory-mapped read-only or read into an aligned buffer, and how much of a mapping is
// resident (mincore). Used by io/LoadVolume.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace surftrack::io::detail {

class OpenFile {
 public:
  /// Opens a regular file for reading. Throws ReadError "<context>: <reason>", where context
  /// names the file (e.g. "cannot read 'a.nhdr': its data file 'a.raw'").
  OpenFile(const std::string& path, std::string context);
  ~OpenFile();
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;

  std::uint64_t size() const { return size_; }
  const std::string& context() const { return context_; }

  /// The first min(bytes, size()) bytes.
  std::string head(std::size_t bytes) const;

  /// Maps bytes [offset, offset + bytes) read-only (offset + bytes <= size(); ReadError
  /// otherwise); the pointer is the byte at `offset` and owns the mapping. Null, with the
  /// reason in `why`, when the system refuses the mapping (the caller then reads instead).
  std::shared_ptr<const void> map(std::uint64_t offset, std::uint64_t bytes, std::string& why) const;

  /// Reads up to `bytes` bytes at `offset` into `buffer`: the count read (less at the end of
  /// the file).
  std::size_t readAt(std::uint64_t offset, void* buffer, std::size_t bytes) const;

  /// Reads bytes [offset, offset + bytes) into a new buffer aligned to 64 bytes.
  std::shared_ptr<void> read(std::uint64_t offset, std::uint64_t bytes) const;

 private:
  void requireRange(std::uint64_t offset, std::uint64_t bytes) const;

  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::string context_;
};

/// Bytes of [data, data + bytes), inside one mapping, whose pages mincore() reports resident;
/// 0 if mincore() fails.
std::uint64_t residentBytes(const void* data, std::uint64_t bytes);

/// madvise() on the pages of [data, data + bytes), inside one mapping: MADV_RANDOM if `sparse`
/// (no read-around: a fault reads its own page), MADV_NORMAL otherwise. False if it fails.
bool adviseAccess(const void* data, std::uint64_t bytes, bool sparse);

}  // namespace surftrack::io::detail
