#include "resoct/render/frame_tables.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "resoct/scene/camera.hpp"
#include "resoct/base/error.hpp"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/scene/preintegration.hpp"
#include "resoct/scene/step_lut.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "resoct/render/traversal_depths.hpp"
#include "render/frame_tables_slices.hpp"

namespace resoct {

namespace {

// Device coordinates are signed 32-bit integers (ivec3); keep a safety margin below 2^31 so that
// cell + node extent never overflows.
constexpr std::uint64_t kMaxDeviceExtent = std::uint64_t(1) << 30;
// The eye may lie outside the volume, but its voxel cell must stay a small multiple of the
// largest extent away so that integer differences fit 32 bits.
constexpr double kMaxEyeCell = double(std::uint64_t(1) << 30);

void fill_camera(const Scene& scene, const BrickHierarchy& h, kernel::ResoctFrame& f) {
  const CameraRays rays(scene.camera, scene.viewport);
  const glm::dvec3 voxel = box_voxel_size(h.volume());
  const glm::dvec3 per_box = 1.0 / voxel;
  const glm::dvec3 eye = scene.camera.eye;
  f.eye_x = float(eye.x);
  f.eye_y = float(eye.y);
  f.eye_z = float(eye.z);
  f.forward_x = float(rays.forward().x);
  f.forward_y = float(rays.forward().y);
  f.forward_z = float(rays.forward().z);
  f.right_x = float(rays.right().x);
  f.right_y = float(rays.right().y);
  f.right_z = float(rays.right().z);
  f.up_x = float(rays.up().x);
  f.up_y = float(rays.up().y);
  f.up_z = float(rays.up().z);
  const double rows = double(scene.viewport.height);
  // CameraRays keeps its half height private; the footprint encodes it exactly.
  f.half_height = scene.camera.projection == Projection::perspective
                      ? float(rays.footprint_slope() * rows / 2.0)
                      : float(rays.footprint_base() * rows / 2.0);
  f.aspect = float(double(scene.viewport.width) / rows);
  f.projection = scene.camera.projection == Projection::perspective
                     ? kernel::RESOCT_PROJECTION_PERSPECTIVE
                     : kernel::RESOCT_PROJECTION_ORTHOGRAPHIC;
  f.footprint_base = float(rays.footprint_base());
  f.footprint_slope = float(rays.footprint_slope());

  // Split in double so that the cell is exact and the fraction carries the remaining bits.
  const glm::dvec3 eye_vox = eye * per_box;
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(eye_vox[i]) < kMaxEyeCell)) {
      throw invalid_parameter("scene.camera.eye",
                              "is too far from the volume (more than 2^30 voxels)");
    }
  }
  const glm::dvec3 cell = glm::floor(eye_vox);
  f.eye_cell_x = int(cell.x);
  f.eye_cell_y = int(cell.y);
  f.eye_cell_z = int(cell.z);
  f.eye_frac_x = std::min(float(eye_vox.x - cell.x), 0.99999994f);
  f.eye_frac_y = std::min(float(eye_vox.y - cell.y), 0.99999994f);
  f.eye_frac_z = std::min(float(eye_vox.z - cell.z), 0.99999994f);
  f.voxels_per_box_x = float(per_box.x);
  f.voxels_per_box_y = float(per_box.y);
  f.voxels_per_box_z = float(per_box.z);
}

// --- Effects (kernel/effects.glsl.h) ------------------------------------------------------------

std::uint32_t effect_mask(const Scene& scene) {
  std::uint32_t m = 0;
  if (scene.has_effect(Effect::shading)) m |= kernel::RESOCT_EFFECT_SHADING;
  if (scene.has_effect(Effect::shadows)) m |= kernel::RESOCT_EFFECT_SHADOWS;
  for (const ChannelSettings& c : scene.channels) {
    if (c.mode == ChannelMode::iso) m |= kernel::RESOCT_EFFECT_ISO;
    if (c.mode == ChannelMode::mip || c.mode == ChannelMode::aip) {
      m |= kernel::RESOCT_EFFECT_PROJECTION;
    }
  }
  if (scene.preintegration) m |= kernel::RESOCT_EFFECT_PREINT;
  return m;
}

void fill_effects(const Scene& scene, const BrickHierarchy& h, kernel::ResoctFxFrame& f) {
  f.effects = effect_mask(scene);
  if (scene.needs_gradients() && h.layout().halo == 0) {
    throw invalid_parameter("scene.effects",
                            "gradients (shading, isosurfaces) need a store halo of at least 1 "
                            "voxel (2 avoids neighbour-brick lookups); this store has 0");
  }
  const Light& l = scene.light;
  f.light_kind = l.kind == Light::Kind::directional ? kernel::RESOCT_LIGHT_DIRECTIONAL
                 : l.kind == Light::Kind::point     ? kernel::RESOCT_LIGHT_POINT
                                                    : kernel::RESOCT_LIGHT_HEADLIGHT;
  const glm::dvec3 v = l.kind == Light::Kind::directional ? glm::normalize(l.vector) : l.vector;
  f.light_x = float(v.x);
  f.light_y = float(v.y);
  f.light_z = float(v.z);
  f.ambient = float(l.ambient);
  f.diffuse = float(l.diffuse);
  f.specular = float(l.specular);
  f.shininess = float(l.shininess);
  f.gradient_forward = scene.gradient == GradientStencil::forward ? 1u : 0u;
  f.shadow_lod_shift = std::uint32_t(std::countr_zero(scene.shadow_lod_factor));
}

// The slot's mode, isovalues and the visible range the node culling tests (projection.glsl.h).
// Whether the kernel's LUT lookup (kernel/tf.glsl.h) can give raw value 0 any opacity: both LUT
// entries it interpolates between are tested, so the answer is conservative.
void fill_slot_zero(const ChannelSettings& c, std::span<const glm::vec4> lut,
                    kernel::ResoctSlotInfo& s) {
  s.zero_value = (0.0f - s.range_lo) * s.inv_range_width;  // resoct_normalize_value(0)
  s.zero_visible = 0u;
  if (c.mode != ChannelMode::dvr || !(s.zero_value == s.zero_value) || lut.size() < 2) return;
  const float x = std::clamp(s.zero_value, 0.0f, 1.0f) * float(lut.size() - 1);
  const std::size_t i0 = std::min(std::size_t(x), lut.size() - 2);
  if (lut[i0].a > 0.0f || lut[i0 + 1].a > 0.0f) s.zero_visible = 1u;
}

// Error-bounded LOD (kernel/error_lod.glsl.h): the least page-entry error code (an error of at
// most 2^-code of the value range) whose value error, times the LUT's steepest premultiplied
// RGBA slope per unit of normalized value, stays within `color` (Scene::lod_error_color). 0 =
// off: asked for none, or no code is fine enough (then the kernel looks nothing up).
std::uint32_t lod_error_code(double color, std::span<const glm::vec4> lut) {
  if (!(color > 0.0) || lut.size() < 2) return 0u;
  double slope = 0.0;
  for (std::size_t i = 1; i < lut.size(); ++i) {
    const glm::vec4 a = lut[i - 1], b = lut[i];
    const glm::vec4 pa(glm::vec3(a) * a.a, a.a), pb(glm::vec3(b) * b.a, b.a);
    const glm::vec4 d = glm::abs(pb - pa);
    slope = std::max({slope, double(d.r), double(d.g), double(d.b), double(d.a)});
  }
  slope *= double(lut.size() - 1);
  // A flat transfer function hides every error: any measured one will do.
  if (!(slope > 0.0)) return 1u;
  const double code = std::ceil(std::log2(slope / color));
  if (code > double(kernel::RESOCT_PAGE_ERROR_MAX)) return 0u;
  return std::uint32_t(std::max(1.0, code));
}

void fill_slot_effects(const ChannelSettings& c, kernel::ResoctSlotInfo& s) {
  s.mode = c.mode == ChannelMode::iso   ? kernel::RESOCT_CHANNEL_ISO
           : c.mode == ChannelMode::mip ? kernel::RESOCT_CHANNEL_MIP
           : c.mode == ChannelMode::aip ? kernel::RESOCT_CHANNEL_AIP
                                        : kernel::RESOCT_CHANNEL_DVR;
  s.iso_count = std::uint32_t(std::min(c.isovalues.size(), kMaxIsovalues));
  float iso[kMaxIsovalues] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (std::uint32_t k = 0; k < s.iso_count; ++k) iso[k] = float(c.isovalues[k]);
  s.iso0 = iso[0];
  s.iso1 = iso[1];
  s.iso2 = iso[2];
  s.iso3 = iso[3];
  const ValueRange unit{0.0, 1.0};
  if (c.mode == ChannelMode::iso) {
    // A node may hold a crossing exactly when its [min, max] reaches an isovalue; occupancy
    // bins cannot tell (a crossing between two voxel values lies in a bin no voxel occupies).
    double lo = 1.0, hi = 0.0;
    bool visible = false;
    for (double x : c.isovalues) {
      if (c.tf.evaluate(x).a > 0.0) {
        visible = true;
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    }
    s.vis_bins = visible ? 0xFFFFFFFFu : 0u;
    s.vis_lo16 = visible ? octree_quantize_min(lo, unit) : 1u;
    s.vis_hi16 = visible ? octree_quantize_max(hi, unit) : 0u;
  } else if (c.mode != ChannelMode::dvr) {
    // Projections: every value may become the result; their nodes are classified by value.
    const bool visible = !c.tf.fully_transparent();
    s.vis_bins = visible ? 0xFFFFFFFFu : 0u;
    s.vis_lo16 = visible ? 0u : 1u;
    s.vis_hi16 = visible ? kernel::RESOCT_QUANT_MAX : 0u;
  }
}

// ------------------------------------------------------------------------------------------------

std::uint32_t check_extent(std::uint64_t v, const char* name) {
  if (v == 0 || v >= kMaxDeviceExtent) {
    throw invalid_parameter(name, "axis of " + std::to_string(v) +
                                      " voxels does not fit the kernel's 32-bit coordinates");
  }
  return std::uint32_t(v);
}

// Finest level the per-sample LOD choice (kernel/step.glsl.h) can select anywhere in the volume
// this frame. The pixel footprint grows with view depth and view depth is linear, so the volume
// corner nearest in depth bounds it. A 1e-3 relative margin keeps the kernel's float rounding
// from choosing one level finer at that corner.
std::uint32_t lod_floor_level(const Scene& scene, const BrickHierarchy& h) {
  const CameraRays rays(scene.camera, scene.viewport);
  const glm::dvec3 ext = box_extent(h.volume());
  double nearest = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 corner((c & 1) ? ext.x : 0.0, (c & 2) ? ext.y : 0.0, (c & 4) ? ext.z : 0.0);
    nearest = std::min(nearest, glm::dot(corner - scene.camera.eye, rays.forward()));
  }
  const double allowed = rays.footprint(nearest) * scene.lod_error_px * (1.0 - 1e-3);
  if (!(allowed > 0.0) || !std::isfinite(allowed)) return 0;
  const double budget = std::log2(allowed);
  const std::vector<float> sizes = level_size_log2_table(h);
  std::uint32_t level = 0;
  for (std::uint32_t l = 1; l < sizes.size(); ++l) {
    if (double(sizes[l]) > budget) break;
    level = l;
  }
  return level;
}

// A process-wide version for FrameTables::step_luts: each change gets a number no tables had.
std::uint64_t next_step_luts_version() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

// The step levels of the frame (out.frame's step fields) and their corrected LUTs for the shown
// slots (out.slots, whose tf_luts entries are current); a slot's LUTs are kept while its transfer
// function and the levels are unchanged, so a camera move recomputes none.
void build_step_luts(glm::dvec3 finest_voxel, float step_scale, std::uint32_t slot_count,
                     FrameTables& out) {
  kernel::ResoctFrame& f = out.frame;
  const StepLevels levels = step_levels(finest_voxel, double(step_scale), f.min_step, f.ref_step);
  f.step_level_shift = levels.shift;
  f.step_level_first = levels.first;
  f.step_level_count = levels.count;
  const std::size_t per_slot = std::size_t(levels.count) * kTfLutSize;
  const bool same_levels = out.step_luts.size() == per_slot * slot_count &&
                           out.step_luts_built.size() == slot_count && out.step_levels == levels;
  bool changed = false;
  if (!same_levels) {
    out.step_luts.assign(per_slot * slot_count, glm::vec4(0.0f));
    out.step_luts_built.assign(slot_count, 0u);
    out.step_levels = levels;
    changed = true;
  }
  for (std::uint32_t slot = 0; slot < slot_count; ++slot) {
    const auto shown = [slot](const kernel::ResoctSlotInfo& s) { return s.slot == slot; };
    const bool is_shown = std::any_of(out.slots.begin(), out.slots.end(), shown);
    const auto first = out.step_luts.begin() + std::ptrdiff_t(slot * per_slot);
    if (!is_shown) {
      if (out.step_luts_built[slot] != 0u) {
        std::fill(first, first + std::ptrdiff_t(per_slot), glm::vec4(0.0f));
        out.step_luts_built[slot] = 0u;
        changed = true;
      }
      continue;
    }
    if (out.step_luts_built[slot] != 0u) continue;
    const std::span<const glm::vec4> lut(out.tf_luts.data() + std::size_t(slot) * kTfLutSize,
                                         kTfLutSize);
    for (std::uint32_t l = 0; l < levels.count; ++l) {
      step_lut(lut, step_level_ratio(levels, l),
               std::span<glm::vec4>(&*first + std::size_t(l) * kTfLutSize, kTfLutSize));
    }
    out.step_luts_built[slot] = 1u;
    changed = true;
  }
  if (changed || out.step_luts_version == 0) out.step_luts_version = next_step_luts_version();
}

}  // namespace

void build_frame_tables(const Scene& scene, const BrickHierarchy& hierarchy,
                        const OctreeLayout& layout, const ChannelMap& channels,
                        const FrameOptions& options, FrameTables& out) {
  const VolumeDesc& volume = hierarchy.volume();
  scene.validate(volume, "scene");
  if (layout.extent0() != volume.extent) {
    throw invalid_parameter("layout", "octree extent differs from the volume extent");
  }
  if (options.max_iterations == 0) throw invalid_parameter("max_iterations", "must be >= 1");
  options.jitter.validate();
  if (scene.channels.size() > kernel::RESOCT_MAX_SLOTS) {
    throw invalid_parameter(
        "scene.channels",
        "more than " + std::to_string(kernel::RESOCT_MAX_SLOTS) + " visible channels");
  }
  const std::uint32_t level_count = hierarchy.level_count();
  const BrickLayout& bl = hierarchy.layout();

  kernel::ResoctFrame& f = out.frame;
  f = kernel::ResoctFrame{};
  f.width = scene.viewport.width;
  f.height = scene.viewport.height;
  f.mode = std::uint32_t(options.mode);
  f.slot_count = std::uint32_t(scene.channels.size());
  f.level_count = level_count;
  f.depth_count = layout.depth_count();
  f.start_depth = std::min(options.start_depth, layout.depth_count() - 1u);
  f.max_iterations = options.max_iterations;
  f.frame_index = options.frame_index;
  f.page_slot_count = channels.slot_count();
  f.node_slot_count = channels.slot_count();
  f.request_greedy = options.request_strategy == RequestStrategy::greedy ? 1u : 0u;
  fill_camera(scene, hierarchy, f);
  f.jitter_x = options.jitter.pixel_x;
  f.jitter_y = options.jitter.pixel_y;
  f.jitter_sample = options.jitter.sample;
  out.fx = kernel::ResoctFxFrame{};
  fill_effects(scene, hierarchy, out.fx);

  f.extent_x = check_extent(volume.extent.x, "extent");
  f.extent_y = check_extent(volume.extent.y, "extent");
  f.extent_z = check_extent(volume.extent.z, "extent");
  f.brick_x = bl.brick_size.x;
  f.brick_y = bl.brick_size.y;
  f.brick_z = bl.brick_size.z;
  f.halo = bl.halo;
  f.padded_x = bl.padded_size().x;
  f.padded_y = bl.padded_size().y;
  f.padded_z = bl.padded_size().z;

  // Slot table in importance order. A stable sort keeps the scene order among full ties.
  std::vector<std::uint32_t> order(scene.channels.size());
  std::iota(order.begin(), order.end(), 0u);
  const std::uint32_t last_level = level_count - 1u;
  auto finest_of = [&](std::uint32_t i) {
    return std::min(scene.channels[i].finest_level, last_level);
  };
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const auto& ca = scene.channels[a];
    const auto& cb = scene.channels[b];
    if (ca.importance != cb.importance) return ca.importance < cb.importance;
    return finest_of(a) < finest_of(b);
  });

  out.slots.clear();
  // LUTs and pre-integration tables are kept from the previous build into `out` where their
  // transfer function is unchanged: the tables then equal a fresh build's, without the work.
  const std::uint32_t slot_count = channels.slot_count();
  const std::size_t lut_entries = std::size_t(slot_count) * kTfLutSize;
  if (out.tf_luts.size() != lut_entries || out.lut_sources.size() != slot_count ||
      out.preint_built.size() != slot_count) {
    out.tf_luts.assign(lut_entries, glm::vec4(0.0f));
    out.lut_sources.assign(slot_count, std::nullopt);
    out.preint_built.assign(slot_count, 0u);
  }
  if (!scene.preintegration) {
    out.preint_tables.clear();
    std::fill(out.preint_built.begin(), out.preint_built.end(), std::uint8_t(0));
  } else if (out.preint_tables.size() != 2u * lut_entries) {
    out.preint_tables.assign(2u * lut_entries, glm::vec4(0.0f));
    std::fill(out.preint_built.begin(), out.preint_built.end(), std::uint8_t(0));
  }
  out.luts_built = 0;
  // The step (Eq. 8.2-8.3) follows the finest level any sample of a channel can use: its finest
  // allowed level, or the level the LOD picks at the volume's nearest point when that is
  // coarser. Without the LOD floor a distant view of a huge volume would march level-0 steps
  // through coarse data, so samples per ray would grow with the data instead of the screen.
  const std::uint32_t lod_floor = lod_floor_level(scene, hierarchy);
  glm::dvec3 finest_voxel(std::numeric_limits<double>::infinity());
  for (std::uint32_t i : order) {
    const ChannelSettings& c = scene.channels[i];
    const auto slot = channels.slot_of(c.channel);
    if (!slot) {
      throw invalid_parameter("channels", "channel " + std::to_string(c.channel) +
                                              " of the scene is not shown in any slot");
    }
    kernel::ResoctSlotInfo s{};
    s.slot = *slot;
    s.finest_level = finest_of(i);
    s.coarsest_level = std::max(s.finest_level, std::min(c.coarsest_level, last_level));
    s.vis_bins = c.tf.visible_mask();
    const ValueRange unit{0.0, 1.0};
    if (c.tf.fully_transparent()) {
      s.vis_lo16 = 1u;
      s.vis_hi16 = 0u;
    } else {
      s.vis_lo16 = octree_quantize_min(c.tf.visible_intervals().front().x, unit);
      s.vis_hi16 = octree_quantize_max(c.tf.visible_intervals().back().y, unit);
    }
    const ValueRange r = volume.range(c.channel);
    s.range_lo = float(r.lo);
    s.inv_range_width = float(1.0 / (r.hi - r.lo));
    fill_slot_effects(c, s);
    const std::span<glm::vec4> lut(out.tf_luts.data() + std::size_t(*slot) * kTfLutSize,
                                   kTfLutSize);
    std::optional<TransferFunction>& built_from = out.lut_sources[*slot];
    if (!built_from || !(*built_from == c.tf)) {
      const std::vector<glm::vec4> fresh = c.tf.lut(kTfLutSize);
      std::copy(fresh.begin(), fresh.end(), lut.begin());
      built_from = c.tf;
      out.preint_built[*slot] = 0u;
      if (*slot < out.step_luts_built.size()) out.step_luts_built[*slot] = 0u;
      ++out.luts_built;
    }
    fill_slot_zero(c, lut, s);
    s.lod_error_code = lod_error_code(scene.lod_error_color, lut);
    out.slots.push_back(s);

    if (scene.preintegration && out.preint_built[*slot] == 0u) {
      const std::vector<glm::vec4> pre = preintegration_table(lut);
      std::copy(pre.begin(), pre.end(),
                out.preint_tables.begin() + std::ptrdiff_t(*slot) * 2 * kTfLutSize);
      out.preint_built[*slot] = 1u;
    }
    const std::uint32_t step_level =
        std::min(std::max(lod_floor, s.finest_level), s.coarsest_level);
    finest_voxel = glm::min(finest_voxel, level_voxel_size(hierarchy, step_level));
  }
  if (scene.channels.empty()) finest_voxel = box_voxel_size(volume);
  // Slots this scene does not show (none of out.slots) read as zero, as in a fresh build.
  for (std::uint32_t slot = 0; slot < slot_count; ++slot) {
    if (!out.lut_sources[slot]) continue;
    const auto shown = [slot](const kernel::ResoctSlotInfo& s) { return s.slot == slot; };
    if (std::any_of(out.slots.begin(), out.slots.end(), shown)) continue;
    const auto first = out.tf_luts.begin() + std::ptrdiff_t(slot) * kTfLutSize;
    std::fill(first, first + kTfLutSize, glm::vec4(0.0f));
    if (!out.preint_tables.empty()) {
      const auto pre = out.preint_tables.begin() + std::ptrdiff_t(slot) * 2 * kTfLutSize;
      std::fill(pre, pre + 2 * kTfLutSize, glm::vec4(0.0f));
    }
    out.lut_sources[slot].reset();
    out.preint_built[slot] = 0u;
  }

  const double ref = reference_step_length(volume);
  f.finest_voxel_x = float(finest_voxel.x);
  f.finest_voxel_y = float(finest_voxel.y);
  f.finest_voxel_z = float(finest_voxel.z);
  f.step_scale = float(scene.step_scale);
  // Far below any step a scene can ask for (1e-3 voxels in the tests), but positive.
  f.min_step = float(ref * 0x1p-20);
  f.ref_step = float(ref);
  build_step_luts(glm::dvec3(f.finest_voxel_x, f.finest_voxel_y, f.finest_voxel_z), f.step_scale,
                  slot_count, out);
  f.lod_error_px = float(scene.lod_error_px);
  f.ert_opacity = float(scene.ert_opacity);
  f.background_r = float(scene.background.r);
  f.background_g = float(scene.background.g);
  f.background_b = float(scene.background.b);
  f.background_a = float(scene.background.a);
  detail::fill_slices_and_lens(scene, hierarchy, channels, out);

  const std::vector<float> sizes = level_size_log2_table(hierarchy);
  out.levels.clear();
  for (std::uint32_t l = 0; l < level_count; ++l) {
    const LevelInfo& li = hierarchy.level(l);
    kernel::ResoctLevelInfo L{};
    L.bricks_x = li.bricks.x;
    L.bricks_y = li.bricks.y;
    L.bricks_z = li.bricks.z;
    L.factor_log2_x = li.factor_log2.x;
    L.factor_log2_y = li.factor_log2.y;
    L.factor_log2_z = li.factor_log2.z;
    L.extent_x = std::uint32_t(li.extent.x);
    L.extent_y = std::uint32_t(li.extent.y);
    L.extent_z = std::uint32_t(li.extent.z);
    L.size_log2 = sizes[l];
    // The standard-octree mode's culling node: the depth whose nodes span exactly this level's
    // bricks, if the layout has one (node and brick grids both start at the volume's corner).
    L.node_depth = 0xFFFFFFFFu;  // RESOCT_NONE_U
    const glm::u64vec3 brick0 = glm::u64vec3(hierarchy.layout().brick_size)
                                << glm::u64vec3(li.factor_log2);
    for (std::uint32_t d = 0; d < layout.depth_count(); ++d) {
      if (layout.depth(d).node_extent == brick0) L.node_depth = d;
    }
    out.levels.push_back(L);
  }

  out.depths.clear();
  // Local index bits per axis: a child's local index is the parent's shifted by child_shift, with
  // the child bits x, then y, then z (x least significant) of the split axes below.
  glm::uvec3 axis_bits(0u);
  for (std::uint32_t d = 0; d < layout.depth_count(); ++d) {
    const OctreeDepth& od = layout.depth(d);
    kernel::ResoctDepthInfo D{};
    D.count_x = od.count.x;
    D.count_y = od.count.y;
    D.count_z = od.count.z;
    D.split_x = od.split.x;
    D.split_y = od.split.y;
    D.split_z = od.split.z;
    D.child_shift = od.child_shift;
    if (od.first_node >= OctreeLayout::kMaxNodes) {
      throw invalid_parameter("layout", "node index does not fit 32 bits");
    }
    D.first_node = std::uint32_t(od.first_node);
    D.node_extent_x = check_extent(od.node_extent.x, "layout");
    D.node_extent_y = check_extent(od.node_extent.y, "layout");
    D.node_extent_z = check_extent(od.node_extent.z, "layout");
    D.count_log2_x = od.count_log2.x;
    D.count_log2_y = od.count_log2.y;
    D.count_log2_z = od.count_log2.z;
    if (d > 0) {
      std::uint32_t bit = 0;
      for (int a = 0; a < 3; ++a) {
        axis_bits[a] <<= od.child_shift;
        if (od.split[a] != 0u) axis_bits[a] |= 1u << bit++;
      }
    }
    D.axis_bits_x = axis_bits.x;
    D.axis_bits_y = axis_bits.y;
    D.axis_bits_z = axis_bits.z;
    D.shortest_side = node_shortest_side(D, f);
    out.depths.push_back(D);
  }
  // Per level, how deep its samples can be classified (both tables are complete here).
  for (kernel::ResoctLevelInfo& L : out.levels) {
    L.depth_cap = level_depth_cap(out.depths, f.start_depth, L);
  }
}

FrameTables build_frame_tables(const Scene& scene, const BrickHierarchy& hierarchy,
                               const OctreeLayout& layout, const ChannelMap& channels,
                               const FrameOptions& options) {
  FrameTables t;
  build_frame_tables(scene, hierarchy, layout, channels, options, t);
  return t;
}

}  // namespace resoct
