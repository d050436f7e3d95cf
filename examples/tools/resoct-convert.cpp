// resoct-convert: writes a procedural volume, a volume file (OME-Zarr, NIfTI, NRRD, TIFF, brick
// store) or a raw binary file as a resoct brick store (.rbs).
// See docs/tools.md.

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/storage/codec.hpp"
#include "resoct/base/error.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/io/formats/raw_volume.hpp"
#include "support/cli_parse.hpp"
#include "support/output_path.hpp"
#include "support/progress.hpp"
#include "support/source_options.hpp"
#include "support/tool_main.hpp"

namespace {

using namespace resoct;
using namespace resoct::tools;

constexpr const char* kTool = "resoct-convert";
constexpr const char* kRawTypes = "u8, u16, f32, i8, i16, i32, u32, f64";

struct Args {
  SourceOptions source;
  std::string input, output;
  // Raw input.
  std::string dims, type, endian = "little", spacing, range;
  std::uint32_t channels = 1;
  std::uint64_t offset = 0;
  // Store encoding.
  std::string brick = "32", codec = "lz4";
  std::uint32_t halo = 1;
  int level = 0;
  std::uint32_t metadata_block = 16;
  bool brick_errors = false;  // --brick-errors: store every brick's down-sampling error
  std::uint32_t threads = 0;
};

BrickLayout parse_layout(const Args& a) {
  BrickLayout layout;
  layout.brick_size = parse_brick(a.brick, "--brick");
  layout.halo = a.halo;
  try {
    layout.validate();
  } catch (const Error& e) {
    const bool brick = std::string_view(e.what()).find("brick_size") != std::string_view::npos;
    throw Error(e.code(), std::string(brick ? "--brick: " : "--halo: ") + e.what());
  }
  return layout;
}

void check_metadata_block(std::uint32_t b) {
  if (b < 4 || b > 1024 || (b & (b - 1)) != 0) {
    throw invalid_parameter("--metadata-block",
                            "must be a power of two in 4..1024, got " + std::to_string(b));
  }
}

// f32 raw data has no natural range, so without --range it is taken from the finite voxels of
// each channel (one pass over the mapped file).
std::vector<ValueRange> scan_f32_ranges(const DenseVolume& v) {
  std::vector<ValueRange> ranges;
  for (std::uint32_t c = 0; c < v.desc().channels; ++c) {
    const auto bytes = v.channel_bytes(c);
    float lo = std::numeric_limits<float>::infinity();
    float hi = -lo;
    for (std::size_t i = 0; i + 4 <= bytes.size(); i += 4) {
      float x;
      std::memcpy(&x, bytes.data() + i, 4);
      if (!std::isfinite(x)) continue;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    if (!(lo <= hi)) {  // no finite voxel at all
      lo = 0.0f;
      hi = 1.0f;
    }
    ValueRange r{double(lo), double(hi)};
    if (!(r.lo < r.hi)) r.hi = r.lo + 1.0;  // constant channel
    ranges.push_back(r);
  }
  return ranges;
}

std::unique_ptr<BrickSource> open_raw(const Args& a, const CLI::App& app,
                                      const BrickLayout& layout) {
  // A missing file is the likelier mistake than missing raw options: say that first.
  struct stat st {};
  if (::stat(a.input.c_str(), &st) != 0) {
    throw file_error(ErrorCode::io, a.input, 0,
                     std::string("cannot open input: ") + std::strerror(errno) +
                         " (input is procedural:NAME[:WxHxD[:CHANNELS]] or a raw file)");
  }
  if (app.count("--dims") == 0) {
    throw invalid_parameter("--dims",
                            "required for raw input '" + a.input + "' (e.g. 256x256x128)");
  }
  if (app.count("--type") == 0) {
    throw invalid_parameter("--type",
                            "required for raw input '" + a.input + "' (" + kRawTypes + ")");
  }
  RawVolumeOptions o;
  o.extent = parse_dims(a.dims, "--dims");
  const auto type = parse_data_type(a.type);
  if (!type) {
    throw invalid_parameter("--type",
                            std::string("expected one of ") + kRawTypes + ", got '" + a.type + "'");
  }
  o.data_type = *type;
  if (!data_mapping(*type).exact) {
    std::fprintf(stderr, "%s: values of type %s\n", kTool, describe_mapping(*type).c_str());
  }
  const auto endian = parse_endian(a.endian);
  if (!endian) {
    throw invalid_parameter("--endian", "expected little or big, got '" + a.endian + "'");
  }
  o.endian = *endian;
  if (app.count("--spacing") != 0) o.spacing = parse_spacing(a.spacing, "--spacing");
  o.channels = a.channels;
  o.offset = a.offset;
  if (app.count("--range") != 0) {
    o.ranges.assign(a.channels, parse_range(a.range, "--range"));
  }
  DenseVolume volume = open_raw_volume(a.input, o);
  if (volume.desc().type == VoxelType::f32 && o.ranges.empty()) {
    VolumeDesc desc = volume.desc();
    desc.ranges = scan_f32_ranges(volume);
    std::fprintf(stderr, "%s: f32 value range of channel 0 taken from the data: [%g, %g]\n", kTool,
                 desc.ranges[0].lo, desc.ranges[0].hi);
    auto keep = std::make_shared<DenseVolume>(std::move(volume));
    volume = DenseVolume::from_pointer(std::move(desc), keep->bytes().data(), keep->bytes().size(),
                                       keep);
  }
  std::fprintf(stderr, "%s: computing the coarse levels of %s in memory\n", kTool, a.input.c_str());
  return std::make_unique<InMemorySource>(std::move(volume), layout, a.metadata_block, a.input);
}

void print_summary(const Args& a, const BrickSource& src, const StoreSummary& s, double seconds) {
  const StoreLevelStats t = s.stats.total();
  const VolumeDesc& v = src.volume();
  const std::uint64_t input_bytes = v.voxel_count() * v.channels * voxel_size(v.type);
  const double ratio = t.compression_ratio();
  char ratio_text[32];
  if (std::isfinite(ratio)) {
    std::snprintf(ratio_text, sizeof ratio_text, "%.2f", ratio);
  } else {
    std::snprintf(ratio_text, sizeof ratio_text, "inf");
  }
  std::printf(
      "Wrote %s: %llux%llux%llu %s, %u channel(s), %zu levels, %llu bricks (%llu constant, %llu "
      "empty); %s of padded bricks compressed to %s with %s (ratio %s), file %s. Input %s "
      "(level 0) in %.2f s = %.1f MB/s, %u thread(s).\n",
      a.output.c_str(), static_cast<unsigned long long>(v.extent.x),
      static_cast<unsigned long long>(v.extent.y), static_cast<unsigned long long>(v.extent.z),
      std::string(to_string(v.file_type())).c_str(), v.channels, s.stats.levels.size(),
      static_cast<unsigned long long>(t.brick_count),
      static_cast<unsigned long long>(t.constant_bricks),
      static_cast<unsigned long long>(t.empty_bricks), format_bytes(t.uncompressed_bytes).c_str(),
      format_bytes(t.compressed_bytes).c_str(), std::string(to_string(s.stats.codec)).c_str(),
      ratio_text, format_bytes(s.stats.file_bytes).c_str(), format_bytes(input_bytes).c_str(),
      seconds, seconds > 0.0 ? double(input_bytes) / 1e6 / seconds : 0.0,
      std::min(256u,
               a.threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : a.threads));
  if (s.stats.brick_errors) {
    std::printf("Brick errors stored (fraction of the value range, largest / mean):");
    for (std::size_t l = 1; l < s.stats.levels.size(); ++l) {
      std::printf(" level %zu %.3g / %.3g%s", l, s.stats.levels[l].max_error,
                  s.stats.levels[l].mean_error, l + 1 < s.stats.levels.size() ? "," : ".\n");
    }
    if (s.stats.levels.size() < 2) std::printf(" one level, none to store.\n");
  }
}

int convert(const Args& a, const CLI::App& app) {
  const auto start = std::chrono::steady_clock::now();
  const auto codec = parse_codec(a.codec);
  if (!codec) {
    throw invalid_parameter("--codec", "expected lz4 or zstd, got '" + a.codec + "'");
  }
  try {
    validate_codec_level(*codec, a.level);
  } catch (const Error& e) {
    throw Error(e.code(), std::string("--level: ") + e.what());
  }
  const BrickLayout layout = parse_layout(a);
  check_metadata_block(a.metadata_block);
  // Fails before any work when the store could never be written, rather than after minutes of
  // conversion (the writer itself would also refuse, atomically).
  check_output_path("output", a.output);

  std::unique_ptr<BrickSource> src;
  const char* const raw_options[] = {"--dims",     "--type",   "--endian", "--spacing",
                                     "--channels", "--offset", "--range"};
  bool raw_given = false;
  for (const char* o : raw_options) raw_given = raw_given || app.count(o) != 0;
  const SourceKind kind = detect_source_kind(a.input);
  if (kind == SourceKind::procedural) {
    for (const char* raw_only : raw_options) {
      if (app.count(raw_only) != 0) {
        throw invalid_parameter(raw_only,
                                "applies to raw input only; a procedural spec carries "
                                "its size and channels: procedural:NAME:WxHxD:C");
      }
    }
    src = make_procedural_source(a.input, layout);
  } else if ((kind == SourceKind::unknown && !is_remote_spec(a.input)) || raw_given) {
    // Raw options make any file raw (e.g. a header skipped with --offset).
    src = open_raw(a, app, layout);
  } else {
    std::fprintf(stderr, "%s: reading %s (coarser levels are built while writing)\n", kTool,
                 a.input.c_str());
    src = open_source(a.input, layout, a.source);
  }

  std::unique_ptr<Progress> progress;
  std::uint64_t reported = 0;
  StoreWriteOptions w;
  w.codec = *codec;
  w.level = a.level;
  w.metadata_block = a.metadata_block;
  w.threads = a.threads;
  w.brick_errors = a.brick_errors;
  w.progress = [&](std::uint64_t done, std::uint64_t total) {
    if (!progress) progress = std::make_unique<Progress>("writing " + a.output, total);
    progress->advance(done - reported);
    reported = done;
  };
  const StoreSummary summary = write_brick_store(*src, a.output, w);
  if (progress) progress->finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  print_summary(a, *src, summary, seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Converts a procedural volume, a volume file (OME-Zarr directory, NIfTI .nii/.nii.gz, NRRD "
      ".nrrd/.nhdr, TIFF file or directory, brick store, stack:A+B) or a raw binary volume file "
      "into a resoct brick store (.rbs). Raw input keeps its coarser levels in memory (about 1/7 "
      "of the input)."};
  one_line_usage_errors(app, kTool);
  Args a;
  app.add_option("input", a.input,
                 std::string(kSourceSpecForms) + ", or a raw file (needs --dims and --type)")
      ->required();
  app.add_option("output", a.output, "brick store to write (replaced atomically)")->required();
  add_source_options(app, a.source);
  auto* raw = "Raw input";
  app.add_option("--dims", a.dims, "raw: voxels per axis, WxHxD")->group(raw);
  app.add_option("--type", a.type,
                 std::string("raw: value type ") + kRawTypes +
                     " (i8/i16 kept exactly as u8/u16 plus an offset; i32, u32, f64 as f32)")
      ->group(raw);
  app.add_option("--endian", a.endian, "raw: byte order little or big (default little)")
      ->group(raw);
  app.add_option("--spacing", a.spacing, "raw: voxel size X,Y,Z (default 1,1,1)")->group(raw);
  app.add_option("--channels", a.channels, "raw: channels stored one after another (default 1)")
      ->group(raw);
  app.add_option("--offset", a.offset, "raw: header bytes to skip (default 0)")->group(raw);
  app.add_option("--range", a.range,
                 "raw: value range LO,HI of every channel in the file's units (default: the "
                 "type's full range; for f32, i32, u32, f64 the data's finite min/max)")
      ->group(raw);
  app.add_option("--brick", a.brick, "core brick size N or NxNxN (4..1024, default 32)");
  app.add_option("--halo", a.halo, "halo voxels per side (0..4, default 1)");
  app.add_option("--codec", a.codec, "payload codec lz4 or zstd (default lz4)");
  app.add_option("--level", a.level, "codec level, 0 = the codec's default");
  app.add_option("--metadata-block", a.metadata_block,
                 "metadata pyramid block edge in voxels (power of two, default 16)");
  app.add_option("--threads", a.threads, "worker threads, 0 = all cores (default)");
  app.add_flag("--brick-errors", a.brick_errors,
               "store every coarse brick's down-sampling error, so that error-bounded LOD "
               "(resoct-render --lod-error-color) reads it instead of measuring (reads level 0 "
               "about three more times)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return run_tool(kTool, [&] { return convert(a, app); });
}
