// Fuzz target: a multi-page TIFF file through open_tiff_stack (libtiff decodes; resoct checks
// page layout, size and type agreement and assembles the z stack), then bricks and metadata.
//
// Inputs whose pages would decode to more than kMaxDecodedBytes are not opened. A few hundred
// compressed bytes can legitimately decode to megabytes, which the reader then scans voxel by
// voxel at open; under coverage instrumentation that ran at 76 inputs per second and spent 72 %
// of its time in those scan loops (perf), which are the same for any volume size and are fuzzed
// through the other file targets. Image decoders' fuzzers bound decoding the same way (image-rs's
// TIFF fuzzer caps its decoding buffer at 1 MB). At 1 MiB the grown corpus still ran at 60 inputs
// per second, half of it in comparison tracing inside those loops; at 16 KiB (pages of up to
// 128 x 128 u8: every strip, tile, compression and multi-page layout the reader handles still
// fits) it runs at about 1 300 per second, with the same coverage after a minute. Claims the
// reader rejects before decoding (beyond what the file can hold) still reach it.

#include <cstddef>
#include <cstdarg>
#include <cstdint>

#include <tiffio.h>

#include "fuzz_support.hpp"
#include "resoct/io/formats/tiff_stack.hpp"

namespace {

constexpr std::uint64_t kMaxDecodedBytes = 1u << 14;

int ignore(TIFF*, void*, const char*, const char*, va_list) {
  return 1;
}

/// Whether open_tiff_stack would decode more than kMaxDecodedBytes of pixels from the file of
/// `size` bytes at `path`: the pages' width x height x sample bytes, summed the way the reader
/// charges them against its budget (size * 4096 + 1 MiB; a page past it is rejected before it is
/// decoded). False when libtiff cannot open the file (the reader reports that itself).
bool decodes_too_much(const char* path, std::uint64_t size) {
  TIFFOpenOptions* o = TIFFOpenOptionsAlloc();
  TIFFOpenOptionsSetErrorHandlerExtR(o, ignore, nullptr);
  TIFFOpenOptionsSetWarningHandlerExtR(o, ignore, nullptr);
  // "m": read, not memory-map: unmapping a file per input cost a tenth of the run (TLB flushes).
  TIFF* t = TIFFOpenExt(path, "rm", o);
  TIFFOpenOptionsFree(o);
  if (t == nullptr) return false;
  const std::uint64_t budget = size * 4096 + (1u << 20);
  std::uint64_t decoded = 0;
  bool too_much = false;
  do {
    std::uint32_t w = 0, h = 0;
    std::uint16_t bits = 8;
    TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &w);
    TIFFGetField(t, TIFFTAG_IMAGELENGTH, &h);
    TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &bits);
    std::uint64_t page = 0;
    if (__builtin_mul_overflow(std::uint64_t(w) * (bits / 8u), std::uint64_t(h), &page) ||
        page > budget - decoded) {
      break;  // rejected by the reader before decoding this page
    }
    decoded += page;
    if (decoded > kMaxDecodedBytes) {
      too_much = true;
      break;
    }
  } while (TIFFReadDirectory(t) == 1);
  TIFFClose(t);
  return too_much;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  static fuzz::ScratchFile file("resoct-fuzz-tiff");
  file.write(data, size);
  if (decodes_too_much(file.path().c_str(), size)) return 0;
  fuzz::errors_only([&] {
    const auto src = open_tiff_stack(file.path(), BrickLayout{glm::uvec3(8), 1});
    fuzz::exercise_source(*src, 64);
  });
  return 0;
}
