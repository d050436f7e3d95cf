#include "resoct/sources/procedural_source.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "resoct/sources/brick_error.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/volume/downsample.hpp"
#include "resoct/base/error.hpp"

namespace resoct {

namespace procedural {

namespace {
struct DatasetInfo {
  std::string_view name;
  VoxelType type;
  glm::u64vec3 extent;
  std::uint32_t min_channels, max_channels, default_channels;
  std::unique_ptr<Field> (*make)(const glm::u64vec3&, std::uint32_t);
};

constexpr std::array<DatasetInfo, 8> kDatasets{{
    {"tubes", VoxelType::u8, {256, 256, 256}, 1, 16, 1, make_tubes_field},
    {"noisefloor", VoxelType::u8, {256, 256, 256}, 1, 16, 1, make_noisefloor_field},
    {"turbulence", VoxelType::u8, {256, 256, 256}, 1, 16, 1, make_turbulence_field},
    {"mandelbulb", VoxelType::u8, {256, 256, 256}, 1, 16, 1, make_mandelbulb_field},
    {"cells", VoxelType::u16, {1024, 1024, 40}, 16, 32, 16, make_cells_field},
    {"constant", VoxelType::f32, {64, 64, 64}, 1, 16, 1, make_constant_field},
    {"ramp", VoxelType::f32, {64, 64, 64}, 1, 16, 1, make_ramp_field},
    {"sphere", VoxelType::f32, {64, 64, 64}, 1, 16, 1, make_sphere_field},
}};
constexpr std::array<std::string_view, kDatasets.size()> kNames = [] {
  std::array<std::string_view, kDatasets.size()> n{};
  for (std::size_t i = 0; i < kDatasets.size(); ++i) n[i] = kDatasets[i].name;
  return n;
}();

const DatasetInfo* find_dataset(std::string_view name) {
  for (const DatasetInfo& d : kDatasets) {
    if (d.name == name) return &d;
  }
  return nullptr;
}
}  // namespace

std::span<const std::string_view> field_names() noexcept {
  return kNames;
}

std::unique_ptr<Field> make_field(std::string_view name, const glm::u64vec3& extent,
                                  std::uint32_t channels) {
  const DatasetInfo* d = find_dataset(name);
  return d ? d->make(extent, channels) : nullptr;
}

}  // namespace procedural

namespace {

constexpr std::string_view kPrefix = "procedural:";

// Field bounds are widened by this before quantizing, so that evaluation and bounding
// arithmetic cannot disagree in the last bit.
constexpr double kBoundSlack = 1e-9;

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  for (;;) {
    const std::size_t p = s.find(sep);
    out.push_back(s.substr(0, p));
    if (p == std::string_view::npos) return out;
    s.remove_prefix(p + 1);
  }
}

template <typename T>
bool parse_uint(std::string_view s, T& out) {
  if (s.empty()) return false;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size();
}

Error spec_error(std::string_view spec, std::string_view why) {
  return invalid_parameter("spec", "'" + std::string(spec) + "': " + std::string(why));
}

double type_scale(VoxelType t) {
  return t == VoxelType::u8 ? 255.0 : t == VoxelType::u16 ? 65535.0 : 1.0;
}

// Field value in [0, 1] to the stored voxel. Monotone, so bounds map to bounds.
void quantize(std::span<const double> v, VoxelType t, std::byte* out) {
  switch (t) {
    case VoxelType::u8:
      for (std::size_t i = 0; i < v.size(); ++i) {
        out[i] = std::byte(std::uint8_t(std::floor(std::clamp(v[i], 0.0, 1.0) * 255.0 + 0.5)));
      }
      break;
    case VoxelType::u16:
      for (std::size_t i = 0; i < v.size(); ++i) {
        const auto q = std::uint16_t(std::floor(std::clamp(v[i], 0.0, 1.0) * 65535.0 + 0.5));
        std::memcpy(out + 2 * i, &q, 2);
      }
      break;
    case VoxelType::f32:
      for (std::size_t i = 0; i < v.size(); ++i) {
        const float f = float(v[i]);
        std::memcpy(out + 4 * i, &f, 4);
      }
      break;
  }
}

double quantized(double v, VoxelType t) {
  std::byte b[4];
  quantize(std::span<const double>(&v, 1), t, b);
  switch (t) {
    case VoxelType::u8: return double(std::uint8_t(b[0]));
    case VoxelType::u16: {
      std::uint16_t q;
      std::memcpy(&q, b, 2);
      return double(q);
    }
    case VoxelType::f32: {
      float f;
      std::memcpy(&f, b, 4);
      return double(f);
    }
  }
  return v;
}

std::string canonical_name(const ProceduralSpec& s) {
  std::string n = "procedural:";
  n += s.name;
  for (int a = 0; a < 3; ++a) {
    n += a == 0 ? ':' : 'x';
    n += std::to_string(s.extent[a]);
  }
  if (s.channels != 1) {
    n += ':';
    n += std::to_string(s.channels);
  }
  return n;
}

VolumeDesc desc_of(const ProceduralSpec& s) {
  VolumeDesc d;
  d.extent = s.extent;
  d.channels = s.channels;
  d.type = s.type;
  return d;
}

// Sample positions and weights along one axis for one coarse voxel: the recursive children at
// factor g of voxel i at factor f, clamped to the level-0 extent e0, each weighted as the
// recursive box filter weighs it, placed at the mean of its level-0 voxel centres.
void axis_samples(std::uint64_t i, std::uint32_t f, std::uint32_t g, std::uint64_t e0,
                  double weight, std::vector<double>& pos, std::vector<double>& w) {
  if (f == g) {
    const std::uint64_t lo = i << g;
    const std::uint64_t hi = std::min((i + 1) << g, e0);
    pos.push_back(0.5 * double(lo + hi));
    w.push_back(weight);
    return;
  }
  const bool second = ((2 * i + 1) << (f - 1)) < e0;
  const double cw = second ? 0.5 * weight : weight;
  axis_samples(2 * i, f - 1, g, e0, cw, pos, w);
  if (second) axis_samples(2 * i + 1, f - 1, g, e0, cw, pos, w);
}

}  // namespace

ProceduralSpec parse_procedural_spec(std::string_view spec) {
  if (spec.substr(0, kPrefix.size()) != kPrefix) {
    throw spec_error(spec, "must start with 'procedural:'");
  }
  const std::vector<std::string_view> parts = split(spec.substr(kPrefix.size()), ':');
  if (parts.size() > 3) throw spec_error(spec, "expected procedural:NAME[:WxHxD[:CHANNELS]]");
  const procedural::DatasetInfo* d = procedural::find_dataset(parts[0]);
  if (d == nullptr) {
    std::string known;
    for (std::string_view n : procedural::field_names())
      known += (known.empty() ? "" : ", ") + std::string(n);
    throw spec_error(spec,
                     "unknown dataset '" + std::string(parts[0]) + "' (known: " + known + ")");
  }
  ProceduralSpec out;
  out.name = std::string(d->name);
  out.type = d->type;
  out.extent = d->extent;
  out.channels = d->default_channels;
  if (parts.size() >= 2) {
    const std::vector<std::string_view> dims = split(parts[1], 'x');
    if (dims.size() != 3)
      throw spec_error(spec, "size '" + std::string(parts[1]) + "' is not WxHxD");
    for (int a = 0; a < 3; ++a) {
      std::uint64_t v = 0;
      if (!parse_uint(dims[std::size_t(a)], v) || v == 0 || v > (1ull << 32)) {
        throw spec_error(
            spec, "size '" + std::string(parts[1]) + "' needs three integers in 1..4294967296");
      }
      out.extent[a] = v;
    }
  }
  if (parts.size() == 3) {
    std::uint32_t c = 0;
    if (!parse_uint(parts[2], c) || c < d->min_channels || c > d->max_channels) {
      throw invalid_parameter("channels", "'" + std::string(spec) + "': " + out.name + " takes " +
                                              std::to_string(d->min_channels) + ".." +
                                              std::to_string(d->max_channels) + " channels, got '" +
                                              std::string(parts[2]) + "'");
    }
    out.channels = c;
  }
  return out;
}

ProceduralSource::ProceduralSource(std::string_view spec, BrickLayout layout,
                                   std::uint32_t samples_log2)
    : samples_log2_(samples_log2 <= 3
                        ? samples_log2
                        : throw invalid_parameter(
                              "samples_log2", "must be 0..3, got " + std::to_string(samples_log2))),
      spec_(parse_procedural_spec(spec)),
      name_(canonical_name(spec_)),
      field_(procedural::make_field(spec_.name, spec_.extent, spec_.channels)),
      hierarchy_(desc_of(spec_), layout) {}

void ProceduralSource::check_level(std::uint32_t level) const {
  if (level >= hierarchy_.level_count()) {
    throw Error(ErrorCode::out_of_range, name_ + ": parameter 'level': " + std::to_string(level) +
                                             " of " + std::to_string(hierarchy_.level_count()));
  }
}

bool ProceduralSource::exact_level(std::uint32_t level) const {
  check_level(level);
  const glm::uvec3 f = hierarchy_.level(level).factor_log2;
  return f.x <= samples_log2_ && f.y <= samples_log2_ && f.z <= samples_log2_;
}

double ProceduralSource::coarse_error_bound(std::uint32_t level, std::uint32_t channel) const {
  if (channel >= spec_.channels) {
    throw Error(ErrorCode::out_of_range, name_ +
                                             ": parameter 'channel': " + std::to_string(channel) +
                                             " of " + std::to_string(spec_.channels));
  }
  if (exact_level(level)) return 0.0;
  const glm::uvec3 f = hierarchy_.level(level).factor_log2;
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const std::uint32_t g = f[a] - std::min(f[a], samples_log2_);
    const double half = 0.5 * (std::ldexp(1.0, int(g)) - 1.0);
    d2 += half * half;
  }
  const double lip = field_->lipschitz(channel) * type_scale(spec_.type);
  if (!std::isfinite(lip)) return std::numeric_limits<double>::infinity();
  const double q = spec_.type == VoxelType::f32 ? 1e-6 * (level + 2) : 0.5 * (level + 2);
  return lip * std::sqrt(d2) + q;
}

double ProceduralSource::brick_error_bound(BrickKey key) const {
  // lipschitz_brick_error_bound refuses a key outside the hierarchy (and answers 0 at level 0);
  // the field and the level's bound are asked only for keys inside it.
  LipschitzErrorTerms terms;
  if (hierarchy_.contains(key) && key.level() > 0) {
    // f32: float(v) of a value in [0, 1] is within 2^-25 of it; 1e-7 per rounding is generous.
    const double rounding = spec_.type != VoxelType::f32 ? 0.5 : 1e-7;
    terms.lipschitz = field_->lipschitz(key.channel()) * type_scale(spec_.type);
    terms.voxel_error = rounding;
    terms.level_error =
        coarse_error_bound(key.level(), key.channel()) + rounding * double(key.level());
  }
  return lipschitz_brick_error_bound(hierarchy_, key, terms);
}

double ProceduralSource::brick_error(BrickKey key, std::span<const std::byte> padded) const {
  return measure_brick_error(*this, key, padded, kBrickErrorMeasuredVoxels, brick_error_bound(key));
}

void ProceduralSource::read_level0(std::uint32_t channel, const Box3& box,
                                   std::span<std::byte> out) const {
  const glm::i64vec3 s = box.size();
  std::vector<double> xs(std::size_t(s.x)), ys(std::size_t(s.y)), vals(xs.size() * ys.size());
  for (std::int64_t i = 0; i < s.x; ++i) xs[std::size_t(i)] = double(box.lo.x + i) + 0.5;
  for (std::int64_t i = 0; i < s.y; ++i) ys[std::size_t(i)] = double(box.lo.y + i) + 0.5;
  const std::size_t vs = voxel_size(spec_.type);
  for (std::int64_t z = 0; z < s.z; ++z) {
    const double zc = double(box.lo.z + z) + 0.5;
    field_->eval_grid(channel, xs, ys, std::span<const double>(&zc, 1), vals);
    quantize(vals, spec_.type, out.data() + std::size_t(z) * vals.size() * vs);
  }
}

void ProceduralSource::read_approximate(std::uint32_t level, std::uint32_t channel, const Box3& box,
                                        std::span<std::byte> out) const {
  const glm::uvec3 f = hierarchy_.level(level).factor_log2;
  const glm::u64vec3 e0 = spec_.extent;
  // Per axis: concatenated samples of every voxel of the box, and where each voxel's start.
  std::array<std::vector<double>, 3> pos, wt;
  std::array<std::vector<std::size_t>, 3> first;
  for (int a = 0; a < 3; ++a) {
    const std::uint32_t g = f[a] - std::min(f[a], samples_log2_);
    for (std::int64_t i = box.lo[a]; i < box.hi[a]; ++i) {
      first[a].push_back(pos[a].size());
      axis_samples(std::uint64_t(i), f[a], g, e0[a], 1.0, pos[a], wt[a]);
    }
    first[a].push_back(pos[a].size());
  }
  const std::size_t nx = pos[0].size(), ny = pos[1].size();
  const std::size_t ox = std::size_t(box.size().x), oy = std::size_t(box.size().y);
  std::vector<double> vals, rx, slice(ox * oy);
  const std::size_t vs = voxel_size(spec_.type);
  for (std::size_t iz = 0; iz < std::size_t(box.size().z); ++iz) {
    const std::size_t z0 = first[2][iz], nz = first[2][iz + 1] - z0;
    vals.resize(nx * ny * nz);
    field_->eval_grid(channel, pos[0], pos[1], std::span<const double>(pos[2]).subspan(z0, nz),
                      vals);
    // Separable weighted reduction: x, then y, then z.
    rx.assign(ox * ny * nz, 0.0);
    for (std::size_t r = 0; r < ny * nz; ++r)
      for (std::size_t x = 0; x < ox; ++x)
        for (std::size_t s = first[0][x]; s < first[0][x + 1]; ++s)
          rx[r * ox + x] += wt[0][s] * vals[r * nx + s];
    std::fill(slice.begin(), slice.end(), 0.0);
    for (std::size_t sz = 0; sz < nz; ++sz) {
      const double wz = wt[2][z0 + sz];
      for (std::size_t y = 0; y < oy; ++y)
        for (std::size_t s = first[1][y]; s < first[1][y + 1]; ++s)
          for (std::size_t x = 0; x < ox; ++x)
            slice[y * ox + x] += wz * wt[1][s] * rx[(sz * ny + s) * ox + x];
    }
    quantize(slice, spec_.type, out.data() + iz * slice.size() * vs);
  }
}

void ProceduralSource::read_region(std::uint32_t level, std::uint32_t channel, const Box3& box,
                                   std::span<std::byte> out) const {
  if (channel >= spec_.channels) {
    throw Error(ErrorCode::out_of_range, name_ +
                                             ": parameter 'channel': " + std::to_string(channel) +
                                             " of " + std::to_string(spec_.channels));
  }
  if (!exact_level(level)) {
    const Box3 lv{glm::i64vec3(0), glm::i64vec3(hierarchy_.level(level).extent)};
    if (box.empty() || intersect(box, lv) != box) {
      throw invalid_parameter("box",
                              "must be a non-empty box inside level " + std::to_string(level));
    }
    if (out.size() != std::uint64_t(box.volume()) * voxel_size(spec_.type)) {
      throw invalid_parameter("out", "buffer size does not match the box");
    }
    read_approximate(level, channel, box, out);
    return;
  }
  downsample_levels(
      hierarchy_, 0, level, box,
      [&](const Box3& b0, std::span<std::byte> o) { read_level0(channel, b0, o); }, out);
}

Box3 ProceduralSource::brick_region(BrickKey key) const {
  const std::uint32_t l = key.level();
  return intersect(hierarchy_.padded_box(l, key.brick()),
                   Box3{glm::i64vec3(0), glm::i64vec3(hierarchy_.level(l).extent)});
}

std::optional<double> ProceduralSource::constant_value(std::uint32_t level, std::uint32_t channel,
                                                       const Box3& region) const {
  // Every level-l voxel of the region, exact or approximated, is a weighted mean of field values
  // inside the region's level-0 footprint. When the field's bound over the footprint quantizes
  // to one value, every such mean (and every rounding of it) is that value.
  const glm::uvec3 f = hierarchy_.level(level).factor_log2;
  glm::dvec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = double(region.lo[a] << f[a]) + 0.5;
    hi[a] = double(std::min(region.hi[a] << f[a], std::int64_t(spec_.extent[a]))) - 0.5;
  }
  const procedural::Interval iv = field_->bound(channel, lo, hi);
  const double a = quantized(iv.lo - kBoundSlack, spec_.type);
  const double b = quantized(iv.hi + kBoundSlack, spec_.type);
  if (a != b) return std::nullopt;
  return a;
}

void ProceduralSource::read_brick(BrickKey key, std::span<std::byte> out) const {
  check_brick_request(key, out);
  const Box3 region = brick_region(key);
  const std::size_t vs = voxel_size(spec_.type);
  if (const std::optional<double> v = constant_value(key.level(), key.channel(), region)) {
    // Empty space (and any provably constant brick) costs no field evaluations.
    std::byte one[4];
    quantize(std::span<const double>(&*v, 1), spec_.type, one);
    for (std::size_t i = 0; i < out.size(); i += vs) std::memcpy(out.data() + i, one, vs);
    return;
  }
  std::vector<std::byte> buf(std::size_t(region.volume()) * vs);
  read_region(key.level(), key.channel(), region, buf);
  copy_box_clamped(buf, region, out, hierarchy_.padded_box(key.level(), key.brick()), vs);
}

BrickMeta ProceduralSource::brick_meta(BrickKey key) const {
  if (hierarchy_.contains(key)) {
    if (const std::optional<double> v =
            constant_value(key.level(), key.channel(), brick_region(key))) {
      return BrickMeta{*v, *v, true};
    }
  }
  return BrickSource::brick_meta(key);
}

RegionMeta ProceduralSource::region_meta(std::uint32_t channel, const Box3& level0_region) const {
  if (channel >= spec_.channels) {
    throw Error(ErrorCode::out_of_range, name_ +
                                             ": parameter 'channel': " + std::to_string(channel) +
                                             " of " + std::to_string(spec_.channels));
  }
  const Box3 r = intersect(level0_region, Box3{glm::i64vec3(0), glm::i64vec3(spec_.extent)});
  if (r.empty()) return {};
  const ValueRange range = hierarchy_.volume().range(channel);
  RegionMeta out;
  // Depth-limited bisection (at most 64 leaves): tight where the field bound decides quickly,
  // bounded cost everywhere.
  auto visit = [&](auto&& self, const Box3& b, int depth) -> void {
    // Bounds over the voxel centres the box holds.
    const procedural::Interval iv =
        field_->bound(channel, glm::dvec3(b.lo) + 0.5, glm::dvec3(b.hi) - 0.5);
    const glm::i64vec3 s = b.size();
    const int axis = s.x >= s.y && s.x >= s.z ? 0 : s.y >= s.z ? 1 : 2;
    if (depth == 0 || iv.lo == iv.hi || s[axis] < 2) {
      RegionMeta m;
      m.min = quantized(iv.lo - kBoundSlack, spec_.type);
      m.max = quantized(iv.hi + kBoundSlack, spec_.type);
      m.occupancy = occupancy_span(m.min, m.max, range);
      out.merge(m);
      return;
    }
    Box3 left = b, right = b;
    left.hi[axis] = right.lo[axis] = b.lo[axis] + s[axis] / 2;
    self(self, left, depth - 1);
    self(self, right, depth - 1);
  };
  visit(visit, r, 6);
  return out;
}

std::unique_ptr<BrickSource> make_procedural_source(std::string_view spec, BrickLayout layout) {
  return std::make_unique<ProceduralSource>(spec, layout);
}

}  // namespace resoct
