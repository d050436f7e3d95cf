#include <cmath>
#include <cstring>
#include <string>

#include "resoct/error.hpp"
#include "resoct/formats/ome_zarr.hpp"

namespace resoct {

namespace detail {

/// One zarr array of the image and where resoct's axes sit in it.
struct ZarrDataset {
  std::string prefix;  // "" or "path/"
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
  std::unique_ptr<HostBrickCache> chunks;
  VoxelType type = VoxelType::u8;
  DataType data_type = DataType::u8;
};

}  // namespace detail

namespace {

using detail::ZarrDataset;
using detail::ZarrImage;

std::string text_of(const std::vector<std::byte>& b) {
  return std::string(reinterpret_cast<const char*>(b.data()), b.size());
}

constexpr std::uint64_t kMaxMetadataBytes = 16u << 20;

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
  const std::string key_text = ds.prefix + ds.meta.chunk_key(index);
  const std::uint64_t bytes = ds.meta.chunk_bytes();
  auto brick = std::make_shared<HostBrick>();
  brick->key = key;
  brick->meta.constant = false;  // HostBrickCache keeps voxels of non-constant entries only
  auto encoded = img.store->get(key_text, 2 * bytes + 65536);
  if (encoded) {
    brick->voxels = decode_zarr_chunk(ds.meta, *encoded, img.store->location(key_text));
  } else {
    brick->voxels.resize(std::size_t(bytes));
    const std::size_t n = std::size_t(ds.meta.chunk_voxels());
    // fill_value is in the file's units; voxels are kept as data_mapping() says.
    const double f = ds.meta.fill_value + data_mapping(ds.meta.data_type).offset;
    switch (img.type) {
      case VoxelType::u8: std::memset(brick->voxels.data(), int(f), n); break;
      case VoxelType::u16: {
        const auto v = std::uint16_t(f);
        for (std::size_t i = 0; i < n; ++i) std::memcpy(brick->voxels.data() + 2 * i, &v, 2);
        break;
      }
      case VoxelType::f32: {
        const auto v = float(f);
        for (std::size_t i = 0; i < n; ++i) std::memcpy(brick->voxels.data() + 4 * i, &v, 4);
        break;
      }
    }
  }
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
  return Error(ErrorCode::corrupt, img.store->location(ds.prefix + ".zarray") + ": " + why);
}

ZarrDataset load_dataset(const ZarrImage& img, const std::string& path) {
  ZarrDataset ds;
  ds.prefix = path.empty() ? "" : path + "/";
  const std::string key = ds.prefix + ".zarray";
  const auto bytes = img.store->get(key, kMaxMetadataBytes);
  if (!bytes) {
    throw Error(ErrorCode::corrupt, img.store->location(key) + ": missing (dataset '" + path +
                                        "' of the multiscales metadata)");
  }
  ds.meta = parse_zarr_array_meta(text_of(*bytes), img.store->location(key));
  if (ds.meta.shape.size() != img.ms.axes.size()) {
    throw dataset_error(img, ds,
                        "rank " + std::to_string(ds.meta.shape.size()) + " differs from the " +
                            std::to_string(img.ms.axes.size()) + " multiscales axes");
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
  ms.version = "0.4";
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
  const auto attrs = img->store->get(".zattrs", kMaxMetadataBytes);
  bool multiscales = false;
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
      throw Error(ErrorCode::bad_magic,
                  img->store->location(".zattrs") +
                      ": no OME-Zarr image here (no 'multiscales' in .zattrs and no .zarray)");
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
  if (d0.t < 0 && o.timepoint != 0) {
    throw invalid_parameter("timepoint", "the image has no t axis");
  }
  if (d0.c >= 0 && d0.meta.shape[std::size_t(d0.c)] > kMaxChannels) {
    throw Error(ErrorCode::unsupported, img->store->location(d0.prefix + ".zarray") + ": " +
                                            std::to_string(d0.meta.shape[std::size_t(d0.c)]) +
                                            " channels (at most 256)");
  }
  return img;
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

OmeZarrSource::OmeZarrSource(std::shared_ptr<const detail::ZarrImage> image, VolumeDesc desc,
                             BrickLayout layout, std::vector<LevelBoxReader> levels,
                             std::string name, PyramidSourceOptions options,
                             std::vector<int> level_dataset)
    : PyramidSource(std::move(desc), layout, std::move(levels), std::move(name), options),
      image_(std::move(image)),
      level_dataset_(std::move(level_dataset)) {}

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
    if (d0.spatial[a] >= 0) desc.spacing[a] = img->ms.datasets[0].scale[std::size_t(d0.spatial[a])];
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
  std::string name = img->store->location(".zattrs");
  name.resize(name.size() - std::string_view("/.zattrs").size());
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

std::unique_ptr<OmeZarrSource> open_ome_zarr(const std::string& directory,
                                             const BrickLayout& layout,
                                             const OmeZarrOptions& options) {
  return open_ome_zarr(open_directory_store(directory), layout, options);
}

}  // namespace resoct
