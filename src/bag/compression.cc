// Decompression of chunks (bz2, lz4 frames, zstd) and reading whole files.
#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <sstream>

#include "container.h"

namespace cheval::bag {

std::string ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, 0, "cannot open the file");
  std::string bytes;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(path, 0, 0, "cannot read the file");
  bytes.resize(static_cast<size_t>(size));
  in.seekg(0);
  in.read(bytes.data(), size);
  if (!in) throw InputError(path, 0, 0, "cannot read the file");
  return bytes;
}

std::string Decompress(std::string_view compression, std::string_view data, uint64_t size, const std::string& path,
                       const std::string& what) {
  // A recorded size far beyond what the data could expand to is corrupt, not a reason to allocate.
  constexpr uint64_t kMaxRatio = 2000;
  if (size > (data.size() + 64) * kMaxRatio) {
    throw InputError(path, 0, 0, fmt::format("{}: says {} uncompressed bytes from {} compressed; corrupt", what, size,
                                             data.size()));
  }
  std::string out(size, '\0');
  auto fail = [&](const std::string& why) {
    throw InputError(path, 0, 0, fmt::format("{}: {} data does not decompress: {}", what, compression, why));
  };
  if (compression == "bz2") {
    unsigned int length = static_cast<unsigned int>(size);
    if (size > 0xffffffffu || data.size() > 0xffffffffu) fail("too large");
    const int status = BZ2_bzBuffToBuffDecompress(out.data(), &length, const_cast<char*>(data.data()),
                                                  static_cast<unsigned int>(data.size()), 0, 0);
    if (status != BZ_OK) fail(fmt::format("bzip2 error {}", status));
    if (length != size) fail(fmt::format("{} bytes instead of {}", length, size));
  } else if (compression == "lz4-frame" || compression == "lz4") {
    LZ4F_dctx* context = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) fail("no lz4 context");
    std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> guard(context, LZ4F_freeDecompressionContext);
    size_t in_pos = 0, out_pos = 0;
    while (in_pos < data.size()) {
      size_t in_size = data.size() - in_pos;
      size_t out_size = out.size() - out_pos;
      const size_t status = LZ4F_decompress(context, out.data() + out_pos, &out_size, data.data() + in_pos, &in_size, nullptr);
      if (LZ4F_isError(status)) fail(LZ4F_getErrorName(status));
      in_pos += in_size;
      out_pos += out_size;
      if (status == 0) break;  // frame complete
      if (in_size == 0 && out_size == 0) fail("truncated frame");
    }
    if (out_pos != size) fail(fmt::format("{} bytes instead of {}", out_pos, size));
  } else if (compression == "zstd") {
    const size_t status = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
    if (ZSTD_isError(status)) fail(ZSTD_getErrorName(status));
    if (status != size) fail(fmt::format("{} bytes instead of {}", status, size));
  } else {
    throw InputError(path, 0, 0, fmt::format("{}: unknown compression '{}'; expected {}", what, compression,
                                             "none, bz2 or lz4 (ROS 1), zstd or lz4 (MCAP)"));
  }
  return out;
}

std::string DecompressZstd(std::string_view data, const std::string& path, const std::string& what) {
  const unsigned long long size = ZSTD_getFrameContentSize(data.data(), data.size());
  if (size == ZSTD_CONTENTSIZE_ERROR) {
    throw InputError(path, 0, 0, fmt::format("{}: not zstd data (no zstd frame header)", what));
  }
  if (size != ZSTD_CONTENTSIZE_UNKNOWN) return Decompress("zstd", data, size, path, what);
  // A frame written by a stream does not record its size: decompress in steps.
  std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> context(ZSTD_createDCtx(), ZSTD_freeDCtx);
  std::string out;
  ZSTD_inBuffer in{data.data(), data.size(), 0};
  size_t status = 1;
  while (status != 0) {
    const size_t used = out.size();
    out.resize(used + std::max<size_t>(ZSTD_DStreamOutSize(), used));
    ZSTD_outBuffer buffer{out.data() + used, out.size() - used, 0};
    status = ZSTD_decompressStream(context.get(), &buffer, &in);
    out.resize(used + buffer.pos);
    if (ZSTD_isError(status)) {
      throw InputError(path, 0, 0, fmt::format("{}: zstd data does not decompress: {}", what, ZSTD_getErrorName(status)));
    }
    if (status != 0 && in.pos == in.size && buffer.pos == 0) {
      throw InputError(path, 0, 0, fmt::format("{}: zstd data does not decompress: truncated frame", what));
    }
  }
  return out;
}

}  // namespace cheval::bag
