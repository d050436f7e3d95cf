#include "render/frame_tables_slices.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "resoct/scene/camera.hpp"
#include "resoct/base/error.hpp"

namespace resoct::detail {
namespace {

static_assert(kMaxSlices == kernel::RESOCT_MAX_SLICES, "scene and kernel slice limits differ");

// As for the eye: cells stay well inside 32-bit integers.
constexpr double kMaxCell = double(std::uint64_t(1) << 30);

// Splits a box-space position into an exact level-0 cell and a fraction in [0, 1).
void split(const glm::dvec3& box_pos, const glm::dvec3& per_box, const char* name, int* cell,
           float* frac) {
  const glm::dvec3 v = box_pos * per_box;
  for (int a = 0; a < 3; ++a) {
    if (!(std::abs(v[a]) < kMaxCell)) {
      throw invalid_parameter(name, "is too far from the volume (more than 2^30 voxels)");
    }
    const double c = std::floor(v[a]);
    cell[a] = int(c);
    frac[a] = std::min(float(v[a] - c), 0.99999994f);
  }
}

// Index in the slot table (bank 0) of a dataset channel.
std::uint32_t table_index(const FrameTables& out, const ChannelMap& channels, std::uint32_t ch) {
  const auto slot = channels.slot_of(ch);
  for (std::uint32_t k = 0; slot && k < out.slots.size(); ++k) {
    if (out.slots[k].slot == *slot) return k;
  }
  throw invalid_parameter("channels", "channel " + std::to_string(ch) + " is not shown");
}

}  // namespace

void fill_slices_and_lens(const Scene& scene, const BrickHierarchy& hierarchy,
                          const ChannelMap& channels, FrameTables& out) {
  kernel::ResoctFrame& f = out.frame;
  const glm::dvec3 voxel = box_voxel_size(hierarchy.volume());
  const glm::dvec3 per_box = 1.0 / voxel;
  f.slice_count = std::uint32_t(scene.slices.size());
  for (std::uint32_t i = 0; i < f.slice_count; ++i) {
    const SlicePlane& p = scene.slices[i];
    split(p.point, per_box, "scene.slices", &f.slice_cell[3 * i], &f.slice_frac[3 * i]);
    // A plane normal is a covector: it scales inversely to positions.
    const glm::dvec3 n = glm::normalize(p.normal * voxel);
    for (int a = 0; a < 3; ++a) f.slice_normal[3 * i + std::uint32_t(a)] = float(n[a]);
    f.slice_window[i] = p.window ? float(*p.window) : 0.0f;
    f.slice_level[i] = p.level ? float(*p.level) : 0.0f;
    std::uint32_t mask = 0;
    for (std::uint32_t c : p.channels) mask |= 1u << table_index(out, channels, c);
    f.slice_channels[i] = mask;
  }
  if (!scene.lens) return;
  const Lens& lens = *scene.lens;
  f.lens_enabled = 1;
  int cell[3];
  float frac[3];
  split(lens.center, per_box, "scene.lens", cell, frac);
  f.lens_cell_x = cell[0];
  f.lens_cell_y = cell[1];
  f.lens_cell_z = cell[2];
  f.lens_frac_x = frac[0];
  f.lens_frac_y = frac[1];
  f.lens_frac_z = frac[2];
  for (int i = 0; i < 3; ++i) {
    const double half = 0.5 * lens.size[i];
    for (int j = 0; j < 3; ++j) {
      f.lens_matrix[3 * i + j] = float(lens.axes[i][j] / (per_box[j] * half));
    }
  }
  // The outside bank: one entry per bank-0 entry, same slot and visibility unless hidden.
  const std::uint32_t n = std::uint32_t(out.slots.size());
  const std::uint32_t last_level = hierarchy.level_count() - 1u;
  for (std::uint32_t k = 0; k < n; ++k) {
    kernel::ResoctSlotInfo s = out.slots[k];
    const LensOutside* rule = nullptr;
    for (const LensOutside& o : lens.outside) {
      if (channels.slot_of(o.channel) == s.slot) rule = &o;
    }
    if (rule == nullptr || rule->hide) {
      s.vis_bins = 0;
      s.vis_lo16 = 1;
      s.vis_hi16 = 0;
    } else {
      s.finest_level = std::min(rule->finest_level, last_level);
      s.coarsest_level = std::max(s.finest_level, std::min(rule->coarsest_level, last_level));
    }
    out.slots.push_back(s);
  }
}

}  // namespace resoct::detail
