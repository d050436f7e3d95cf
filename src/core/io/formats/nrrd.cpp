#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>

#include "io/storage/confined_path.hpp"
#include "io/formats/inflate.hpp"
#include "io/formats/placement.hpp"
#include "io/formats/samples.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/io/formats/nrrd.hpp"
#include "resoct/io/formats/pyramid_source.hpp"

namespace resoct {

namespace {

/// Longest header read (a header is text of a few hundred bytes; this bounds hostile files).
constexpr std::uint64_t kMaxHeader = std::uint64_t(1) << 20;

/// Offset just past `lines` newlines starting at `from`.
std::uint64_t skip_lines(const ReadFile& f, std::uint64_t from, std::uint64_t lines) {
  std::uint64_t pos = from;
  std::vector<std::byte> buf(1 << 16);
  while (lines > 0) {
    if (pos >= f.size()) {
      throw file_error(ErrorCode::truncated, f.path(), pos, "file ends within 'line skip' lines");
    }
    const std::size_t n = std::size_t(std::min<std::uint64_t>(buf.size(), f.size() - pos));
    f.read_at(pos, std::span(buf).first(n));
    std::size_t i = 0;
    for (; i < n && lines > 0; ++i) {
      if (buf[i] == std::byte('\n')) --lines;
    }
    pos += i;
  }
  return pos;
}

/// Channel-interleaved samples (channel fastest) to channel-major voxels.
std::vector<std::byte> deinterleave(const std::vector<std::byte>& in, std::uint32_t channels,
                                    std::size_t vs) {
  std::vector<std::byte> out(in.size());
  const std::size_t n = in.size() / vs / channels;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::uint32_t c = 0; c < channels; ++c) {
      std::memcpy(out.data() + (c * n + i) * vs, in.data() + (i * channels + c) * vs, vs);
    }
  }
  return out;
}

}  // namespace

std::unique_ptr<BrickSource> open_nrrd(const std::string& path, const BrickLayout& layout) {
  const ReadFile file(path);
  std::string head(std::size_t(std::min(file.size(), kMaxHeader)), '\0');
  file.read_at(0, std::as_writable_bytes(std::span(head)));
  const NrrdHeader h = parse_nrrd_header(head, path);
  const bool attached = h.data_file.empty();
  if (attached && h.header_bytes >= head.size() && head.find("\n\n") == std::string::npos &&
      head.find("\n\r\n") == std::string::npos) {
    throw file_error(ErrorCode::truncated, path, head.size(),
                     "no blank line ends the header, and no 'data file' is named");
  }
  std::string data_path = path;
  if (!attached) {
    // The header is untrusted: its data file may only be one below the header's own directory
    // (no absolute path, no '..', no symbolic link leading out), or a header downloaded with a
    // dataset could make resoct read any file the user can read.
    std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (dir.empty()) dir = ".";
    data_path = detail::confined_path(detail::canonical_root(dir), h.data_file, path,
                                      "NRRD field 'data file'")
                    .string();
  }
  const ReadFile data_file_handle = attached ? ReadFile(path) : ReadFile(data_path);
  const ReadFile& data = data_file_handle;
  std::uint64_t start = attached ? h.header_bytes : 0;
  start = skip_lines(data, start, h.line_skip);

  // With space directions the voxels are served in world order (NIfTI's rule, one for every
  // format: io/formats/placement.hpp); without them in index order at origin 0.
  detail::Placement place;
  place.spacing = h.spacing;
  if (h.world_axes) place = detail::place_grid({*h.world_axes, h.world_origin}, h.extent());
  VolumeDesc d;
  d.extent = detail::served_extent(place.order, h.extent());
  d.spacing = place.spacing;
  d.origin = place.origin;
  d.channels = h.channels();
  const DataType st = h.type;
  d.type = detail::voxel_type_for(st, false);
  if (data_type_of(d.type) != st) d.data_type = st;
  const std::uint64_t need = h.data_bytes();
  PyramidSourceOptions o;
  o.ranges_from_data = true;
  // The voxels are read (or mapped) whole at open anyway, so the scan adds at most as much
  // again, and data-derived ranges beat a type's default range for float data.
  o.eager_scan_voxels = std::numeric_limits<std::uint64_t>::max();
  const std::string name = path;

  std::vector<std::byte> stored;
  if (h.gzip) {
    // As in teem, byte skip applies to the decompressed data of compressed encodings.
    std::vector<std::byte> packed(std::size_t(data.size() - std::min(data.size(), start)));
    data.read_at(start, packed);
    // The buffer grows with the decoded data, so a header announcing more than the stream holds
    // fails as truncated instead of allocating the announced size up front. Byte skip (< 2^63)
    // plus the data size can wrap, which would make `want` small and the skip below point far
    // outside the buffer.
    const std::uint64_t skip = std::uint64_t(h.byte_skip);
    if (need > ~std::uint64_t(0) - skip) {
      throw file_error(ErrorCode::overflow, data.path(), start,
                       "byte skip plus data size overflows 64 bits");
    }
    const std::uint64_t want = skip + need;
    std::vector<std::byte> all = detail::inflate_all(packed, want, data.path(), true);
    if (all.size() != want) {
      throw file_error(ErrorCode::truncated, data.path(), start,
                       "gzip data holds " + std::to_string(all.size()) + " bytes, the header " +
                           "announces " + std::to_string(want));
    }
    stored.assign(all.begin() + std::ptrdiff_t(h.byte_skip), all.end());
  } else {
    std::uint64_t offset = start + std::uint64_t(std::max<std::int64_t>(h.byte_skip, 0));
    if (h.byte_skip == -1) {
      if (data.size() < need) {
        throw file_error(ErrorCode::truncated, data.path(), data.size(),
                         "file is shorter than its " + std::to_string(need) + " data bytes");
      }
      offset = data.size() - need;
    }
    if (h.channel_axis != 0 && detail::samples_are_voxels(st, h.endian, false) &&
        place.order.identity()) {
      RawVolumeOptions r;
      r.extent = d.extent;
      r.type = d.type;
      r.endian = h.endian;
      r.spacing = d.spacing;
      r.origin = d.origin;
      r.channels = d.channels;
      r.offset = offset;
      return make_dense_pyramid_source(open_raw_volume(data.path(), r), layout, name, o);
    }
    if (offset > data.size() || data.size() - offset < need) {
      throw file_error(ErrorCode::truncated, data.path(), data.size(),
                       "data ends early: needs " + std::to_string(need) + " bytes from offset " +
                           std::to_string(offset));
    }
    stored.resize(std::size_t(need));
    data.read_at(offset, stored);
  }
  std::vector<std::byte> voxels(std::size_t(need / data_size(st) * voxel_size(d.type)));
  detail::convert_samples(stored, st, h.endian, false, 1.0, 0.0, voxels);
  if (h.channel_axis == 0 && d.channels > 1) {
    voxels = deinterleave(voxels, d.channels, voxel_size(d.type));
  }
  if (!place.order.identity()) {
    std::vector<std::byte> served(voxels.size());
    detail::reorder_voxels(voxels, h.extent(), d.channels, voxel_size(d.type), place.order, served);
    voxels = std::move(served);
  }
  return make_dense_pyramid_source(DenseVolume::from_bytes(d, std::move(voxels)), layout, name, o);
}

}  // namespace resoct
