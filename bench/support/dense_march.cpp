#include "support/dense_march.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <exception>
#include <span>
#include <string>
#include <type_traits>

#include <omp.h>

#include <glm/geometric.hpp>

#include "resoct/volume/brick_key.hpp"
#include "resoct/scene/camera.hpp"
#include "resoct/scene/step_lut.hpp"
#include "resoct/base/error.hpp"

namespace resoct::bench {

namespace {

// Constants of the per-ray definition (kernel/ray, step, composite, tf .glsl.h; the values are
// those of docs/rendering.md).
constexpr float kParallelEps = 1.0e-20f;  // |d_i| below this never limits the step or the box
constexpr float kTInf = 3.0e38f;
constexpr float kSegmentEps = 1.0e-4f;  // a ray ends when less than this fraction of a step remains
constexpr float kTUlpFactor = 1.1920929e-7f;
constexpr float kTMinAdvance = 1.0e-30f;
constexpr float kSeriesLimit = 0.0625f;
constexpr float kLn2 = 0.69314718056f;
constexpr float kInvLn2 = 1.44269504089f;
constexpr std::uint32_t kLutSize = kTfLutSize;
constexpr std::uint32_t kTile = 16;  // the CPU backend's tile edge

// ln(1 − a) for a in [0, 1), with its series below 1/16 (composite.glsl.h).
inline float log_one_minus(float a) {
  if (a < kSeriesLimit) {
    return -a *
           (1.0f + a * (0.5f + a * (0.33333333f + a * (0.25f + a * (0.2f + a * 0.16666667f)))));
  }
  return std::log2(1.0f - a) * kLn2;
}

// 1 − e^y for y <= 0, with its series above −1/16.
inline float one_minus_exp(float y) {
  if (y > -kSeriesLimit) {
    return -y *
           (1.0f + y * (0.5f + y * (0.16666667f +
                                    y * (0.041666668f + y * (0.0083333333f + y * 0.0013888889f)))));
  }
  return 1.0f - std::exp2(y * kInvLn2);
}

// Opacity of a segment of `ratio` reference steps; the caller has checked alpha > 0.
inline float correct_opacity(float alpha, float ratio) {
  if (alpha >= 1.0f) return 1.0f;
  return std::clamp(one_minus_exp(ratio * log_one_minus(alpha)), 0.0f, 1.0f);
}

// Entry and exit of the half-open slab [lo, hi) along one axis (ray.glsl.h): the ray's
// reciprocal direction component, 0 where it is parallel, multiplies the plane distances.
inline glm::vec2 slab(float origin, float dir, float lo, float hi) {
  const float inv = std::abs(dir) < kParallelEps ? 0.0f : 1.0f / dir;
  if (inv == 0.0f) {
    if (origin >= lo && origin < hi) return {-kTInf, kTInf};
    return {kTInf, -kTInf};
  }
  const float t0 = (lo - origin) * inv;
  const float t1 = (hi - origin) * inv;
  return {std::min(t0, t1), std::max(t0, t1)};
}

// One voxel of the array as float (memcpy: the array is bytes; compiles to one load).
template <class T>
inline float load(const std::byte* base, std::size_t i) {
  T v;
  std::memcpy(&v, base + i * sizeof(T), sizeof(T));
  return float(v);
}

// Everything the march loop reads, hoisted out of the pixel loop.
struct Setup {
  const DenseMarch::Frame* f;
  const glm::vec4* lut;
  const glm::vec4* level_luts;  // corrected, premultiplied LUT per step level
  StepLevels levels;
  std::size_t row, plane;  // strides of the padded array (elements)
};

// What march_pixel does with the samples: marches every segment (the dense march), marches every
// segment and keeps the visible ones (record_visible), or evaluates only kept ones (the
// oracle-culling bound, render_visible).
enum class Pass { dense, record, replay };

// One pixel: the premultiplied colour over the background. Pass::record appends the ray's
// visible samples to `kept`; Pass::replay evaluates `replay` instead of marching.
template <class T, Pass kPass>
[[gnu::always_inline]] inline glm::vec4 march_pixel(const Setup& s, const std::byte* vox,
                                                    std::uint32_t px, std::uint32_t py,
                                                    std::uint64_t& samples, std::uint64_t& visible,
                                                    std::vector<VisibleSample>* kept,
                                                    std::span<const VisibleSample> replay) {
  const DenseMarch::Frame& f = *s.f;
  glm::vec4 acc(0.0f);
  const glm::vec4 bg = f.background;
  const glm::vec4 bg_premul(glm::vec3(bg) * bg.a, bg.a);

  // Camera ray exactly as the kernel computes it (camera_ray.glsl.h).
  const float rows = float(f.height);
  const float u = (2.0f * (float(px) + 0.5f) - float(f.width)) / rows * f.half_height;
  const float v = (rows - 2.0f * (float(py) + 0.5f)) / rows * f.half_height;
  glm::vec3 dir_box;
  glm::ivec3 o_cell = f.eye_cell;
  glm::vec3 o_frac = f.eye_frac;
  if (f.perspective) {
    dir_box = glm::normalize(f.forward + u * f.right + v * f.up);
  } else {
    dir_box = f.forward;
    o_frac = o_frac + (u * f.right + v * f.up) * f.voxels_per_box;
    const glm::vec3 whole = glm::floor(o_frac);
    o_cell = o_cell + glm::ivec3(whole);
    o_frac = o_frac - whole;
  }
  const glm::vec3 dv = dir_box * f.voxels_per_box;

  // The volume [0, extent) relative to the origin cell (exact integer corners).
  const glm::vec3 lo(-o_cell);
  const glm::vec3 hi(f.extent - o_cell);
  const glm::vec2 sx = slab(o_frac.x, dv.x, lo.x, hi.x);
  const glm::vec2 sy = slab(o_frac.y, dv.y, lo.y, hi.y);
  const glm::vec2 sz = slab(o_frac.z, dv.z, lo.z, hi.z);
  float t = std::max(std::max(sx.x, std::max(sy.x, sz.x)), 0.0f);
  const float t_exit = std::min(sx.y, std::min(sy.y, sz.y));
  if (!(t < t_exit)) return acc + (1.0f - acc.a) * bg_premul;

  // Step (Eq. 8.2-8.3) at level-0 voxels, and the per-ray constants of the loop.
  const glm::vec3 ad = glm::abs(dir_box);
  float dt = kTInf;
  if (ad.x >= kParallelEps) dt = std::min(dt, f.finest_voxel.x / ad.x);
  if (ad.y >= kParallelEps) dt = std::min(dt, f.finest_voxel.y / ad.y);
  if (ad.z >= kParallelEps) dt = std::min(dt, f.finest_voxel.z / ad.z);
  if (dt >= kTInf) dt = std::min(f.finest_voxel.x, std::min(f.finest_voxel.y, f.finest_voxel.z));
  dt = std::max(dt * f.step_scale, f.min_step);
  // The step rounded down to its level, whose LUT holds the corrected, premultiplied colours of
  // full steps (kernel/step_lut.glsl.h); a ray without a level corrects every sample.
  const glm::vec4* level_lut = nullptr;
  {
    const float ratio = dt * (1.0f / f.ref_step);
    const std::uint32_t level =
        (std::bit_cast<std::uint32_t>(ratio) >> s.levels.shift) - s.levels.first;
    if (ratio > 0.0f && level < s.levels.count) {
      dt = step_level_ratio(s.levels, level) * f.ref_step;
      level_lut = s.level_luts + std::size_t(level) * kLutSize;
    }
  }
  const float end_eps = kSegmentEps * dt;
  const float half_dt = 0.5f * dt;
  const float ratio_full = dt * (1.0f / f.ref_step);
  // Padded-array coordinate (voxel centres at integers) of the sample at parameter tm:
  // o_cell + 1 + (o_frac + tm · dv) − 0.5 = base + tm · dv. No clamp: samples lie in [t_enter,
  // t_exit), so coordinates stay within rounding of [0.5, extent + 0.5], and the border voxels
  // (and truncation toward zero just below 0) keep the footprint inside the array and the value
  // clamp-to-edge.
  const float base_x = o_frac.x + (float(o_cell.x) + 0.5f);
  const float base_y = o_frac.y + (float(o_cell.y) + 0.5f);
  const float base_z = o_frac.z + (float(o_cell.z) + 0.5f);
  const float lo_norm = f.range_lo, inv_width = f.inv_range_width;
  const float ert = f.ert_opacity;
  const glm::vec4* lut = s.lut;
  const std::size_t row = s.row, plane = s.plane;

  std::uint64_t n = 0, nv = 0;
  // One sample at parameter tm of a segment of `ratio` reference steps (with `corrected`, a
  // full step of the ray's level: its LUT); true once saturated.
  const auto sample = [&](float tm, float ratio,
                          const glm::vec4* corrected) [[gnu::always_inline]] {
    const float cx = base_x + tm * dv.x;
    const float cy = base_y + tm * dv.y;
    const float cz = base_z + tm * dv.z;
    const int x0 = int(cx), y0 = int(cy), z0 = int(cz);
    const float fx = cx - float(x0), fy = cy - float(y0), fz = cz - float(z0);
    const std::size_t i = std::size_t(z0) * plane + std::size_t(y0) * row + std::size_t(x0);
    const std::size_t k = i + plane;
    const float v000 = load<T>(vox, i), v100 = load<T>(vox, i + 1);
    const float v010 = load<T>(vox, i + row), v110 = load<T>(vox, i + row + 1);
    const float v001 = load<T>(vox, k), v101 = load<T>(vox, k + 1);
    const float v011 = load<T>(vox, k + row), v111 = load<T>(vox, k + row + 1);
    const float c00 = v000 + fx * (v100 - v000);
    const float c10 = v010 + fx * (v110 - v010);
    const float c01 = v001 + fx * (v101 - v001);
    const float c11 = v011 + fx * (v111 - v011);
    const float c0 = c00 + fy * (c10 - c00);
    const float c1 = c01 + fy * (c11 - c01);
    const float raw = c0 + fz * (c1 - c0);

    // Transfer function: normalized value, LUT entry pair, alpha first (tf.glsl.h); NaN voxels
    // (float data only) are transparent.
    const float value = (raw - lo_norm) * inv_width;
    if constexpr (std::is_floating_point_v<T>) {
      if (std::isnan(value)) return false;
    }
    const float x = std::min(std::max(value, 0.0f), 1.0f) * float(kLutSize - 1u);
    const std::uint32_t e = std::min(std::uint32_t(x), kLutSize - 2u);
    const float w = x - float(e);
    if (corrected != nullptr) {
      const glm::vec4 p = corrected[e] * (1.0f - w) + corrected[e + 1u] * w;
      if (!(p.a > 0.0f)) return false;
      ++nv;
      acc = acc + (1.0f - acc.a) * p;
      return acc.a >= ert;
    }
    const glm::vec4 a = lut[e], b = lut[e + 1u];
    const float alpha = a.a * (1.0f - w) + b.a * w;
    if (!(alpha > 0.0f)) return false;
    ++nv;
    const float op = correct_opacity(alpha, ratio);
    const glm::vec3 rgb = glm::vec3(a) * (1.0f - w) + glm::vec3(b) * w;
    // Front to back, premultiplied (composite.glsl.h): A += (1 − A.a) · (rgb · α', α').
    acc = acc + (1.0f - acc.a) * glm::vec4(rgb * op, op);
    return acc.a >= ert;
  };
  if constexpr (kPass == Pass::replay) {
    // The kept samples alone, each as the march below evaluated it.
    for (const VisibleSample& k : replay) {
      ++n;
      const bool from_level = k.ratio < 0.0f;
      if (sample(k.tm, from_level ? ratio_full : k.ratio, from_level ? level_lut : nullptr)) break;
    }
    samples += n;
    visible += nv;
    return acc + (1.0f - acc.a) * bg_premul;
  }
  // Pass::record: the sample at tm is kept when it added colour.
  const auto keep = [&](std::uint64_t nv_before, float tm, float ratio, bool from_level) {
    if constexpr (kPass == Pass::record) {
      if (nv != nv_before) kept->push_back({tm, from_level ? -1.0f : ratio});
    }
  };
  // Whole steps [t, t + dt) while they fit, then the shorter last segment(s), corrected for
  // their length (resoct_segment_length). Step j starts at t_grid + j * dt, each operation
  // rounded once (resoct_grid_t), at least one ulp past the previous start.
  const float t_grid = t;
  std::uint32_t j = 0;
  const auto next_t = [&](float current) {
    ++j;
    const float jdt = float(j) * dt;
    float next = t_grid + jdt;
    if (next <= current) {
      next = current + dt;
      if (next <= current) {
        next = current + std::max(std::abs(current) * kTUlpFactor, kTMinAdvance);
      }
    }
    return next;
  };
  bool saturated = false;
  while (t_exit - t >= dt) {
    ++n;
    const std::uint64_t nv_before = nv;
    const bool done = sample(t + half_dt, ratio_full, level_lut);
    keep(nv_before, t + half_dt, ratio_full, level_lut != nullptr);
    if (done) {
      saturated = true;
      break;
    }
    t = next_t(t);
  }
  while (!saturated && t_exit - t > end_eps) {
    ++n;
    const float seg = std::max(std::min(dt, t_exit - t), 0.0f);
    const glm::vec4* corrected = seg == dt ? level_lut : nullptr;
    const std::uint64_t nv_before = nv;
    const bool done = sample(t + 0.5f * seg, seg * (1.0f / f.ref_step), corrected);
    keep(nv_before, t + 0.5f * seg, seg * (1.0f / f.ref_step), corrected != nullptr);
    if (done) break;
    t = next_t(t);
  }
  samples += n;
  visible += nv;
  return acc + (1.0f - acc.a) * bg_premul;
}

template <class T, Pass kPass = Pass::dense>
DenseStats render_typed(const Setup& s, const std::byte* vox, glm::vec4* pixels, int threads,
                        std::vector<std::vector<VisibleSample>>* kept = nullptr,
                        const VisibleSamples* replay = nullptr) {
  const DenseMarch::Frame& f = *s.f;
  const std::uint32_t tiles_x = (f.width + kTile - 1) / kTile;
  const std::uint32_t tiles_y = (f.height + kTile - 1) / kTile;
  const std::int64_t tile_count = std::int64_t(tiles_x) * tiles_y;
  std::uint64_t samples = 0, visible = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : samples, visible)
  for (std::int64_t tile = 0; tile < tile_count; ++tile) {
    const std::uint32_t tx = std::uint32_t(tile % tiles_x) * kTile;
    const std::uint32_t ty = std::uint32_t(tile / tiles_x) * kTile;
    const std::uint32_t x1 = std::min(tx + kTile, f.width);
    const std::uint32_t y1 = std::min(ty + kTile, f.height);
    for (std::uint32_t y = ty; y < y1; ++y) {
      for (std::uint32_t x = tx; x < x1; ++x) {
        const std::size_t ray = std::size_t(y) * f.width + x;
        std::span<const VisibleSample> mine;
        if constexpr (kPass == Pass::replay) {
          mine =
              std::span<const VisibleSample>(replay->samples)
                  .subspan(replay->offsets[ray], replay->offsets[ray + 1] - replay->offsets[ray]);
        }
        const glm::vec4 p = march_pixel<T, kPass>(
            s, vox, x, y, samples, visible, kPass == Pass::record ? &(*kept)[ray] : nullptr, mine);
        pixels[std::size_t(y) * f.width + x] =
            p.a > 0.0f ? glm::vec4(glm::vec3(p) / p.a, p.a) : glm::vec4(0.0f);
      }
    }
  }
  DenseStats st;
  st.rays = std::uint64_t(f.width) * f.height;
  st.samples = samples;
  st.visible_samples = visible;
  return st;
}

}  // namespace

DenseVolume DenseVolume::read(const BrickSource& source, std::uint32_t channel) {
  const BrickHierarchy& h = source.hierarchy();
  DenseVolume d;
  d.volume = h.volume();
  if (channel >= d.volume.channels) {
    throw invalid_parameter("channel", std::to_string(channel) + " of " +
                                           std::to_string(d.volume.channels) + " channels");
  }
  d.channel = channel;
  const glm::uvec3 e(d.volume.extent);
  d.padded = e + 2u;
  const std::size_t vs = voxel_size(d.volume.type);
  const std::size_t px = d.padded.x, py = d.padded.y, pz = d.padded.z;
  d.voxels.assign(px * py * pz * vs, std::byte{0});

  // Level-0 bricks, their cores copied into the interior (bricks in parallel: sources are
  // thread-safe and procedural bricks cost field evaluations).
  const BrickLayout& bl = h.layout();
  const LevelInfo& l0 = h.level(0);
  const glm::uvec3 pb = bl.padded_size();
  const std::int64_t count = std::int64_t(l0.brick_count);
  std::exception_ptr failure;
#pragma omp parallel
  {
    std::vector<std::byte> brick(std::size_t(bl.padded_voxels()) * vs);
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t b = 0; b < count; ++b) {
      const glm::uvec3 c(std::uint32_t(b % l0.bricks.x),
                         std::uint32_t((b / l0.bricks.x) % l0.bricks.y),
                         std::uint32_t(b / (std::int64_t(l0.bricks.x) * l0.bricks.y)));
      try {
        source.read_brick(BrickKey(0, channel, c), brick);
      } catch (...) {
#pragma omp critical(resoct_dense_read)
        if (!failure) failure = std::current_exception();
        continue;
      }
      const glm::uvec3 first = c * bl.brick_size;
      const glm::uvec3 size = glm::min(bl.brick_size, e - first);
      for (std::uint32_t z = 0; z < size.z; ++z) {
        for (std::uint32_t y = 0; y < size.y; ++y) {
          const std::size_t src =
              ((std::size_t(z + bl.halo) * pb.y + (y + bl.halo)) * pb.x + bl.halo) * vs;
          const std::size_t dst =
              ((std::size_t(first.z + z + 1) * py + (first.y + y + 1)) * px + first.x + 1) * vs;
          std::memcpy(d.voxels.data() + dst, brick.data() + src, std::size_t(size.x) * vs);
        }
      }
    }
  }
  if (failure) std::rethrow_exception(failure);
  // The border: x, then y (whole rows), then z (whole planes), so edges and corners repeat
  // their nearest volume voxel.
  std::byte* v = d.voxels.data();
  for (std::size_t z = 1; z + 1 < pz; ++z) {
    for (std::size_t y = 1; y + 1 < py; ++y) {
      std::byte* row = v + (z * py + y) * px * vs;
      std::memcpy(row, row + vs, vs);
      std::memcpy(row + (px - 1) * vs, row + (px - 2) * vs, vs);
    }
    std::memcpy(v + (z * py) * px * vs, v + (z * py + 1) * px * vs, px * vs);
    std::memcpy(v + (z * py + py - 1) * px * vs, v + (z * py + py - 2) * px * vs, px * vs);
  }
  std::memcpy(v, v + py * px * vs, py * px * vs);
  std::memcpy(v + (pz - 1) * py * px * vs, v + (pz - 2) * py * px * vs, py * px * vs);
  return d;
}

std::vector<std::byte> DenseVolume::core() const {
  const std::size_t vs = voxel_size(volume.type);
  const glm::uvec3 e(volume.extent);
  std::vector<std::byte> out(std::size_t(e.x) * e.y * e.z * vs);
  for (std::uint32_t z = 0; z < e.z; ++z) {
    for (std::uint32_t y = 0; y < e.y; ++y) {
      std::memcpy(out.data() + (std::size_t(z) * e.y + y) * e.x * vs,
                  voxels.data() + ((std::size_t(z + 1) * padded.y + (y + 1)) * padded.x + 1) * vs,
                  std::size_t(e.x) * vs);
    }
  }
  return out;
}

DenseMarch::DenseMarch(const DenseVolume& volume, const Scene& scene) : volume_(volume) {
  scene.validate(volume.volume, "scene");
  if (scene.channels.size() != 1 || scene.channels[0].channel != volume.channel) {
    throw invalid_parameter("scene", "the dense march shows exactly channel " +
                                         std::to_string(volume.channel) + " of its volume");
  }
  const ChannelSettings& c = scene.channels[0];
  if (c.mode != ChannelMode::dvr || c.finest_level != 0 || !scene.effects.empty() ||
      !scene.slices.empty() || scene.lens || scene.preintegration) {
    throw invalid_parameter("scene",
                            "the dense march renders one dvr channel at level 0 without effects, "
                            "slices, lens or pre-integration");
  }
  for (int a = 0; a < 3; ++a) {
    if (volume.volume.extent[a] > 65536u) {
      throw invalid_parameter("volume", "the dense march takes at most 65536 voxels per axis");
    }
  }
  // The frame constants as build_frame_tables computes them (frame_tables.cpp), with the step
  // at level-0 voxels.
  const VolumeDesc& vd = volume.volume;
  const CameraRays rays(scene.camera, scene.viewport);
  const glm::dvec3 voxel = box_voxel_size(vd);
  const glm::dvec3 per_box = 1.0 / voxel;
  Frame& f = frame_;
  f.width = scene.viewport.width;
  f.height = scene.viewport.height;
  f.perspective = scene.camera.projection == Projection::perspective;
  const double rows = double(scene.viewport.height);
  f.half_height = f.perspective ? float(rays.footprint_slope() * rows / 2.0)
                                : float(rays.footprint_base() * rows / 2.0);
  f.forward = glm::vec3(rays.forward());
  f.right = glm::vec3(rays.right());
  f.up = glm::vec3(rays.up());
  const glm::dvec3 eye_vox = scene.camera.eye * per_box;
  const glm::dvec3 cell = glm::floor(eye_vox);
  f.eye_cell = glm::ivec3(cell);
  for (int i = 0; i < 3; ++i) f.eye_frac[i] = std::min(float(eye_vox[i] - cell[i]), 0.99999994f);
  f.voxels_per_box = glm::vec3(per_box);
  f.finest_voxel = glm::vec3(voxel);
  f.step_scale = float(scene.step_scale);
  const double ref = reference_step_length(vd);
  f.min_step = float(ref * 0x1p-20);
  f.ref_step = float(ref);
  f.ert_opacity = float(scene.ert_opacity);
  f.background = glm::vec4(scene.background);
  const ValueRange r = vd.range(volume.channel);
  f.range_lo = float(r.lo);
  f.inv_range_width = float(1.0 / (r.hi - r.lo));
  f.extent = glm::ivec3(glm::uvec3(vd.extent));
  lut_ = c.tf.lut(kLutSize);
  levels_ = step_levels(glm::dvec3(f.finest_voxel), double(f.step_scale), f.min_step, f.ref_step);
  level_luts_.resize(std::size_t(levels_.count) * kLutSize);
  for (std::uint32_t l = 0; l < levels_.count; ++l) {
    step_lut(lut_, step_level_ratio(levels_, l),
             std::span<glm::vec4>(level_luts_.data() + std::size_t(l) * kLutSize, kLutSize));
  }
}

namespace {

// render_typed for the volume's voxel type.
template <Pass kPass>
DenseStats render_pass(const DenseVolume& volume, const Setup& s, glm::vec4* px, int threads,
                       std::vector<std::vector<VisibleSample>>* kept,
                       const VisibleSamples* replay) {
  const std::byte* data = volume.voxels.data();
  switch (volume.volume.type) {
    case VoxelType::u8:
      return render_typed<std::uint8_t, kPass>(s, data, px, threads, kept, replay);
    case VoxelType::u16:
      return render_typed<std::uint16_t, kPass>(s, data, px, threads, kept, replay);
    case VoxelType::f32: return render_typed<float, kPass>(s, data, px, threads, kept, replay);
  }
  return {};
}

Setup make_setup(const DenseMarch::Frame& f, const std::vector<glm::vec4>& lut,
                 const std::vector<glm::vec4>& level_luts, const StepLevels& levels,
                 const DenseVolume& volume) {
  Setup s{};
  s.f = &f;
  s.lut = lut.data();
  s.level_luts = level_luts.data();
  s.levels = levels;
  s.row = volume.padded.x;
  s.plane = std::size_t(volume.padded.x) * volume.padded.y;
  return s;
}

}  // namespace

DenseStats DenseMarch::render(Image& image, int threads) const {
  const Frame& f = frame_;
  if (image.width() != f.width || image.height() != f.height) image = Image(f.width, f.height);
  const int n = threads > 0 ? threads : omp_get_max_threads();
  return render_pass<Pass::dense>(volume_, make_setup(f, lut_, level_luts_, levels_, volume_),
                                  image.pixels().data(), n, nullptr, nullptr);
}

VisibleSamples DenseMarch::record_visible(int threads) const {
  const Frame& f = frame_;
  const int n = threads > 0 ? threads : omp_get_max_threads();
  Image image(f.width, f.height);
  std::vector<std::vector<VisibleSample>> kept(std::size_t(f.width) * f.height);
  render_pass<Pass::record>(volume_, make_setup(f, lut_, level_luts_, levels_, volume_),
                            image.pixels().data(), n, &kept, nullptr);
  VisibleSamples v;
  v.width = f.width;
  v.height = f.height;
  v.offsets.reserve(kept.size() + 1);
  v.offsets.push_back(0);
  for (const auto& k : kept) v.offsets.push_back(v.offsets.back() + k.size());
  v.samples.reserve(v.offsets.back());
  for (const auto& k : kept) v.samples.insert(v.samples.end(), k.begin(), k.end());
  return v;
}

DenseStats DenseMarch::render_visible(Image& image, const VisibleSamples& visible,
                                      int threads) const {
  const Frame& f = frame_;
  if (visible.width != f.width || visible.height != f.height ||
      visible.offsets.size() != std::size_t(f.width) * f.height + 1 ||
      visible.offsets.back() != visible.samples.size()) {
    throw invalid_parameter("visible", "recorded for a " + std::to_string(visible.width) + "x" +
                                           std::to_string(visible.height) +
                                           " frame, not this march's " + std::to_string(f.width) +
                                           "x" + std::to_string(f.height));
  }
  if (image.width() != f.width || image.height() != f.height) image = Image(f.width, f.height);
  const int n = threads > 0 ? threads : omp_get_max_threads();
  return render_pass<Pass::replay>(volume_, make_setup(f, lut_, level_luts_, levels_, volume_),
                                   image.pixels().data(), n, nullptr, &visible);
}

}  // namespace resoct::bench
