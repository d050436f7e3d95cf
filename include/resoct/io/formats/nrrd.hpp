#pragma once
/// \file
/// NRRD volumes (.nrrd with attached data, .nhdr with a detached data file) as brick sources.
/// Encodings raw and gzip; types (u)char/(u)int8, (u)short/(u)int16, (u)int/(u)int32, float,
/// double, kept through data_mapping() (voxel_type.hpp: int8 / int16 exactly with an offset,
/// 32-bit integers and double as f32); 1..4 dimensions: up to three spatial axes (x fastest),
/// plus a channel axis that is either the first (interleaved, kind vector/list/RGB-color/...) or
/// the last (one volume after another). Placement (docs/formats.md "Physical placement"): with
/// `space directions` the voxels are reordered so that served +x, +y, +z follow world +R, +A, +S
/// (as NIfTI's), spacing is the step lengths and the origin comes from `space origin`; without
/// them the index order is served at origin 0 with spacing from `spacings`, else 1. Each
/// channel's value range is its data's finite min/max.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "resoct/sources/brick_source.hpp"
#include "resoct/io/formats/raw_volume.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// The fields of an NRRD header that resoct uses.
struct NrrdHeader {
  DataType type = DataType::u8;
  std::vector<std::uint64_t> sizes;  ///< per axis, fastest first
  bool gzip = false;                 ///< encoding gzip (else raw)
  Endian endian = Endian::little;
  /// -1: no channel axis; 0: the first axis holds channels (interleaved); otherwise the index
  /// of the last axis, which holds channels.
  int channel_axis = -1;
  glm::dvec3 spacing{1.0};
  /// From `space directions`: the world step of each spatial axis (columns, stored order x, y, z)
  /// in a right-anterior-superior world (`space` left-posterior-superior or left-anterior-superior
  /// is converted by negating the axes it names the other way); nullopt without directions.
  std::optional<glm::dmat3> world_axes;
  /// From `space origin`: the world position of the centre of the first voxel (converted like
  /// world_axes); 0 when absent.
  glm::dvec3 world_origin{0.0};
  std::string data_file;       ///< detached data file as written ("" = attached)
  std::int64_t byte_skip = 0;  ///< bytes skipped before the data (after line_skip lines)
  std::uint64_t line_skip = 0;
  std::uint64_t header_bytes = 0;  ///< bytes up to and including the blank line ending the header

  glm::u64vec3 extent() const noexcept;
  std::uint32_t channels() const noexcept;
  std::size_t stored_voxel_bytes() const noexcept;
  /// Decoded bytes of all samples; Error(overflow) when it does not fit 64 bits.
  std::uint64_t data_bytes() const;
};

/// Parses an NRRD header: `text` starts with the magic line and holds the header up to the
/// blank line that ends it (anything after that is ignored; a detached header may end at the
/// end of the text). Throws Error(bad_magic) naming `location` without "NRRD000x",
/// Error(corrupt) naming the field and the line's byte offset for malformed lines, missing
/// `type`/`dimension`/`sizes`/`encoding`, counts that disagree with `dimension`, zero sizes,
/// bad spacings; Error(unsupported) naming the field for other types, encodings (ascii, hex,
/// bzip2), data file lists, or an axis layout with no channel-axis interpretation.
/// Thread-safety: a pure function.
NrrdHeader parse_nrrd_header(std::string_view text, std::string_view location);

/// Opens a .nrrd / .nhdr file as a brick source whose coarser levels are built on demand. A
/// detached data file is resolved relative to the header's directory and must stay below it:
/// an absolute path, a ".." component or a symbolic link leading out of that directory is
/// Error(invalid_argument) naming the header and the data file (docs/formats.md, "Files a file
/// may name"). Voxels are held in memory. Throws what parse_nrrd_header throws,
/// Error(io) / Error(truncated) naming the data file.
/// Thread-safety: a pure function; the source is thread-safe as BrickSource requires.
std::unique_ptr<BrickSource> open_nrrd(const std::string& path, const BrickLayout& layout = {});

}  // namespace resoct
