#include "resoct/engine/prefetch.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>

#include <glm/geometric.hpp>

namespace resoct {

void CameraPredictor::observe(const Camera& camera) {
  previous_ = last_;
  last_ = camera;
}

std::vector<Camera> CameraPredictor::predict(std::uint32_t steps) const {
  std::vector<Camera> out;
  if (!last_ || !previous_) return out;
  const glm::dvec3 d_eye = last_->eye - previous_->eye;
  const glm::dvec3 d_target = last_->target - previous_->target;
  if (d_eye == glm::dvec3(0.0) && d_target == glm::dvec3(0.0)) return out;
  for (std::uint32_t k = 1; k <= steps; ++k) {
    Camera c = *last_;
    c.eye += double(k) * d_eye;
    c.target += double(k) * d_target;
    out.push_back(c);
  }
  return out;
}

void CameraPredictor::reset() noexcept {
  last_.reset();
  previous_.reset();
}

namespace {

/// The view frustum in the camera's frame, for box tests and depth ranges.
struct Frustum {
  glm::dvec3 eye, right, up, forward;
  bool perspective;
  double tan_x, tan_y;    // perspective: half extent per unit depth
  double half_x, half_y;  // orthographic: half extent in box units

  Frustum(const CameraRays& rays) {
    const Camera& c = rays.camera();
    eye = c.eye;
    right = rays.right();
    up = rays.up();
    forward = rays.forward();
    perspective = c.projection == Projection::perspective;
    const double w = rays.viewport().width, h = rays.viewport().height;
    tan_y = rays.footprint_slope() * h / 2.0;
    tan_x = tan_y * w / h;
    half_y = rays.footprint_base() * h / 2.0;
    half_x = half_y * w / h;
  }

  /// False when the box is certainly outside; fills its view depth range otherwise.
  bool visible(const glm::dvec3& lo, const glm::dvec3& hi, double& zmin, double& zmax) const {
    std::array<glm::dvec3, 8> v;
    for (int i = 0; i < 8; ++i) {
      const glm::dvec3 p((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
      const glm::dvec3 d = p - eye;
      v[std::size_t(i)] = {glm::dot(d, right), glm::dot(d, up), glm::dot(d, forward)};
    }
    // A box is outside when all corners are beyond one plane: behind the eye, or past a side.
    const auto all = [&](auto outside) { return std::all_of(v.begin(), v.end(), outside); };
    if (all([](const glm::dvec3& q) { return q.z < 0.0; })) return false;
    const double kx = perspective ? tan_x : 0.0, ky = perspective ? tan_y : 0.0;
    const double bx = perspective ? 0.0 : half_x, by = perspective ? 0.0 : half_y;
    if (all([&](const glm::dvec3& q) { return q.x > kx * q.z + bx; })) return false;
    if (all([&](const glm::dvec3& q) { return -q.x > kx * q.z + bx; })) return false;
    if (all([&](const glm::dvec3& q) { return q.y > ky * q.z + by; })) return false;
    if (all([&](const glm::dvec3& q) { return -q.y > ky * q.z + by; })) return false;
    zmin = std::numeric_limits<double>::infinity();
    zmax = 0.0;
    for (const glm::dvec3& q : v) {
      zmin = std::min(zmin, q.z);
      zmax = std::max(zmax, q.z);
    }
    zmin = std::max(zmin, 0.0);
    return true;
  }
};

struct Candidate {
  std::uint32_t level;
  glm::uvec3 brick;
  double distance = 0.0;
  std::uint32_t near_lod = 0, far_lod = 0;  // LOD at the box's nearest and farthest depth
};

}  // namespace

std::vector<BrickKey> view_bricks(const BrickHierarchy& h, const Scene& scene,
                                  std::size_t max_bricks,
                                  const std::function<bool(BrickKey)>& want) {
  std::vector<BrickKey> out;
  if (max_bricks == 0 || scene.channels.empty()) return out;
  const CameraRays rays(scene.camera, scene.viewport);
  const Frustum frustum(rays);
  const std::uint32_t levels = h.level_count();
  const glm::dvec3 voxel0 = box_voxel_size(h.volume());
  std::vector<double> size(levels);
  for (std::uint32_t l = 0; l < levels; ++l) {
    const glm::dvec3 s = level_voxel_size(h, l);
    size[l] = std::max({s.x, s.y, s.z});
  }
  // The LOD rule: the coarsest level whose voxels project to at most lod_error_px pixels.
  // `slack` widens the level range a little so that the kernel's float evaluation of the same
  // rule cannot select a level just outside it.
  const auto lod = [&](double z, double slack) {
    const double budget = scene.lod_error_px * rays.footprint(z) * slack;
    std::uint32_t l = 0;
    while (l + 1 < levels && size[l + 1] <= budget) ++l;
    return l;
  };
  const auto clamp_level = [&](std::uint32_t l, const ChannelSettings& c) {
    const std::uint32_t coarsest = std::min(c.coarsest_level, levels - 1);
    return std::clamp(l, std::min(c.finest_level, coarsest), coarsest);
  };

  std::vector<Candidate> current, next;
  const LevelInfo& top = h.level(levels - 1);
  for (std::uint32_t z = 0; z < top.bricks.z; ++z) {
    for (std::uint32_t y = 0; y < top.bricks.y; ++y) {
      for (std::uint32_t x = 0; x < top.bricks.x; ++x) {
        current.push_back({levels - 1, {x, y, z}});
      }
    }
  }
  for (std::uint32_t l = levels; l-- > 0 && !current.empty();) {
    next.clear();
    std::vector<Candidate> listed;
    for (Candidate& cand : current) {
      const Box3 b0 = h.level0_box(l, cand.brick);
      // Grown by one voxel of this level: trilinear samples near the border read neighbours.
      const glm::dvec3 grow = glm::dvec3(glm::u64vec3(1) << glm::u64vec3(h.level(l).factor_log2));
      const glm::dvec3 lo = (glm::dvec3(b0.lo) - grow) * voxel0;
      const glm::dvec3 hi = (glm::dvec3(b0.hi) + grow) * voxel0;
      double zmin = 0.0, zmax = 0.0;
      if (!frustum.visible(lo, hi, zmin, zmax)) continue;
      cand.near_lod = lod(zmin, 1.0 - 1e-4);
      cand.far_lod = lod(zmax, 1.0 + 1e-4);
      bool listed_here = false, descend = false;
      for (const ChannelSettings& c : scene.channels) {
        const std::uint32_t fine = clamp_level(cand.near_lod, c);
        const std::uint32_t coarse = clamp_level(cand.far_lod, c);
        if (l >= fine && l <= coarse) listed_here = true;
        if (l > fine) descend = true;
      }
      cand.distance = glm::length(0.5 * (lo + hi) - frustum.eye);
      if (listed_here) listed.push_back(cand);
      if (descend && l > 0) {
        const Box3 child = h.level_box_from_level0(l - 1, b0);
        const glm::uvec3 bs = h.layout().brick_size;
        const glm::u64vec3 first = glm::u64vec3(child.lo) / glm::u64vec3(bs);
        const glm::u64vec3 last = (glm::u64vec3(child.hi) - glm::u64vec3(1)) / glm::u64vec3(bs);
        const glm::uvec3 nb = h.level(l - 1).bricks;
        for (std::uint64_t z = first.z; z <= last.z && z < nb.z; ++z) {
          for (std::uint64_t y = first.y; y <= last.y && y < nb.y; ++y) {
            for (std::uint64_t x = first.x; x <= last.x && x < nb.x; ++x) {
              next.push_back({l - 1, glm::uvec3(x, y, z)});
            }
          }
        }
      }
    }
    std::sort(listed.begin(), listed.end(),
              [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
    for (const Candidate& cand : listed) {
      for (const ChannelSettings& c : scene.channels) {
        if (l < clamp_level(cand.near_lod, c) || l > clamp_level(cand.far_lod, c)) continue;
        const BrickKey key(l, c.channel, cand.brick);
        if (want && !want(key)) continue;
        out.push_back(key);
        if (out.size() >= max_bricks) return out;
      }
    }
    // Children are shared by neighbouring parents only through rounding; deduplicate.
    std::sort(next.begin(), next.end(), [](const Candidate& a, const Candidate& b) {
      return std::tie(a.brick.z, a.brick.y, a.brick.x) < std::tie(b.brick.z, b.brick.y, b.brick.x);
    });
    next.erase(
        std::unique(next.begin(), next.end(),
                    [](const Candidate& a, const Candidate& b) { return a.brick == b.brick; }),
        next.end());
    std::swap(current, next);
  }
  return out;
}

}  // namespace resoct
