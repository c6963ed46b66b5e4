// One chunk decoded by libblosc, libzstd or libdeflate, its size checked before and after:
// libblosc trusts the sizes in its header, so the header is validated against the bytes read
// first; the other decoders are given exactly the room the chunk's voxels take.
#include "ChunkCodecs.h"

#include <blosc.h>
#include <libdeflate.h>
#include <zstd.h>
#include <zstd_errors.h>

#include <cstring>
#include <memory>
#include <string>

#include "ReadVolume.h"

namespace surftrack::io::detail {

namespace {

[[noreturn]] void fail(const std::string& context, const std::string& why) { throw ReadError(context + ": " + why); }

std::string sizeText(std::size_t made, std::size_t expected) {
  return "decodes to " + std::to_string(made) + " bytes where the chunk holds " + std::to_string(expected);
}

void decodeBlosc(const unsigned char* in, std::size_t size, unsigned char* out, std::size_t expected,
                 const std::string& context) {
  std::size_t nbytes = 0;
  if (size < BLOSC_MIN_HEADER_LENGTH || blosc_cbuffer_validate(in, size, &nbytes) != 0)
    fail(context, "corrupt blosc data (its header does not match the " + std::to_string(size) + " bytes stored)");
  if (nbytes != expected) fail(context, "blosc data " + sizeText(nbytes, expected));
  // One internal thread: ChunkCache decodes chunks on several threads already.
  const int made = blosc_decompress_ctx(in, out, expected, 1);
  if (made < 0) {
    const char* library = blosc_cbuffer_complib(in);
    fail(context, "corrupt blosc data (libblosc error " + std::to_string(made) + (library ? std::string(", codec ") + library : "") + ")");
  }
  if (std::size_t(made) != expected) fail(context, "blosc data " + sizeText(std::size_t(made), expected));
}

void decodeZstd(const unsigned char* in, std::size_t size, unsigned char* out, std::size_t expected,
                const std::string& context) {
  struct FreeContext {
    void operator()(ZSTD_DCtx* c) const { ZSTD_freeDCtx(c); }
  };
  thread_local std::unique_ptr<ZSTD_DCtx, FreeContext> dctx(ZSTD_createDCtx());
  if (!dctx) throw std::bad_alloc();
  const std::size_t made = ZSTD_decompressDCtx(dctx.get(), out, expected, in, size);
  if (ZSTD_isError(made)) {
    if (ZSTD_getErrorCode(made) == ZSTD_error_dstSize_tooSmall)
      fail(context, "zstd data decodes to more than the " + std::to_string(expected) + " bytes the chunk holds");
    fail(context, std::string("corrupt zstd data (") + ZSTD_getErrorName(made) + ")");
  }
  if (made != expected) fail(context, "zstd data " + sizeText(made, expected));
}

/// zlib: one stream; gzip: one member or more, as gzip concatenates them.
void decodeDeflate(bool gzip, const unsigned char* in, std::size_t size, unsigned char* out, std::size_t expected,
                   const std::string& context) {
  struct FreeDecompressor {
    void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
  };
  thread_local std::unique_ptr<libdeflate_decompressor, FreeDecompressor> decompressor(libdeflate_alloc_decompressor());
  if (!decompressor) throw std::bad_alloc();
  const char* name = gzip ? "gzip" : "zlib";
  std::size_t used = 0, made = 0;
  do {
    std::size_t in_n = 0, out_n = 0;
    const libdeflate_result r =
        gzip ? libdeflate_gzip_decompress_ex(decompressor.get(), in + used, size - used, out + made, expected - made, &in_n, &out_n)
             : libdeflate_zlib_decompress_ex(decompressor.get(), in + used, size - used, out + made, expected - made, &in_n, &out_n);
    if (r == LIBDEFLATE_INSUFFICIENT_SPACE)
      fail(context, std::string(name) + " data decodes to more than the " + std::to_string(expected) + " bytes the chunk holds");
    if (r != LIBDEFLATE_SUCCESS) fail(context, std::string("corrupt or truncated ") + name + " data");
    used += in_n;
    made += out_n;
    // Another gzip member follows (its magic bytes); anything else after the stream is ignored.
  } while (gzip && made < expected && size - used >= 2 && in[used] == 0x1f && in[used + 1] == 0x8b);
  if (made != expected) fail(context, std::string(name) + " data " + sizeText(made, expected));
}

}  // namespace

void decodeChunk(const ChunkCodec& codec, const unsigned char* in, std::size_t size, unsigned char* out,
                 std::size_t expected, const std::string& context) {
  switch (codec.kind) {
    case ChunkCodec::Kind::Raw:
      if (size != expected) fail(context, "holds " + std::to_string(size) + " bytes where the chunk holds " + std::to_string(expected));
      std::memcpy(out, in, size);
      return;
    case ChunkCodec::Kind::Blosc: return decodeBlosc(in, size, out, expected, context);
    case ChunkCodec::Kind::Zstd: return decodeZstd(in, size, out, expected, context);
    case ChunkCodec::Kind::Zlib: return decodeDeflate(false, in, size, out, expected, context);
    case ChunkCodec::Kind::Gzip: return decodeDeflate(true, in, size, out, expected, context);
  }
}

}  // namespace surftrack::io::detail
