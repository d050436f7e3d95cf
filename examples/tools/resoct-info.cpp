// resoct-info: prints the hierarchy of a brick store, a procedural source or a volume file, with
// per-level storage numbers for stores; --json emits the same as JSON. See docs/tools.md.

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/open_source.hpp"
#include "support/cli_parse.hpp"
#include "support/source_options.hpp"
#include "support/tool_main.hpp"

namespace {

using namespace resoct;
using namespace resoct::tools;
// Insertion order keeps the output in reading order (volume, layout, levels, totals).
using json = nlohmann::ordered_json;

constexpr const char* kTool = "resoct-info";

std::string xyz(auto v) {
  return std::to_string(v.x) + "x" + std::to_string(v.y) + "x" + std::to_string(v.z);
}

json vec(auto v) {
  return json::array({v.x, v.y, v.z});
}

// JSON has no infinity: a ratio with nothing compressed is null.
json finite_or_null(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

std::uint64_t padded_brick_bytes(const BrickHierarchy& h) {
  return h.layout().padded_voxels() * voxel_size(h.volume().type);
}

json level_json(const BrickHierarchy& h, std::uint32_t l, const StoreStats* stats) {
  const LevelInfo& info = h.level(l);
  const std::uint32_t channels = h.volume().channels;
  json j;
  j["level"] = l;
  j["extent"] = vec(info.extent);
  j["factor_log2"] = vec(info.factor_log2);
  j["factor"] = vec(glm::uvec3(1u) << info.factor_log2);
  j["bricks"] = vec(info.bricks);
  j["bricks_per_channel"] = info.brick_count;
  j["brick_count"] = info.brick_count * channels;
  j["uncompressed_bytes"] = info.brick_count * channels * padded_brick_bytes(h);
  if (stats != nullptr) {
    const StoreLevelStats& s = stats->levels.at(l);
    j["uncompressed_bytes"] = s.uncompressed_bytes;
    j["compressed_bytes"] = s.compressed_bytes;
    j["compression_ratio"] = finite_or_null(s.compression_ratio());
    j["empty_bricks"] = s.empty_bricks;
    j["constant_bricks"] = s.constant_bricks;
    j["empty_fraction"] = s.empty_fraction();
    j["constant_fraction"] =
        s.brick_count == 0 ? 0.0 : double(s.constant_bricks) / double(s.brick_count);
    if (stats->brick_errors) {
      j["max_error"] = s.max_error;
      j["mean_error"] = s.mean_error;
    }
  }
  return j;
}

json describe(const BrickSource& src, const BrickStoreSource* store, SourceKind kind) {
  const BrickHierarchy& h = src.hierarchy();
  const VolumeDesc& v = h.volume();
  const StoreStats* stats = store != nullptr ? &store->stats() : nullptr;
  json j;
  j["source"] = src.name();
  j["kind"] = std::string(to_string(kind));
  json ranges = json::array();
  for (std::uint32_t c = 0; c < v.channels; ++c) {
    ranges.push_back(json::array({v.data_range(c).lo, v.data_range(c).hi}));
  }
  const DataMapping mapping = data_mapping(v.file_type());
  // "type" is the file's value type and "ranges" are in its units; "stored_type" and
  // "value_offset" say how the cache keeps it, "exact" whether that loses nothing.
  j["volume"] = {{"extent", vec(v.extent)},
                 {"spacing", vec(v.spacing)},
                 {"origin", vec(v.origin)},
                 {"physical_size", vec(physical_size(v))},
                 {"channels", v.channels},
                 {"type", std::string(to_string(v.file_type()))},
                 {"stored_type", std::string(to_string(v.type))},
                 {"value_offset", mapping.offset},
                 {"exact", mapping.exact},
                 {"ranges", ranges},
                 // A time series: the count, and which timepoint the rest describes.
                 {"timepoints", src.timepoints()},
                 {"timepoint", src.timepoint()}};
  j["layout"] = {{"brick_size", vec(h.layout().brick_size)},
                 {"halo", h.layout().halo},
                 {"padded_size", vec(h.layout().padded_size())},
                 {"padded_brick_bytes", padded_brick_bytes(h)}};
  if (stats != nullptr) {
    j["store"] = {
        {"codec", std::string(to_string(stats->codec))}, {"codec_level", stats->codec_level},
        {"format_version", stats->format_version},       {"file_bytes", stats->file_bytes},
        {"metadata_block", store->metadata_block()},     {"brick_errors", stats->brick_errors}};
  }
  j["levels"] = json::array();
  for (std::uint32_t l = 0; l < h.level_count(); ++l)
    j["levels"].push_back(level_json(h, l, stats));
  json total;
  total["level_count"] = h.level_count();
  total["brick_count"] = h.bricks_per_channel() * v.channels;
  total["uncompressed_bytes"] = h.bricks_per_channel() * v.channels * padded_brick_bytes(h);
  if (stats != nullptr) {
    const StoreLevelStats t = stats->total();
    total["uncompressed_bytes"] = t.uncompressed_bytes;
    total["compressed_bytes"] = t.compressed_bytes;
    total["compression_ratio"] = finite_or_null(t.compression_ratio());
    total["empty_bricks"] = t.empty_bricks;
    total["constant_bricks"] = t.constant_bricks;
    total["empty_fraction"] = t.empty_fraction();
    total["constant_fraction"] =
        t.brick_count == 0 ? 0.0 : double(t.constant_bricks) / double(t.brick_count);
    if (stats->brick_errors) {
      total["max_error"] = t.max_error;
      total["mean_error"] = t.mean_error;
    }
  }
  j["total"] = total;
  return j;
}

std::string ranges_text(const VolumeDesc& v) {
  auto one = [&](std::uint32_t c) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "[%g, %g]", v.data_range(c).lo, v.data_range(c).hi);
    return std::string(buf);
  };
  bool same = true;
  for (std::uint32_t c = 1; c < v.channels; ++c) same = same && v.range(c) == v.range(0);
  if (same) return (v.channels > 1 ? "all channels " : "") + one(0);
  std::string s;
  for (std::uint32_t c = 0; c < v.channels; ++c) {
    s += (c ? ", " : "") + std::string("c") + std::to_string(c) + " " + one(c);
  }
  return s;
}

void print_text(const BrickSource& src, const BrickStoreSource* store, SourceKind kind) {
  const BrickHierarchy& h = src.hierarchy();
  const VolumeDesc& v = h.volume();
  const BrickLayout& lay = h.layout();
  const StoreStats* stats = store != nullptr ? &store->stats() : nullptr;
  const glm::dvec3 phys = physical_size(v);
  std::printf("%s\n", src.name().c_str());
  std::printf("  volume   %s voxels, %u channel(s), %s, spacing %g x %g x %g (size %g x %g x %g)\n",
              xyz(v.extent).c_str(), v.channels, describe_mapping(v.file_type()).c_str(),
              v.spacing.x, v.spacing.y, v.spacing.z, phys.x, phys.y, phys.z);
  // Where the volume sits (the low corner of voxel 0, docs/formats.md "Physical placement").
  std::printf("  origin   %g, %g, %g\n", v.origin.x, v.origin.y, v.origin.z);
  std::printf("  ranges   %s\n", ranges_text(v).c_str());
  if (src.timepoints() > 1) {
    std::printf("  time     %u timepoints (this is timepoint %u)\n", src.timepoints(),
                src.timepoint());
  }
  std::printf("  bricks   %s core, halo %u, %s padded (%s each)\n", xyz(lay.brick_size).c_str(),
              lay.halo, xyz(lay.padded_size()).c_str(),
              format_bytes(padded_brick_bytes(h)).c_str());
  if (stats != nullptr) {
    std::printf("  store    %s (level %d), format version %u, metadata block %u, file %s%s\n",
                std::string(to_string(stats->codec)).c_str(), stats->codec_level,
                stats->format_version, store->metadata_block(),
                format_bytes(stats->file_bytes).c_str(),
                stats->brick_errors ? ", brick errors stored" : "");
  } else if (kind == SourceKind::procedural) {
    std::printf(
        "  (procedural source: bricks are computed on demand, nothing is stored; "
        "hierarchy only)\n");
  } else {
    std::printf("  (%s source: coarser levels are built on demand; hierarchy only)\n",
                std::string(to_string(kind)).c_str());
  }
  std::printf("\n%-5s %-17s %-9s %-11s %9s", "level", "extent", "factor", "bricks", "count");
  if (stats != nullptr) {
    std::printf(" %11s %12s %7s %6s %6s", "compressed", "uncompressed", "ratio", "empty", "const");
    if (stats->brick_errors) std::printf(" %9s %9s", "max error", "mean err.");
  } else {
    std::printf(" %12s", "uncompressed");
  }
  std::printf("\n");
  auto row = [&](const std::string& name, const std::string& extent, const std::string& factor,
                 const std::string& bricks, std::uint64_t count, std::uint64_t raw_bytes,
                 const StoreLevelStats* s) {
    std::printf("%-5s %-17s %-9s %-11s %9llu", name.c_str(), extent.c_str(), factor.c_str(),
                bricks.c_str(), static_cast<unsigned long long>(count));
    if (s != nullptr) {
      const double ratio = s->compression_ratio();
      const double constant =
          s->brick_count == 0 ? 0.0 : double(s->constant_bricks) / double(s->brick_count);
      char ratio_text[16];
      if (std::isfinite(ratio)) {
        std::snprintf(ratio_text, sizeof ratio_text, "%.2f", ratio);
      } else {
        std::snprintf(ratio_text, sizeof ratio_text, "-");
      }
      std::printf(" %11s %12s %7s %5.1f%% %5.1f%%", format_bytes(s->compressed_bytes).c_str(),
                  format_bytes(s->uncompressed_bytes).c_str(), ratio_text,
                  100.0 * s->empty_fraction(), 100.0 * constant);
      // Fractions of the value range (BrickSource::brick_error), when the store holds them.
      if (stats->brick_errors) std::printf(" %9.3g %9.3g", s->max_error, s->mean_error);
    } else {
      std::printf(" %12s", format_bytes(raw_bytes).c_str());
    }
    std::printf("\n");
  };
  const std::uint64_t brick_bytes = padded_brick_bytes(h);
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const LevelInfo& info = h.level(l);
    const std::uint64_t count = info.brick_count * v.channels;
    row(std::to_string(l), xyz(info.extent), xyz(glm::uvec3(1u) << info.factor_log2),
        xyz(info.bricks), count, count * brick_bytes,
        stats != nullptr ? &stats->levels.at(l) : nullptr);
  }
  const std::uint64_t count = h.bricks_per_channel() * v.channels;
  const StoreLevelStats total = stats != nullptr ? stats->total() : StoreLevelStats{};
  row("total", std::to_string(h.level_count()) + " levels", "", "", count, count * brick_bytes,
      stats != nullptr ? &total : nullptr);
}

int info(const std::string& spec, const SourceOptions& options, bool as_json) {
  const std::unique_ptr<BrickSource> src = open_source(spec, {}, options);
  const auto* store = dynamic_cast<const BrickStoreSource*>(src.get());
  const SourceKind kind = detect_source_kind(spec);
  if (as_json) {
    std::printf("%s\n", describe(*src, store, kind).dump(2).c_str());
  } else {
    print_text(*src, store, kind);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Prints the resolution levels, bricks and storage numbers of a resoct brick store "
      "a procedural source or a volume file (OME-Zarr, NIfTI, NRRD, TIFF)."};
  one_line_usage_errors(app, kTool);
  std::string spec;
  bool as_json = false;
  app.add_option("source", spec, std::string(kSourceSpecForms))->required();
  app.add_flag("--json", as_json, "print JSON instead of text");
  SourceOptions options;
  add_source_options(app, options);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return run_tool(kTool, [&] { return info(spec, options, as_json); });
}
