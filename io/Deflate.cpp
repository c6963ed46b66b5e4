// zlib's inflate over a byte range of a file, the output discarded or the first bytes kept;
// libdeflate's one-call gzip decoder for a whole file.
#include "Deflate.h"

#include <libdeflate.h>
#include <zlib.h>

#include <algorithm>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "HugePages.h"
#include "ReadVolume.h"

namespace surftrack::io::detail {

namespace {

[[noreturn]] void corrupt(const OpenFile& file, const std::string& why) {
  throw ReadError(file.context() + ": corrupt compressed data (" + why + ")");
}

std::string zlibError(const z_stream& z, int status) {
  return z.msg ? z.msg : "zlib error " + std::to_string(status);
}

/// zlib's inflate over bytes [offset, offset + length) of `file` (windowBits as inflateInit2
/// takes them), the one loop of both checks and decodes here: the first `keep` bytes inflated
/// go to `out` (nullptr: counted, not kept) and inflation stops there, unless `toEnd`, which
/// inflates the rest into a scratch buffer and requires the last stream to end. With `members`,
/// a stream followed by another gzip member goes on into it, as gzread does; other bytes after
/// a stream are ignored. Returns min(keep, the bytes inflated).
std::uint64_t inflateRange(const OpenFile& file, std::uint64_t offset, std::uint64_t length, int windowBits,
                           unsigned char* out, std::uint64_t keep, bool toEnd, bool members) {
  z_stream z{};
  if (inflateInit2(&z, windowBits) != Z_OK) corrupt(file, "zlib cannot start");
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  std::vector<unsigned char> in(kChunk), scratch;
  std::uint64_t read = 0, made = 0;
  bool ended = false;  // the last stream read to its end
  for (;;) {
    const bool keeping = made < keep;
    if (!keeping && !toEnd) break;
    if (keeping && out) {
      z.next_out = out + made;
      z.avail_out = uInt(std::min<std::uint64_t>(keep - made, std::uint64_t(1) << 30));
    } else {
      scratch.resize(kChunk);
      z.next_out = scratch.data();
      z.avail_out = uInt(keeping ? std::min<std::uint64_t>(keep - made, kChunk) : kChunk);
    }
    if (z.avail_in == 0) {
      const std::size_t n =
          read < length ? file.readAt(offset + read, in.data(), std::size_t(std::min<std::uint64_t>(kChunk, length - read))) : 0;
      if (n == 0) break;  // the range ends (inside a stream, unless `ended`)
      read += n;
      z.next_in = in.data();
      z.avail_in = uInt(n);
    }
    const uInt room = z.avail_out;
    const int status = inflate(&z, Z_NO_FLUSH);
    if (keeping) made += room - z.avail_out;
    ended = status == Z_STREAM_END;
    if (ended) {
      const std::uint64_t at = read - z.avail_in;  // the byte after the stream
      unsigned char magic[2] = {0, 0};
      if (!members || at + 2 > length || file.readAt(offset + at, magic, 2) < 2 || magic[0] != 0x1f || magic[1] != 0x8b)
        break;
      inflateReset(&z);
    } else if (status != Z_OK && !(status == Z_BUF_ERROR && z.avail_in == 0)) {
      const std::string why = zlibError(z, status);
      inflateEnd(&z);
      corrupt(file, why);
    }
  }
  inflateEnd(&z);
  if (toEnd && !ended) corrupt(file, "the gzip stream is cut short (truncated file?)");
  return made;
}

}  // namespace

void requireDeflated(const OpenFile& file, std::uint64_t offset, std::uint64_t length, std::uint64_t expected) {
  if (offset > file.size() || file.size() - offset < length) corrupt(file, "the stream runs past the end of the file");
  const std::uint64_t inflated = inflateRange(file, offset, length, 47, nullptr, expected, false, false);
  if (inflated < expected)
    corrupt(file, "it inflates to " + std::to_string(inflated) + " bytes, fewer than the " + std::to_string(expected) +
                      " bytes of voxels (truncated file?)");
}

bool isGzip(const OpenFile& file) {
  const std::string magic = file.head(2);
  return magic.size() == 2 && static_cast<unsigned char>(magic[0]) == 0x1f && static_cast<unsigned char>(magic[1]) == 0x8b;
}

std::size_t inflateGzipPrefix(const OpenFile& file, unsigned char* out, std::size_t bytes, bool checkRest) {
  return std::size_t(inflateRange(file, 0, file.size(), 16 + MAX_WBITS, out, bytes, checkRest, /*members=*/true));
}

Inflated inflateGzip(const OpenFile& file, std::uint64_t bytes, std::uint64_t alignedAt) {
  if (bytes > std::uint64_t(SIZE_MAX) / 2) throw std::bad_alloc();
  // The compressed bytes mapped (read if the system refuses), the output on fresh 2 MiB pages:
  // it is written once, front to back.
  std::string why;
  std::shared_ptr<const void> in = file.map(0, file.size(), why);
  if (!in) in = file.read(0, file.size());
  // (From 1 MiB on, whole 2 MiB pages, as converter/SurfaceMesh.cpp's fresh arrays.)
  constexpr std::size_t kHuge = std::size_t(1) << 21;
  const std::size_t pad = std::size_t((64 - alignedAt % 64) % 64);
  const std::size_t total = std::max<std::size_t>(std::size_t(bytes) + pad, 1);
  const std::size_t align = total >= kHuge / 2 ? kHuge : 64;
  const std::size_t rounded = (total + align - 1) & ~(align - 1);
  void* p = std::aligned_alloc(align, rounded);
  if (!p) throw std::bad_alloc();
  Inflated out{std::shared_ptr<void>(p, [](void* q) { std::free(q); }), static_cast<unsigned char*>(p) + pad};
  if (align == kHuge) adviseHugePages(p, rounded);

  const std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)> decoder(
      libdeflate_alloc_decompressor(), libdeflate_free_decompressor);
  if (!decoder) throw std::bad_alloc();
  const auto* next = static_cast<const unsigned char*>(in.get());
  std::size_t left = std::size_t(file.size()), done = 0;
  // Member after member until the output is full; what follows is ignored, as gzread does.
  while (done < bytes && left >= 2 && next[0] == 0x1f && next[1] == 0x8b) {
    std::size_t used = 0, made = 0;
    const libdeflate_result r = libdeflate_gzip_decompress_ex(decoder.get(), next, left, out.data + done,
                                                              std::size_t(bytes) - done, &used, &made);
    if (r == LIBDEFLATE_INSUFFICIENT_SPACE) {
      // The members hold more than `bytes` (or a damaged one seems to): gzread would read the
      // first `bytes` and stop, and so does zlib here.
      done = inflateGzipPrefix(file, out.data, std::size_t(bytes), /*checkRest=*/true);
      break;
    }
    if (r != LIBDEFLATE_SUCCESS)
      corrupt(file, "the gzip stream" + (done > 0 ? " after byte " + std::to_string(file.size() - left) : std::string()) +
                        " is damaged or cut short (truncated file?)");
    done += made;
    next += used;
    left -= used;
  }
  // Members after the first `bytes` (bgzip's empty end-of-file member, say): checked, as
  // readVolume checks them, into a scratch buffer grown to the size of the largest.
  std::vector<unsigned char> scratch;
  while (done == bytes && left >= 2 && next[0] == 0x1f && next[1] == 0x8b) {
    if (scratch.empty()) scratch.resize(std::size_t(1) << 16);
    std::size_t used = 0, made = 0;
    const libdeflate_result r =
        libdeflate_gzip_decompress_ex(decoder.get(), next, left, scratch.data(), scratch.size(), &used, &made);
    if (r == LIBDEFLATE_INSUFFICIENT_SPACE) {
      if (scratch.size() >= (std::size_t(1) << 28)) {  // a long one: zlib's streaming check
        inflateGzipPrefix(file, out.data, std::size_t(bytes), /*checkRest=*/true);
        break;
      }
      scratch.resize(4 * scratch.size());
      continue;
    }
    if (r != LIBDEFLATE_SUCCESS)
      corrupt(file, "the gzip member at byte " + std::to_string(file.size() - left) + " is damaged or cut short (truncated file?)");
    next += used;
    left -= used;
  }
  if (done < bytes)
    corrupt(file, "it inflates to " + std::to_string(done) + " bytes, fewer than the " + std::to_string(bytes) +
                      " its header announces (truncated file?)");
  return out;
}

}  // namespace surftrack::io::detail
