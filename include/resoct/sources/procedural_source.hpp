#pragma once
/// \file
/// Virtual volumes computed on demand: nothing is materialized, so a 65536³ volume is described
/// and any brick read in memory proportional to one brick.
///
/// Spec: `procedural:NAME[:WxHxD[:CHANNELS]]` (the prefix is required). Datasets (all seeded and
/// deterministic: the same spec gives the same bytes on every run and platform):
/// | NAME       | type | default size       | channels | content                                  |
/// |------------|------|--------------------|----------|------------------------------------------|
/// | tubes      | u8   | 256³               | 1..16    | sparse branching tube network, ~all 0    |
/// | noisefloor | u8   | 256³               | 1..16    | blobs on a floor of 8..13 (never 0)      |
/// | turbulence | u8   | 256³               | 1..16    | dense fractal value-noise turbulence     |
/// | mandelbulb | u8   | 256³               | 1..16    | shell around the power-(8 + c) Mandelbulb
/// | | cells      | u16  | 1024×1024×40       | 16..32   | slab of cells, one marker per channel |
/// | constant   | f32  | 64³                | 1..16    | 0.5 everywhere                           |
/// | ramp       | f32  | 64³                | 1..16    | voxel x holds (x + 0.5) / W (channel c:  |
/// |            |      |                    |          | axis c % 3 instead of x)                 |
/// | sphere     | f32  | 64³                | 1..16    | max(0, 1 - r / R), r = distance of the   |
/// |            |      |                    |          | voxel centre from the volume centre, R = |
/// |            |      |                    |          | half the smallest extent                 |
/// tubes, noisefloor and turbulence draw channel c from its own seed; cells channel 0 stains all
/// nuclei and channel c >= 1 a marker-positive subset as cytoplasm, membrane or nucleus (c % 3).
/// Values use the type's default range (u8 0..255, u16 0..65535, f32 0..1). Integer datasets
/// store round(v * max) of a field v in [0, 1].
///
/// Coarser levels. Level l voxels follow the box filter of downsample.hpp. With s =
/// samples_log2 (default 2):
/// - when every axis has factor_log2 <= s (footprint <= 2^s voxels per axis) they are computed
///   exactly: level-0 voxels of the footprint, downsampled level by level as the hierarchy does;
/// - otherwise each footprint axis is cut into 2^min(f, s) sub-intervals (the recursive children
///   at factor g = f - min(f, s), clamped to the volume, with the recursive filter's weights) and
///   the field is sampled once at each sub-interval's centre (the mean of its voxel centres); the
///   weighted mean is rounded once. So every brick of every level costs at most 8^s field
///   evaluations per voxel, at any volume size.
/// Error bound (coarse_error_bound): against exact recursive downsampling of the stored level 0,
///   |error| <= L * D + Q, with L the field's Lipschitz constant (Field::lipschitz times the
///   type's maximum: value units per level-0 voxel), D = sqrt(sum_a ((2^g_a - 1) / 2)^2) the
///   farthest a voxel centre lies from the sample standing for it, and Q = 0.5 * (l + 2) for
///   integer types (level-0 rounding, l rounding steps of the reference, the final rounding) or
///   1e-6 * (l + 2) for f32. Exact levels have bound 0. The bound is proven but only tight for
///   smooth fields (sphere: 0.036 at factor 8 on 48³); for sharp features it is far above what
///   happens. Observed maxima on the test volumes (48³ and 64×64×16, brick 4, all levels), for
///   s = 2 / s = 1, asserted as regression limits (in parentheses) but not proven:
///   | tubes      | 6 / 49 of 255        (24 / 80)       |
///   | mandelbulb | 10 / 38 of 255       (24 / 64)       | no Lipschitz constant: bound +inf
///   | noisefloor | 2 / 12 of 255        (6 / 24)        |
///   | turbulence | 1 / 8 of 255         (6 / 16)        |
///   | cells      | 1375 / 8497 of 65535 (3000 / 12000)  |
///   | sphere     | 0.008 / 0.031        (0.02 / 0.05)   |
///   | ramp, constant | float rounding   (1e-6)          |
///   Cost: a level-l brick takes up to 8^s times the field evaluations of a level-0 brick.
///
/// region_meta is conservative for level-0 voxels: each dataset bounds its field over a box
/// analytically (distance to tube segments, blobs and cells; Lipschitz bounds for turbulence; the
/// Mandelbulb's bounding sphere), refined by splitting the region into up to 64 boxes; occupancy
/// is the union of occupancy_span() of those boxes.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "resoct/sources/brick_source.hpp"
#include "resoct/sources/procedural/field.hpp"

namespace resoct {

/// A parsed procedural spec.
struct ProceduralSpec {
  std::string name;
  glm::u64vec3 extent{0};
  std::uint32_t channels = 0;
  VoxelType type = VoxelType::u8;
};

/// Parses `procedural:NAME[:WxHxD[:CHANNELS]]`, filling defaults. Throws
/// Error(invalid_argument) naming "spec" (missing prefix, unknown name, malformed or zero size,
/// trailing fields) or "channels" (outside the dataset's range).
ProceduralSpec parse_procedural_spec(std::string_view spec);

/// A BrickSource over one procedural field. Immutable; all members are thread-safe.
class ProceduralSource : public BrickSource {
 public:
  /// `samples_log2` (0..3, named s in the file comment) trades coarse-level cost for accuracy:
  /// a level-l brick costs about 8^s times a level-0 brick. Throws Error as
  /// parse_procedural_spec, or naming "samples_log2", or when the layout or hierarchy is invalid.
  explicit ProceduralSource(std::string_view spec, BrickLayout layout = {},
                            std::uint32_t samples_log2 = kDefaultSamplesLog2);

  /// Default s = 2: exact up to footprints of 4 per axis, 64 samples per coarse voxel. s = 1 is
  /// 8x cheaper per coarse brick but about 4x less accurate (see the table above).
  static constexpr std::uint32_t kDefaultSamplesLog2 = 2;

  const BrickHierarchy& hierarchy() const override { return hierarchy_; }
  /// Bricks whose level-0 footprint the field provably holds constant (empty space) are filled
  /// without evaluating the field.
  void read_brick(BrickKey key, std::span<std::byte> out) const override;
  /// Answered from field bounds for provably constant bricks, else by scanning the brick.
  BrickMeta brick_meta(BrickKey key) const override;
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override;
  std::string name() const override { return name_; }

  const ProceduralSpec& spec() const noexcept { return spec_; }
  const procedural::Field& field() const noexcept { return *field_; }
  /// True when level l is computed exactly from level-0 voxels (every factor_log2 <= s).
  /// Throws Error(out_of_range) for a missing level (as do the members below).
  bool exact_level(std::uint32_t level) const;
  /// The documented bound (see file comment) on |level-l voxel - exact recursive downsampling of
  /// level 0|, in stored value units. 0 for exact levels.
  double coarse_error_bound(std::uint32_t level, std::uint32_t channel) const;
  /// The analytic bound on brick `key`'s down-sampling error (measure_brick_error()'s quantity,
  /// range fraction) from the field's Lipschitz constant: lipschitz_brick_error_bound() with
  /// L = Field::lipschitz times the type's maximum, quantization 0.5 (integer types) and the
  /// level's voxels within coarse_error_bound() plus the reference's own roundings (0.5 per
  /// level) of the exact mean. Reads nothing. 1 where the field has no Lipschitz constant
  /// (mandelbulb). Throws Error(out_of_range) for a key outside the hierarchy.
  double brick_error_bound(BrickKey key) const;
  /// measure_brick_error() with brick_error_bound() as the known bound: bricks too large to
  /// measure (over kBrickErrorMeasuredVoxels level-0 voxels: 32³ bricks from level 4 up) get the
  /// analytic bound instead of the far looser metadata spread; smaller ones are measured.
  double brick_error(BrickKey key, std::span<const std::byte> padded) const override;

  /// Voxels of `box` (inside level `level`) of one channel, dense, x fastest, always evaluated
  /// (no constant-brick shortcut). Throws Error(out_of_range) for a bad channel and
  /// Error(invalid_argument) for a box outside the level or a wrongly sized `out`.
  void read_region(std::uint32_t level, std::uint32_t channel, const Box3& box,
                   std::span<std::byte> out) const;

 private:
  void check_level(std::uint32_t level) const;
  Box3 brick_region(BrickKey key) const;
  std::optional<double> constant_value(std::uint32_t level, std::uint32_t channel,
                                       const Box3& region) const;
  void read_level0(std::uint32_t channel, const Box3& box, std::span<std::byte> out) const;
  void read_approximate(std::uint32_t level, std::uint32_t channel, const Box3& box,
                        std::span<std::byte> out) const;

  std::uint32_t samples_log2_;
  ProceduralSpec spec_;
  std::string name_;
  std::unique_ptr<procedural::Field> field_;
  BrickHierarchy hierarchy_;
};

/// Builds a ProceduralSource (see the spec grammar above).
std::unique_ptr<BrickSource> make_procedural_source(std::string_view spec, BrickLayout layout = {});

}  // namespace resoct
