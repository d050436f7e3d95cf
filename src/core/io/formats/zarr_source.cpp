#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

#include "io/formats/zarr_shard_reader.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/formats/zarr_v3.hpp"

namespace resoct {

namespace detail {

/// One zarr array of the image and where resoct's axes sit in it.
struct ZarrDataset {
  std::string prefix;    // "" or "path/"
  std::string meta_key;  // prefix + ".zarray" (v2) or prefix + "zarr.json" (v3)
  ZarrArrayMeta meta;
  std::vector<std::uint64_t> grid;
  int t = -1, c = -1;
  int spatial[3] = {-1, -1, -1};  // array dimension of x, y, z
  glm::u64vec3 extent{1};
};

struct ZarrImage {
  std::shared_ptr<const ByteStore> store;
  OmeMultiscales ms;
  std::vector<ZarrDataset> datasets;
  std::uint64_t timepoint = 0;
  std::uint64_t timepoints = 1;  // extent of the t axis (1 without one)
  // Decoded chunks of this timepoint (keys have no room for t); each timepoint has its own.
  std::unique_ptr<HostBrickCache> chunks;
  std::uint64_t chunk_cache_bytes = 0;
  // v3 shard indexes (LRU) and inner-chunk reads; keyed by store key, so shared by timepoints.
  std::shared_ptr<ZarrShardReader> shards;
  VoxelType type = VoxelType::u8;
  DataType data_type = DataType::u8;
  std::string group_key;  // ".zattrs" (v2) or "zarr.json" (v3): names the image in messages
};

}  // namespace detail

namespace {

using detail::ZarrDataset;
using detail::ZarrImage;

std::string text_of(const std::vector<std::byte>& b) {
  return std::string(reinterpret_cast<const char*>(b.data()), b.size());
}

constexpr std::uint64_t kMaxMetadataBytes = 16u << 20;
/// Decoded shard indexes kept per image (16 bytes per inner chunk).
constexpr std::uint64_t kShardIndexCacheBytes = 32u << 20;

/// The stored bytes of chunk `index` (in units of meta.chunks) of a v3 array, nullopt when
/// absent: the chunk object itself, or for a sharded array the inner chunk read by ranges.
/// `where` receives the chunk's location for messages.
std::optional<std::vector<std::byte>> v3_chunk_bytes(const ZarrImage& img, const ZarrDataset& ds,
                                                     std::span<const std::uint64_t> index,
                                                     std::uint64_t max_bytes, std::string& where) {
  const ZarrV3Layout& v3 = *ds.meta.v3;
  if (v3.shard_shape.empty()) {
    const std::string key = ds.prefix + ds.meta.chunk_key(index);
    where = img.store->location(key);
    return img.store->get(key, max_bytes);
  }
  const std::size_t rank = index.size();
  std::vector<std::uint64_t> shard(rank);
  std::uint64_t inner = 0, per_shard = 1;
  for (std::size_t d = 0; d < rank; ++d) {
    const std::uint64_t per = v3.shard_shape[d] / ds.meta.chunks[d];
    shard[d] = index[d] / per;
    inner = inner * per + index[d] % per;
    per_shard *= per;
  }
  const std::string key = ds.prefix + ds.meta.chunk_key(shard);
  where = img.store->location(key) + " (inner chunk " + std::to_string(inner) + ")";
  return img.shards->inner_chunk(key, *v3.codecs[0].sharding, per_shard, inner, max_bytes);
}

/// Voxels of one decoded chunk (or fill) for (dataset, channel-chunk, spatial chunk).
std::shared_ptr<const HostBrick> chunk(const ZarrImage& img, std::size_t ds_index,
                                       std::uint64_t c_chunk, const glm::u64vec3& sc) {
  const ZarrDataset& ds = img.datasets[ds_index];
  const BrickKey key{std::uint32_t(ds_index), std::uint32_t(c_chunk), glm::uvec3(sc)};
  if (auto hit = img.chunks->get(key)) return hit;
  std::vector<std::uint64_t> index(ds.meta.shape.size(), 0);
  if (ds.t >= 0) index[std::size_t(ds.t)] = img.timepoint / ds.meta.chunks[std::size_t(ds.t)];
  if (ds.c >= 0) index[std::size_t(ds.c)] = c_chunk;
  for (int a = 0; a < 3; ++a) {
    if (ds.spatial[a] >= 0) index[std::size_t(ds.spatial[a])] = sc[a];
  }
  const std::uint64_t bytes = ds.meta.chunk_bytes();
  auto brick = std::make_shared<HostBrick>();
  brick->key = key;
  brick->meta.constant = false;  // HostBrickCache keeps voxels of non-constant entries only
  std::optional<std::vector<std::byte>> encoded;
  if (ds.meta.v3) {
    // Encoded v3 chunks may carry a nested shard index (16 bytes per voxel at most).
    const std::uint64_t max = 2 * bytes + 16 * ds.meta.chunk_voxels() + 65536;
    std::string where;
    encoded = v3_chunk_bytes(img, ds, index, max, where);
    if (encoded) {
      const ZarrV3Layout& v3 = *ds.meta.v3;
      const ZarrCodecs& codecs = v3.shard_shape.empty() ? v3.codecs : v3.codecs[0].sharding->codecs;
      brick->voxels = decode_zarr_v3_chunk(codecs, ds.meta.chunks, img.data_type,
                                           ds.meta.fill_value, *encoded, where);
    }
  } else {
    const std::string key_text = ds.prefix + ds.meta.chunk_key(index);
    encoded = img.store->get(key_text, 2 * bytes + 65536);
    if (encoded)
      brick->voxels = decode_zarr_chunk(ds.meta, *encoded, img.store->location(key_text));
  }
  if (!encoded)
    brick->voxels = zarr_fill_voxels(img.data_type, ds.meta.fill_value, ds.meta.chunk_voxels());
  img.chunks->put(brick);
  return brick;
}

/// Copies `box` (dataset voxel coordinates, inside its extent) of `channel` from chunks.
void read_box(const ZarrImage& img, std::size_t ds_index, std::uint32_t channel, const Box3& box,
              std::span<std::byte> out) {
  const ZarrDataset& ds = img.datasets[ds_index];
  const std::size_t vs = voxel_size(img.type);
  const std::size_t rank = ds.meta.shape.size();
  // Strides of a chunk (C order) in voxels.
  std::vector<std::uint64_t> stride(rank, 1);
  for (std::size_t i = rank - 1; i > 0; --i) stride[i - 1] = stride[i] * ds.meta.chunks[i];
  std::uint64_t base = 0;  // offset of the fixed t and c within the chunk
  if (ds.t >= 0) {
    const auto t = std::size_t(ds.t);
    base += (img.timepoint % ds.meta.chunks[t]) * stride[t];
  }
  std::uint64_t c_chunk = 0;
  if (ds.c >= 0) {
    const auto c = std::size_t(ds.c);
    c_chunk = channel / ds.meta.chunks[c];
    base += (channel % ds.meta.chunks[c]) * stride[c];
  }
  glm::u64vec3 csize(1), cstride(0);
  for (int a = 0; a < 3; ++a) {
    if (ds.spatial[a] >= 0) {
      csize[a] = ds.meta.chunks[std::size_t(ds.spatial[a])];
      cstride[a] = stride[std::size_t(ds.spatial[a])];
    }
  }
  const glm::i64vec3 cs(csize);
  const glm::i64vec3 c0 = box.lo / cs, c1 = (box.hi - std::int64_t(1)) / cs;
  const glm::i64vec3 bs = box.size();
  for (std::int64_t cz = c0.z; cz <= c1.z; ++cz) {
    for (std::int64_t cy = c0.y; cy <= c1.y; ++cy) {
      for (std::int64_t cx = c0.x; cx <= c1.x; ++cx) {
        const glm::i64vec3 ci(cx, cy, cz);
        const auto data = chunk(img, ds_index, c_chunk, glm::u64vec3(ci));
        const Box3 cbox{ci * cs, ci * cs + cs};
        const Box3 r = intersect(cbox, box);
        const std::size_t run = std::size_t(r.hi.x - r.lo.x);
        for (std::int64_t z = r.lo.z; z < r.hi.z; ++z) {
          for (std::int64_t y = r.lo.y; y < r.hi.y; ++y) {
            const std::uint64_t src = base + std::uint64_t(z - cbox.lo.z) * cstride.z +
                                      std::uint64_t(y - cbox.lo.y) * cstride.y +
                                      std::uint64_t(r.lo.x - cbox.lo.x) * cstride.x;
            const std::size_t dst =
                std::size_t(((z - box.lo.z) * bs.y + (y - box.lo.y)) * bs.x + (r.lo.x - box.lo.x));
            if (cstride.x == 1 || run == 1) {
              std::memcpy(out.data() + dst * vs, data->voxels.data() + src * vs, run * vs);
            } else {
              for (std::size_t i = 0; i < run; ++i) {
                std::memcpy(out.data() + (dst + i) * vs,
                            data->voxels.data() + (src + i * cstride.x) * vs, vs);
              }
            }
          }
        }
      }
    }
  }
}

Error dataset_error(const ZarrImage& img, const ZarrDataset& ds, const std::string& why) {
  return Error(ErrorCode::corrupt, img.store->location(ds.meta_key) + ": " + why);
}

ZarrDataset load_dataset(const ZarrImage& img, const std::string& path) {
  ZarrDataset ds;
  ds.prefix = path.empty() ? "" : path + "/";
  const bool v3 = img.group_key == "zarr.json";
  ds.meta_key = ds.prefix + (v3 ? "zarr.json" : ".zarray");
  const std::string& key = ds.meta_key;
  const auto bytes = img.store->get(key, kMaxMetadataBytes);
  if (!bytes) {
    throw Error(ErrorCode::corrupt, img.store->location(key) + ": missing (dataset '" + path +
                                        "' of the multiscales metadata)");
  }
  ds.meta = v3 ? parse_zarr_v3_array_meta(text_of(*bytes), img.store->location(key))
               : parse_zarr_array_meta(text_of(*bytes), img.store->location(key));
  if (ds.meta.shape.size() != img.ms.axes.size()) {
    throw dataset_error(img, ds,
                        "rank " + std::to_string(ds.meta.shape.size()) + " differs from the " +
                            std::to_string(img.ms.axes.size()) + " multiscales axes");
  }
  if (ds.meta.v3) {
    // NGFF 0.5: dimension_names, when given, must name the multiscales axes in order.
    const std::vector<std::string>& names = ds.meta.v3->dimension_names;
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (!names[i].empty() && names[i] != std::string(1, img.ms.axes[i])) {
        throw Error(ErrorCode::corrupt, img.store->location(key) + ": key 'dimension_names[" +
                                            std::to_string(i) + "]': '" + names[i] +
                                            "' disagrees with the multiscales axis '" +
                                            std::string(1, img.ms.axes[i]) + "'");
      }
    }
  }
  ds.t = img.ms.axis_index('t');
  ds.c = img.ms.axis_index('c');
  const char names[3] = {'x', 'y', 'z'};
  for (int a = 0; a < 3; ++a) {
    ds.spatial[a] = img.ms.axis_index(names[a]);
    if (ds.spatial[a] >= 0) ds.extent[a] = ds.meta.shape[std::size_t(ds.spatial[a])];
  }
  ds.grid = ds.meta.chunk_grid();
  for (int a = 0; a < 3; ++a) {
    if (ds.spatial[a] >= 0 && ds.grid[std::size_t(ds.spatial[a])] > BrickKey::kMaxAxis + 1u) {
      throw Error(ErrorCode::unsupported, img.store->location(key) + ": more than " +
                                              std::to_string(BrickKey::kMaxAxis + 1u) +
                                              " chunks along axis " + names[a]);
    }
  }
  return ds;
}

OmeMultiscales bare_array_axes(const ZarrArrayMeta& m, const std::string& location) {
  OmeMultiscales ms;
  ms.version = m.zarr_format == 3 ? "0.5" : "0.4";
  static const char* const kByRank[] = {"", "x", "yx", "zyx", "czyx", "tczyx"};
  if (m.shape.size() > 5) {
    throw Error(ErrorCode::unsupported, location + ": a bare array of rank " +
                                            std::to_string(m.shape.size()) + " (at most 5)");
  }
  for (const char* p = kByRank[m.shape.size()]; *p != 0; ++p) {
    ms.axes.push_back(*p);
    ms.units.emplace_back();
  }
  ms.datasets.push_back(OmeDataset{"", std::vector<double>(m.shape.size(), 1.0),
                                   std::vector<double>(m.shape.size(), 0.0)});
  return ms;
}

std::shared_ptr<ZarrImage> load_image(std::shared_ptr<const ByteStore> store,
                                      const OmeZarrOptions& o) {
  auto img = std::make_shared<ZarrImage>();
  img->store = std::move(store);
  img->timepoint = o.timepoint;
  img->chunks = std::make_unique<HostBrickCache>(o.chunk_cache_bytes);
  img->chunk_cache_bytes = o.chunk_cache_bytes;
  img->shards = std::make_shared<detail::ZarrShardReader>(img->store, kShardIndexCacheBytes);
  img->group_key = ".zattrs";
  bool multiscales = false;
  // Zarr v3 (OME-Zarr 0.5): one zarr.json per node; a group with attributes.ome, or an array.
  if (const auto node = img->store->get("zarr.json", kMaxMetadataBytes)) {
    img->group_key = "zarr.json";
    const std::string text = text_of(*node);
    const std::string loc = img->store->location("zarr.json");
    try {
      img->ms = parse_ome_zarr_group(text, loc);
      multiscales = true;
    } catch (const Error& e) {
      // Not an image group: a bare v3 array at the root, or nothing resoct reads.
      const auto j = nlohmann::json::parse(text, nullptr, false);
      if (e.code() != ErrorCode::bad_magic || !j.is_object() ||
          j.value("node_type", "") != "array") {
        throw;
      }
      img->ms = bare_array_axes(parse_zarr_v3_array_meta(text, loc), loc);
      multiscales = true;
    }
  }
  const auto attrs = multiscales ? std::nullopt : img->store->get(".zattrs", kMaxMetadataBytes);
  if (attrs) {
    const std::string text = text_of(*attrs);
    try {
      img->ms = parse_ome_multiscales(text, img->store->location(".zattrs"));
      multiscales = true;
    } catch (const Error& e) {
      if (e.code() != ErrorCode::bad_magic) throw;
    }
  }
  if (!multiscales) {
    const auto arr = img->store->get(".zarray", kMaxMetadataBytes);
    if (!arr) {
      throw Error(
          ErrorCode::bad_magic,
          img->store->location(".zattrs") +
              ": no OME-Zarr image here (no zarr.json, no 'multiscales' in .zattrs, no .zarray)");
    }
    const std::string loc = img->store->location(".zarray");
    img->ms = bare_array_axes(parse_zarr_array_meta(text_of(*arr), loc), loc);
  }
  for (const OmeDataset& d : img->ms.datasets) img->datasets.push_back(load_dataset(*img, d.path));
  const ZarrDataset& d0 = img->datasets[0];
  img->type = d0.meta.type;
  img->data_type = d0.meta.data_type;
  for (const ZarrDataset& ds : img->datasets) {
    if (ds.meta.data_type != img->data_type) {
      throw dataset_error(*img, ds, "voxel type differs from the first dataset's");
    }
    for (int axis : {ds.t, ds.c}) {
      if (axis >= 0 && ds.meta.shape[std::size_t(axis)] != d0.meta.shape[std::size_t(axis)]) {
        throw dataset_error(*img, ds, "t or c extent differs from the first dataset's");
      }
    }
  }
  if (d0.t >= 0 && o.timepoint >= d0.meta.shape[std::size_t(d0.t)]) {
    throw invalid_parameter("timepoint", std::to_string(o.timepoint) + " but the image has " +
                                             std::to_string(d0.meta.shape[std::size_t(d0.t)]) +
                                             " timepoints");
  }
  if (d0.t >= 0) img->timepoints = d0.meta.shape[std::size_t(d0.t)];
  if (d0.t < 0 && o.timepoint != 0) {
    throw invalid_parameter("timepoint", "the image has no t axis");
  }
  if (d0.c >= 0 && d0.meta.shape[std::size_t(d0.c)] > kMaxChannels) {
    throw Error(ErrorCode::unsupported, img->store->location(d0.meta_key) + ": " +
                                            std::to_string(d0.meta.shape[std::size_t(d0.c)]) +
                                            " channels (at most 256)");
  }
  return img;
}

/// The same image at another timepoint: metadata and shard indexes shared, chunk cache its own.
std::shared_ptr<ZarrImage> image_at(const ZarrImage& img, std::uint64_t t) {
  auto other = std::make_shared<ZarrImage>();
  other->store = img.store;
  other->ms = img.ms;
  other->datasets = img.datasets;
  other->timepoint = t;
  other->timepoints = img.timepoints;
  other->chunks = std::make_unique<HostBrickCache>(img.chunk_cache_bytes);
  other->chunk_cache_bytes = img.chunk_cache_bytes;
  other->shards = img.shards;
  other->type = img.type;
  other->data_type = img.data_type;
  other->group_key = img.group_key;
  return other;
}

/// The hierarchy level a coarser dataset can serve, or -1.
int matching_level(const BrickHierarchy& h, const ZarrImage& img, std::size_t k) {
  const ZarrDataset& ds = img.datasets[k];
  for (std::uint32_t l = 1; l < h.level_count(); ++l) {
    const LevelInfo& info = h.level(l);
    if (info.extent != ds.extent) continue;
    bool ok = true;
    for (int a = 0; a < 3 && ok; ++a) {
      const int axis = ds.spatial[a];
      if (axis < 0) continue;
      const double want =
          img.ms.datasets[0].scale[std::size_t(axis)] * std::ldexp(1.0, int(info.factor_log2[a]));
      const double got = img.ms.datasets[k].scale[std::size_t(axis)];
      ok = std::fabs(got - want) <= 1e-3 * want;
    }
    if (ok) return int(l);
  }
  return -1;
}

}  // namespace

/// The source over `img`: stored datasets serve the levels they match, the rest is computed.
static std::unique_ptr<OmeZarrSource> make_zarr_source(std::shared_ptr<const ZarrImage> img,
                                                       const VolumeDesc& desc,
                                                       const BrickLayout& layout,
                                                       const PyramidSourceOptions& po,
                                                       std::string name) {
  const BrickHierarchy h(desc, layout);
  std::vector<LevelBoxReader> levels(h.level_count());
  std::vector<int> level_dataset(h.level_count(), -1);
  auto reader = [img](std::size_t k) {
    return [img, k](std::uint32_t c, const Box3& box, std::span<std::byte> out) {
      read_box(*img, k, c, box, out);
    };
  };
  levels[0] = reader(0);
  level_dataset[0] = 0;
  for (std::size_t k = 1; k < img->datasets.size(); ++k) {
    const int l = matching_level(h, *img, k);
    if (l > 0 && level_dataset[std::size_t(l)] < 0) {
      levels[std::size_t(l)] = reader(k);
      level_dataset[std::size_t(l)] = int(k);
    }
  }
  return std::make_unique<OmeZarrSource>(img, desc, layout, std::move(levels), std::move(name), po,
                                         std::move(level_dataset));
}

OmeZarrSource::OmeZarrSource(std::shared_ptr<const detail::ZarrImage> image, VolumeDesc desc,
                             BrickLayout layout, std::vector<LevelBoxReader> levels,
                             std::string name, PyramidSourceOptions options,
                             std::vector<int> level_dataset)
    : PyramidSource(std::move(desc), layout, std::move(levels), std::move(name), options),
      image_(std::move(image)),
      level_dataset_(std::move(level_dataset)),
      options_(options) {}

std::uint32_t OmeZarrSource::timepoints() const {
  return std::uint32_t(std::min<std::uint64_t>(image_->timepoints, UINT32_MAX));
}

std::uint32_t OmeZarrSource::timepoint() const {
  return std::uint32_t(image_->timepoint);
}

std::shared_ptr<const BrickSource> OmeZarrSource::open_timepoint(std::uint32_t t) const {
  if (t >= timepoints()) {
    throw invalid_parameter("timepoint", std::to_string(t) + " but the image has " +
                                             std::to_string(timepoints()) + " timepoints");
  }
  // The series keeps the value ranges it was opened with (omero windows, or the data range of
  // the timepoint opened first), so one transfer function maps every timepoint alike.
  PyramidSourceOptions po = options_;
  po.ranges_from_data = false;
  return make_zarr_source(image_at(*image_, t), hierarchy().volume(), hierarchy().layout(), po,
                          name());
}

const OmeMultiscales& OmeZarrSource::multiscales() const noexcept {
  return image_->ms;
}

const ZarrArrayMeta& OmeZarrSource::array(std::size_t dataset) const {
  if (dataset >= image_->datasets.size()) {
    throw Error(ErrorCode::out_of_range, name() + ": no dataset " + std::to_string(dataset));
  }
  return image_->datasets[dataset].meta;
}

int OmeZarrSource::dataset_of_level(std::uint32_t level) const noexcept {
  return level < level_dataset_.size() ? level_dataset_[level] : -1;
}

HostBrickCacheStats OmeZarrSource::chunk_cache_stats() const {
  return image_->chunks->stats();
}

std::unique_ptr<OmeZarrSource> open_ome_zarr(std::shared_ptr<const ByteStore> store,
                                             const BrickLayout& layout,
                                             const OmeZarrOptions& options) {
  if (!store) throw invalid_parameter("store", "null ByteStore");
  std::shared_ptr<const ZarrImage> img = load_image(std::move(store), options);
  const ZarrDataset& d0 = img->datasets[0];
  VolumeDesc desc;
  desc.extent = d0.extent;
  desc.type = img->type;
  if (data_type_of(img->type) != img->data_type) desc.data_type = img->data_type;
  desc.channels = d0.c >= 0 ? std::uint32_t(d0.meta.shape[std::size_t(d0.c)]) : 1u;
  for (int a = 0; a < 3; ++a) {
    if (d0.spatial[a] >= 0) {
      // The finest dataset places the volume. NGFF 0.4 / 0.5 do not say whether a translation
      // places voxel 0's centre or its corner; it is read as the corner, so that an image
      // without one starts at 0 (docs/formats.md, "Physical placement").
      const auto axis = std::size_t(d0.spatial[a]);
      desc.spacing[a] = img->ms.datasets[0].scale[axis];
      desc.origin[a] = img->ms.datasets[0].translation[axis];
    }
  }
  PyramidSourceOptions po = options.pyramid;
  if (img->ms.channels.size() == desc.channels) {
    for (const OmeChannel& c : img->ms.channels) {
      // omero windows are in the file's units, ranges in stored ones.
      const double o = desc.value_offset();
      if (c.window) desc.ranges.push_back({c.window->lo + o, c.window->hi + o});
    }
  }
  if (desc.ranges.size() != desc.channels) {
    desc.ranges.clear();
    po.ranges_from_data = true;
  }
  std::string name = img->store->location(img->group_key);
  name.resize(name.size() - img->group_key.size() - 1);
  return make_zarr_source(img, desc, layout, po, std::move(name));
}

std::unique_ptr<OmeZarrSource> open_ome_zarr(const std::string& directory,
                                             const BrickLayout& layout,
                                             const OmeZarrOptions& options) {
  return open_ome_zarr(open_directory_store(directory), layout, options);
}

}  // namespace resoct
