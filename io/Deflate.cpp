// zlib's inflate over a byte range of a file, the output discarded.
#include "Deflate.h"

#include <zlib.h>

#include <algorithm>
#include <string>
#include <vector>

#include "ReadVolume.h"

namespace surftrack::io::detail {

void requireDeflated(const OpenFile& file, std::uint64_t offset, std::uint64_t length, std::uint64_t expected) {
  auto fail = [&](const std::string& why) {
    throw ReadError(file.context() + ": corrupt compressed data (" + why + ")");
  };
  if (offset > file.size() || file.size() - offset < length) fail("the stream runs past the end of the file");
  z_stream z{};
  if (inflateInit2(&z, 47) != Z_OK) fail("zlib cannot start");
  constexpr std::size_t kChunk = std::size_t(1) << 20;
  std::vector<unsigned char> in(kChunk), out(kChunk);
  std::uint64_t read = 0, inflated = 0;
  int status = Z_OK;
  while (status != Z_STREAM_END && inflated < expected) {
    if (z.avail_in == 0) {
      if (read == length) break;  // the stream ends before its end: truncated
      const std::size_t n = file.readAt(offset + read, in.data(), std::size_t(std::min<std::uint64_t>(kChunk, length - read)));
      if (n == 0) break;
      read += n;
      z.next_in = in.data();
      z.avail_in = uInt(n);
    }
    z.next_out = out.data();
    z.avail_out = uInt(out.size());
    status = inflate(&z, Z_NO_FLUSH);
    inflated += out.size() - z.avail_out;
    if (status != Z_OK && status != Z_STREAM_END && !(status == Z_BUF_ERROR && z.avail_in == 0)) {
      const std::string why = z.msg ? z.msg : "zlib error " + std::to_string(status);
      inflateEnd(&z);
      fail(why);
    }
  }
  inflateEnd(&z);
  if (inflated < expected)
    fail("it inflates to " + std::to_string(inflated) + " bytes, fewer than the " + std::to_string(expected) +
         " bytes of voxels (truncated file?)");
}

}  // namespace surftrack::io::detail
