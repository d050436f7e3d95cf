#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "io/storage/confined_path.hpp"
#include "io/formats/inflate.hpp"
#include "io/formats/placement.hpp"
#include "io/formats/samples.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/io/formats/nifti.hpp"
#include "resoct/io/formats/pyramid_source.hpp"

namespace resoct {

namespace {

bool ends_with_ci(const std::string& s, std::string_view suffix) {
  if (s.size() < suffix.size()) return false;
  for (std::size_t i = 0; i < suffix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) {
      return false;
    }
  }
  return true;
}

/// The header file and the data file of an image (the same file for a .nii).
struct NiftiFiles {
  std::string header;
  std::string data;
  bool pair = false;
};

/// The first of `names` (siblings of `path`) that exists, confined to `path`'s directory.
std::string find_sibling(const std::string& path, std::initializer_list<std::string> names,
                         std::string_view what) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const std::filesystem::path root = detail::canonical_root(dir);
  std::string tried;
  for (const std::string& name : names) {
    // The name is derived from the opened file's, but a symbolic link named like the partner
    // must not lead out of the directory either (docs/formats.md, "Files a file may name").
    const std::filesystem::path p = detail::confined_path(root, name, path, what);
    std::error_code ec;
    if (std::filesystem::is_regular_file(p, ec)) return p.string();
    tried += (tried.empty() ? "" : " or ") + name;
  }
  throw file_error(ErrorCode::io, path, 0,
                   "the " + std::string(what) + " of this NIfTI / Analyze pair is missing: no " +
                       tried + " beside it");
}

NiftiFiles locate(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  for (const char* gz : {"", ".gz"}) {
    for (const auto& [mine, other, what] :
         {std::tuple{".hdr", ".img", "data file"}, std::tuple{".img", ".hdr", "header file"}}) {
      const std::string suffix = std::string(mine) + gz;
      if (!ends_with_ci(name, suffix)) continue;
      const std::string stem = name.substr(0, name.size() - suffix.size());
      // The partner may be compressed or not, whatever this file is.
      const std::string partner = find_sibling(
          path, {stem + other, stem + other + ".gz", stem + (mine[1] == 'h' ? ".IMG" : ".HDR")},
          what);
      if (mine[1] == 'h') return {path, partner, true};
      return {partner, path, true};
    }
  }
  return {path, path, false};
}

/// A file's bytes, inflated when it is gzip (recognised by its magic).
class Stream {
 public:
  explicit Stream(const std::string& path) : file_(path) {
    std::array<std::byte, 2> magic{};
    if (file_.size() >= 2) file_.read_at(0, magic);
    gzip_ = detail::is_gzip(magic);
    if (gzip_) {
      packed_.resize(std::size_t(file_.size()));
      file_.read_at(0, packed_);
    }
  }
  bool gzip() const noexcept { return gzip_; }
  const std::string& path() const noexcept { return file_.path(); }

  /// The first min(n, available) decoded bytes. Memory follows what is asked for and what the
  /// stream holds, not what a damaged stream would expand to.
  std::vector<std::byte> prefix(std::uint64_t n) const {
    if (gzip_) return detail::inflate_all(packed_, n, file_.path(), true);
    std::vector<std::byte> out(std::size_t(std::min(n, file_.size())));
    file_.read_at(0, out);
    return out;
  }

  /// Decoded bytes [offset, offset + size) into `out`; Error(truncated) naming the file when it
  /// ends before (`prefix_bytes` is a decoded prefix reaching at least that far, for gzip).
  void read(std::uint64_t offset, std::span<std::byte> out,
            const std::vector<std::byte>& prefix_bytes) const {
    const std::uint64_t have = gzip_ ? prefix_bytes.size() : file_.size();
    if (have < offset || have - offset < out.size()) {
      throw file_error(ErrorCode::truncated, file_.path(), have,
                       "NIfTI data ends early: needs " + std::to_string(out.size()) +
                           " bytes at offset " + std::to_string(offset) +
                           (gzip_ ? " of the decompressed data" : ""));
    }
    if (gzip_) {
      if (!out.empty()) std::memcpy(out.data(), prefix_bytes.data() + offset, out.size());
    } else {
      file_.read_at(offset, out);
    }
  }

  const ReadFile& file() const noexcept { return file_; }

 private:
  ReadFile file_;
  bool gzip_ = false;
  std::vector<std::byte> packed_;
};

NiftiHeader read_header(const Stream& s, const NiftiFiles& files) {
  const NiftiHeader h = parse_nifti_header(s.prefix(540), files.header);
  if (files.pair && h.form == NiftiForm::single) {
    throw file_error(ErrorCode::invalid_argument, files.header, h.version == 2 ? 4 : 344,
                     "single-file NIfTI magic (\"n+" + std::to_string(h.version) +
                         "\") in a .hdr: a .nii holds header and data together");
  }
  if (!files.pair && h.form != NiftiForm::single) {
    throw file_error(
        h.form == NiftiForm::analyze ? ErrorCode::bad_magic : ErrorCode::invalid_argument,
        files.header, h.version == 2 ? 4 : 344,
        h.form == NiftiForm::analyze
            ? "magic is not \"n+1\" (not a NIfTI-1 file; Analyze 7.5 comes as .hdr + .img)"
            : "two-file NIfTI magic (\"ni" + std::to_string(h.version) +
                  "\"): open the .hdr with its .img beside it");
  }
  return h;
}

/// Where the served volume sits and how stored voxels are reordered for it.
detail::Placement placement(const NiftiHeader& h) {
  const auto m = h.voxel_to_world();
  detail::VoxelGrid g;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) g.axes[c][r] = m[std::size_t(r)][std::size_t(c)];
  }
  g.centre0 = glm::dvec3(m[0][3], m[1][3], m[2][3]);
  detail::Placement p = detail::place_grid(g, h.extent());
  if (h.form == NiftiForm::analyze) {
    // Analyze 7.5 has no world map: index order, pixdim spacing, voxel 0 centred at 0.
    const glm::dvec3 s = h.spacing();
    p = detail::Placement{};
    p.spacing = s;
    p.origin = -0.5 * s;
  }
  return p;
}

}  // namespace

NiftiHeader read_nifti_header(const std::string& path) {
  const NiftiFiles files = locate(path);
  return read_header(Stream(files.header), files);
}

std::unique_ptr<BrickSource> open_nifti(const std::string& path, const BrickLayout& layout,
                                        const NiftiOptions& options) {
  const NiftiFiles files = locate(path);
  std::optional<Stream> header_stream(std::in_place, files.header);
  const NiftiHeader h = read_header(*header_stream, files);
  if (files.pair) header_stream.reset();
  const Stream data = files.pair ? Stream(files.data) : std::move(*header_stream);

  const std::uint64_t timepoints = h.timepoints();
  if (options.timepoint >= timepoints) {
    throw invalid_parameter("timepoint", files.header + ": " + std::to_string(options.timepoint) +
                                             " is out of range: the image has " +
                                             std::to_string(timepoints) + " timepoint(s)");
  }
  const std::uint64_t volume = h.volume_bytes();
  const std::uint32_t channels = h.components();
  if (h.vox_offset > std::numeric_limits<std::uint64_t>::max() - h.data_bytes()) {
    throw file_error(ErrorCode::overflow, files.header, h.version == 2 ? 168 : 108,
                     "NIfTI field 'vox_offset': offset plus data size overflows 64 bits");
  }
  // NIfTI order: x fastest, then y, z, time, components; component c of timepoint t is one
  // 3-D volume at this offset.
  const auto offset_of = [&](std::uint32_t c) {
    return h.vox_offset + (std::uint64_t(c) * timepoints + options.timepoint) * volume;
  };

  const detail::Placement place = placement(h);
  VolumeDesc d;
  d.extent = detail::served_extent(place.order, h.extent());
  d.spacing = place.spacing;
  d.origin = place.origin;
  d.channels = channels;
  d.type = detail::voxel_type_for(h.datatype, h.scaled());
  if (!h.scaled() && data_type_of(d.type) != h.datatype) d.data_type = h.datatype;

  d.ranges = options.ranges;  // checked against the channel count by VolumeDesc::validate

  PyramidSourceOptions o;
  o.ranges_from_data = options.ranges.empty();
  // The voxels are read (or mapped) whole at open anyway, so the scan adds at most as much
  // again, and data-derived ranges beat a type's default range for float data.
  o.eager_scan_voxels = std::numeric_limits<std::uint64_t>::max();
  // The series: another timepoint is this file re-read there, with this timepoint's ranges.
  o.timepoints = std::uint32_t(std::min<std::uint64_t>(timepoints, UINT32_MAX));
  o.timepoint = std::uint32_t(options.timepoint);
  o.open_timepoint = [path, layout, options](std::uint32_t t, const BrickSource& self) {
    NiftiOptions other = options;
    other.timepoint = t;
    other.ranges = self.volume().ranges;
    return std::shared_ptr<const BrickSource>(open_nifti(path, layout, other));
  };
  if (!data.gzip() && detail::samples_are_voxels(h.datatype, h.endian, h.scaled()) &&
      place.order.identity() && (channels == 1 || timepoints == 1)) {
    // Stored voxels are resoct voxels, in served order and one channel after another: map the
    // file instead of copying it.
    RawVolumeOptions r;
    r.extent = d.extent;
    r.type = d.type;
    r.endian = h.endian;
    r.spacing = d.spacing;
    r.origin = d.origin;
    r.channels = d.channels;
    r.ranges = d.ranges;  // samples are voxels here: the file's units are stored units
    r.offset = offset_of(0);
    if (data.file().size() < r.offset || data.file().size() - r.offset < volume * channels) {
      throw file_error(ErrorCode::truncated, data.path(), data.file().size(),
                       "NIfTI data ends early: needs " + std::to_string(volume * channels) +
                           " bytes from offset " + std::to_string(r.offset));
    }
    return make_dense_pyramid_source(open_raw_volume(data.path(), r), layout, path, o);
  }
  const std::uint64_t need = volume * channels;  // <= data_bytes(), checked at parse
  if (need > std::numeric_limits<std::size_t>::max()) {
    throw file_error(ErrorCode::overflow, files.header, 0, "NIfTI volume exceeds memory");
  }
  // A gzip stream is decoded up to the last byte needed (all earlier timepoints included: gzip
  // has no random access); a plain file is read where the chosen timepoint lies.
  const std::vector<std::byte> prefix =
      data.gzip() ? data.prefix(offset_of(channels - 1) + volume) : std::vector<std::byte>{};
  // Checked before allocating: a header may announce far more than the file holds.
  const std::uint64_t end = offset_of(channels - 1) + volume;
  const std::uint64_t have = data.gzip() ? prefix.size() : data.file().size();
  if (have < end) {
    throw file_error(ErrorCode::truncated, data.path(), have,
                     "NIfTI data ends early: timepoint " + std::to_string(options.timepoint) +
                         " needs bytes up to offset " + std::to_string(end) +
                         (data.gzip() ? " of the decompressed data" : ""));
  }
  std::vector<std::byte> stored(static_cast<std::size_t>(need));
  for (std::uint64_t c = 0; c < channels; ++c) {
    data.read(offset_of(std::uint32_t(c)), {stored.data() + c * volume, std::size_t(volume)},
              prefix);
  }
  std::vector<std::byte> voxels(std::size_t(d.voxel_count() * d.channels * voxel_size(d.type)));
  detail::convert_samples(stored, h.datatype, h.endian, h.scaled(), h.scl_slope, h.scl_inter,
                          voxels);
  stored = {};
  if (!place.order.identity()) {
    std::vector<std::byte> served(voxels.size());
    detail::reorder_voxels(voxels, h.extent(), channels, voxel_size(d.type), place.order, served);
    voxels = std::move(served);
  }
  return make_dense_pyramid_source(DenseVolume::from_bytes(d, std::move(voxels)), layout, path, o);
}

}  // namespace resoct
