// POSIX file access for the loader: open/fstat, pread, mmap, mincore.
#include "MappedFile.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <limits>
#include <new>
#include <vector>

#include "ReadVolume.h"

namespace surftrack::io::detail {

namespace {

std::uint64_t pageSize() {
  static const std::uint64_t page = std::uint64_t(::sysconf(_SC_PAGESIZE));
  return page;
}

}  // namespace

OpenFile::OpenFile(const std::string& path, std::string context) : context_(std::move(context)) {
  // O_NONBLOCK: opening a FIFO named by a header must not wait for a writer; it is then
  // refused as not a regular file.
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0)
    throw ReadError(context_ + ": " + (errno == ENOENT ? std::string("no such file") : std::strerror(errno)));
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int e = errno;
    ::close(fd_);
    throw ReadError(context_ + ": " + std::strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd_);
    throw ReadError(context_ + (S_ISDIR(st.st_mode) ? ": it is a directory" : ": not a regular file"));
  }
  size_ = std::uint64_t(st.st_size);
}

OpenFile::~OpenFile() {
  if (fd_ >= 0) ::close(fd_);
}

void OpenFile::requireRange(std::uint64_t offset, std::uint64_t bytes) const {
  if (offset > size_ || size_ - offset < bytes)
    throw ReadError(context_ + ": the file has " + std::to_string(size_) + " bytes, fewer than the " +
                    std::to_string(bytes) + " bytes of voxels at byte " + std::to_string(offset) +
                    " (truncated file?)");
}

std::string OpenFile::head(std::size_t bytes) const {
  std::string out(std::size_t(std::min<std::uint64_t>(bytes, size_)), '\0');
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::pread(fd_, out.data() + done, out.size() - done, off_t(done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw ReadError(context_ + ": read error: " + std::strerror(errno));
    if (n == 0) break;  // the file shrank since fstat: parse what there is
    done += std::size_t(n);
  }
  out.resize(done);
  return out;
}

std::size_t OpenFile::readAt(std::uint64_t offset, void* buffer, std::size_t bytes) const {
  auto* out = static_cast<unsigned char*>(buffer);
  std::size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::pread(fd_, out + done, bytes - done, off_t(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw ReadError(context_ + ": read error: " + std::strerror(errno));
    if (n == 0) break;
    done += std::size_t(n);
  }
  return done;
}

std::shared_ptr<const void> OpenFile::map(std::uint64_t offset, std::uint64_t bytes, std::string& why) const {
  requireRange(offset, bytes);
  if (bytes == 0) throw ReadError(context_ + ": no voxels to map");
  // mmap maps whole pages from a page-aligned file offset: map from the page holding `offset`.
  const std::uint64_t start = offset - offset % pageSize();
  const std::uint64_t length = bytes + (offset - start);
  if (length > std::uint64_t(SIZE_MAX) || start > std::uint64_t(std::numeric_limits<off_t>::max())) {
    why = "the voxels do not fit in the address space";
    return nullptr;
  }
  // Read-only MAP_SHARED: the pages are the page cache's own (shared with any other reader of
  // the file, never copied, no swap or commit charge). No madvise: the kernel's default
  // read-ahead suits both ways the engine reads — surface tracking touches the slices around the
  // surface, scans sweep rows in order —, whereas MADV_RANDOM would read a scan page by page,
  // MADV_SEQUENTIAL drop pages tracking comes back to, and MADV_WILLNEED read the whole file.
  void* base = ::mmap(nullptr, std::size_t(length), PROT_READ, MAP_SHARED, fd_, off_t(start));
  if (base == MAP_FAILED) {
    why = std::string("mmap failed: ") + std::strerror(errno);
    return nullptr;
  }
  // The size was checked before mapping; check it again now that the mapping exists, so that a
  // file that shrank in between is an error here rather than a SIGBUS on first access. (A file
  // that shrinks later still raises SIGBUS: see LoadVolume.h.)
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || std::uint64_t(st.st_size) < offset + bytes) {
    ::munmap(base, std::size_t(length));
    throw ReadError(context_ + ": the file shrank while it was being mapped (truncated file?)");
  }
  const void* data = static_cast<const unsigned char*>(base) + (offset - start);
  // (If allocating the control block throws, shared_ptr calls the deleter: no leak.)
  return std::shared_ptr<const void>(data, [base, length](const void*) { ::munmap(base, std::size_t(length)); });
}

std::shared_ptr<void> OpenFile::read(std::uint64_t offset, std::uint64_t bytes) const {
  requireRange(offset, bytes);
  if (bytes > std::uint64_t(SIZE_MAX)) throw std::bad_alloc();
  constexpr std::align_val_t kAlign{64};
  void* p = ::operator new(std::max<std::size_t>(std::size_t(bytes), 1), kAlign);
  std::shared_ptr<void> buffer(p, [](void* q) { ::operator delete(q, kAlign); });
  auto* out = static_cast<unsigned char*>(p);
  std::uint64_t done = 0;
  while (done < bytes) {
    const std::size_t chunk = std::size_t(std::min<std::uint64_t>(bytes - done, std::uint64_t(1) << 30));
    const ssize_t n = ::pread(fd_, out + done, chunk, off_t(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw ReadError(context_ + ": read error: " + std::strerror(errno));
    if (n == 0) throw ReadError(context_ + ": the file shrank while it was being read (truncated file?)");
    done += std::uint64_t(n);
  }
  return buffer;
}

bool adviseAccess(const void* data, std::uint64_t bytes, bool sparse) {
  if (!data || bytes == 0) return true;
  const std::uint64_t page = pageSize();
  const auto first = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = first - first % page;
  return ::madvise(reinterpret_cast<void*>(begin), std::size_t(first + bytes - begin),
                   sparse ? MADV_RANDOM : MADV_NORMAL) == 0;
}

std::uint64_t residentBytes(const void* data, std::uint64_t bytes) {
  if (!data || bytes == 0) return 0;
  const std::uint64_t page = pageSize();
  const auto first = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = first - first % page;
  const std::uint64_t end = first + bytes;
  // mincore() one chunk of pages at a time, so that a large mapping needs a small vector.
  constexpr std::uint64_t kChunkPages = std::uint64_t(1) << 16;
  std::vector<unsigned char> resident(kChunkPages);
  std::uint64_t total = 0;
  for (std::uint64_t at = begin; at < end; at += kChunkPages * page) {
    const std::uint64_t length = std::min<std::uint64_t>(end - at, kChunkPages * page);
    if (::mincore(reinterpret_cast<void*>(at), std::size_t(length), resident.data()) != 0) return 0;
    const std::uint64_t pages = (length + page - 1) / page;
    for (std::uint64_t i = 0; i < pages; ++i) {
      if (!(resident[i] & 1)) continue;
      const std::uint64_t lo = std::max<std::uint64_t>(at + i * page, first);
      const std::uint64_t hi = std::min<std::uint64_t>(at + (i + 1) * page, end);
      total += hi - lo;
    }
  }
  return total;
}

}  // namespace surftrack::io::detail
