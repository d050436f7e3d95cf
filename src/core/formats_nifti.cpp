#include <array>
#include <limits>
#include <string>

#include "formats_inflate.hpp"
#include "formats_samples.hpp"
#include "resoct/dense_volume.hpp"
#include "resoct/error.hpp"
#include "resoct/file_io.hpp"
#include "resoct/formats/nifti.hpp"
#include "resoct/formats/pyramid_source.hpp"

namespace resoct {

namespace {

VolumeDesc describe(const NiftiHeader& h) {
  VolumeDesc d;
  d.extent = h.extent();
  d.spacing = h.spacing();
  d.channels = h.volumes();
  d.type = detail::voxel_type_for(h.datatype, h.scaled());
  if (!h.scaled() && data_type_of(d.type) != h.datatype) d.data_type = h.datatype;
  return d;
}

DenseVolume decode(const NiftiHeader& h, std::span<const std::byte> file, const std::string& path) {
  const std::uint64_t need = h.data_bytes();
  if (file.size() < h.vox_offset || file.size() - h.vox_offset < need) {
    throw file_error(ErrorCode::truncated, path, file.size(),
                     "NIfTI data ends early: needs " + std::to_string(need) +
                         " bytes from vox_offset " + std::to_string(h.vox_offset));
  }
  const VolumeDesc d = describe(h);
  std::vector<std::byte> voxels(std::size_t(d.voxel_count() * d.channels * voxel_size(d.type)));
  detail::convert_samples(file.subspan(std::size_t(h.vox_offset), std::size_t(need)), h.datatype,
                          h.endian, h.scaled(), h.scl_slope, h.scl_inter, voxels);
  return DenseVolume::from_bytes(d, std::move(voxels));
}

}  // namespace

std::unique_ptr<BrickSource> open_nifti(const std::string& path, const BrickLayout& layout) {
  const ReadFile file(path);
  std::array<std::byte, 2> magic{};
  if (file.size() >= 2) file.read_at(0, magic);
  PyramidSourceOptions o;
  o.ranges_from_data = true;
  // The voxels are read (or mapped) whole at open anyway, so the scan adds at most as much
  // again, and data-derived ranges beat a type's default range for float data.
  o.eager_scan_voxels = std::numeric_limits<std::uint64_t>::max();
  if (detail::is_gzip(magic)) {
    std::vector<std::byte> packed(std::size_t(file.size()));
    file.read_at(0, packed);
    // Header first, then exactly the bytes it announces: memory follows the decoded data and
    // the header, not whatever a damaged stream would expand to.
    const std::vector<std::byte> head = detail::inflate_all(packed, 348, path, true);
    const NiftiHeader h = parse_nifti_header(head, path);
    const std::uint64_t need = h.vox_offset + h.data_bytes();
    const std::vector<std::byte> bytes = detail::inflate_all(packed, need, path, true);
    packed = {};
    return make_dense_pyramid_source(decode(h, bytes, path), layout, path, o);
  }
  std::array<std::byte, 348> head{};
  if (file.size() < head.size()) {
    throw file_error(ErrorCode::truncated, path, file.size(),
                     "NIfTI header needs 348 bytes, the file has " + std::to_string(file.size()));
  }
  file.read_at(0, head);
  const NiftiHeader h = parse_nifti_header(head, path);
  if (detail::samples_are_voxels(h.datatype, h.endian, h.scaled())) {
    // Stored voxels are resoct voxels: map the file instead of copying it.
    const VolumeDesc d = describe(h);
    RawVolumeOptions r;
    r.extent = d.extent;
    r.type = d.type;
    r.endian = h.endian;
    r.spacing = d.spacing;
    r.channels = d.channels;
    r.offset = h.vox_offset;
    return make_dense_pyramid_source(open_raw_volume(path, r), layout, path, o);
  }
  const std::uint64_t need = h.data_bytes();
  if (file.size() < h.vox_offset || file.size() - h.vox_offset < need) {
    throw file_error(ErrorCode::truncated, path, file.size(),
                     "NIfTI data ends early: needs " + std::to_string(need) +
                         " bytes from vox_offset " + std::to_string(h.vox_offset));
  }
  std::vector<std::byte> bytes(std::size_t(h.vox_offset + need));
  file.read_at(0, bytes);
  return make_dense_pyramid_source(decode(h, bytes, path), layout, path, o);
}

}  // namespace resoct
