#include "support/reference_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>

#include "resoct/error.hpp"

namespace resoct::test {

VoxelFunction dense_voxels(const glm::u64vec3& extent, std::vector<std::vector<double>> channels) {
  const std::uint64_t count = extent.x * extent.y * extent.z;
  for (std::size_t c = 0; c < channels.size(); ++c) {
    if (channels[c].size() != count) {
      throw Error(ErrorCode::size_mismatch, "dense_voxels: channel " + std::to_string(c) + " has " +
                                                std::to_string(channels[c].size()) +
                                                " values, expected " + std::to_string(count));
    }
  }
  return [extent, data = std::move(channels)](std::uint32_t channel, const glm::i64vec3& v) {
    const std::uint64_t i =
        (std::uint64_t(v.z) * extent.y + std::uint64_t(v.y)) * extent.x + std::uint64_t(v.x);
    return data.at(channel).at(i);
  };
}

double sample_trilinear(const VoxelFunction& voxels, std::uint32_t channel,
                        const glm::u64vec3& extent, const glm::dvec3& pos) {
  glm::i64vec3 i0;
  glm::dvec3 f;
  for (int a = 0; a < 3; ++a) {
    const double last = double(extent[a]) - 1.0;
    const double x = std::clamp(pos[a] - 0.5, 0.0, last);
    const double fl = std::min(std::floor(x), std::max(last - 1.0, 0.0));
    i0[a] = std::int64_t(fl);
    f[a] = x - fl;
  }
  const glm::i64vec3 hi = glm::i64vec3(extent) - glm::i64vec3(1);
  double result = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    glm::i64vec3 v;
    double w = 1.0;
    for (int a = 0; a < 3; ++a) {
      const bool up = (corner >> a) & 1;
      v[a] = std::min(i0[a] + (up ? 1 : 0), hi[a]);
      w *= up ? f[a] : 1.0 - f[a];
    }
    if (w != 0.0) result += w * voxels(channel, v);
  }
  return result;
}

double reference_step(const VolumeDesc& volume) {
  const glm::dvec3 h = box_voxel_size(volume);
  return std::min(h.x, std::min(h.y, h.z));
}

glm::dvec2 reference_ray_box(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi) {
  const double inf = std::numeric_limits<double>::infinity();
  double enter = -inf;
  double exit = inf;
  for (int a = 0; a < 3; ++a) {
    if (ray.dir[a] == 0.0) {
      if (!(ray.origin[a] >= lo[a] && ray.origin[a] < hi[a])) return {inf, -inf};
      continue;
    }
    const double t0 = (lo[a] - ray.origin[a]) / ray.dir[a];
    const double t1 = (hi[a] - ray.origin[a]) / ray.dir[a];
    enter = std::max(enter, std::min(t0, t1));
    exit = std::min(exit, std::max(t0, t1));
  }
  return {enter, exit};
}

glm::dvec4 reference_ray(const Scene& scene, const VolumeDesc& volume, const VoxelFunction& voxels,
                         const Ray& ray, const ReferenceOptions& options) {
  if (!(options.step > 0.0)) throw invalid_parameter("step", "must be positive");
  const glm::dvec3 box = box_extent(volume);
  const glm::dvec2 span = reference_ray_box(ray, glm::dvec3(0.0), box);
  const double t_enter = std::max(span.x, 0.0);
  const double t_exit = span.y;
  glm::dvec4 acc(0.0);
  if (!(t_enter < t_exit)) return acc;

  const double delta0 = reference_step(volume);
  const double step = options.step * delta0;
  const glm::dvec3 to_voxels = glm::dvec3(volume.extent) / box;
  const auto segments = std::uint64_t(std::ceil((t_exit - t_enter) / step));
  for (std::uint64_t k = 0; k < segments; ++k) {
    const double t0 = t_enter + double(k) * step;
    const double t1 = std::min(t0 + step, t_exit);
    if (!(t1 > t0)) break;
    const glm::dvec3 pos = (ray.origin + ray.dir * (0.5 * (t0 + t1))) * to_voxels;
    // Intermixing: α = 1 − Π(1 − α'_c), colour weighted by α'_c (docs/rendering.md).
    double transmit = 1.0;
    double weight = 0.0;
    glm::dvec3 weighted(0.0);
    for (const ChannelSettings& c : scene.channels) {
      const ValueRange range = volume.range(c.channel);
      const double raw = sample_trilinear(voxels, c.channel, volume.extent, pos);
      const glm::dvec4 rgba = c.tf.evaluate((raw - range.lo) / (range.hi - range.lo));
      const double a = rgba.a >= 1.0 ? 1.0 : -std::expm1((t1 - t0) / delta0 * std::log1p(-rgba.a));
      transmit *= 1.0 - a;
      weight += a;
      weighted += a * glm::dvec3(rgba);
    }
    const double alpha = 1.0 - transmit;
    if (weight > 0.0) {
      const glm::dvec4 sample(weighted * (alpha / weight), alpha);
      acc += (1.0 - acc.a) * sample;
    }
    if (options.early_termination && acc.a >= scene.ert_opacity) break;
  }
  return acc;
}

Image render_reference(const Scene& scene, const VolumeDesc& volume, const VoxelFunction& voxels,
                       const ReferenceOptions& options) {
  scene.validate(volume);
  const CameraRays rays(scene.camera, scene.viewport);
  Image image(scene.viewport.width, scene.viewport.height);
  const glm::dvec4 bg = scene.background;
  for (std::uint32_t y = 0; y < scene.viewport.height; ++y) {
    for (std::uint32_t x = 0; x < scene.viewport.width; ++x) {
      const glm::dvec4 acc = reference_ray(scene, volume, voxels, rays.pixel_ray(x, y), options);
      const glm::dvec4 out = acc + (1.0 - acc.a) * glm::dvec4(glm::dvec3(bg) * bg.a, bg.a);
      image.at(x, y) = out.a > 0.0 ? glm::vec4(glm::dvec3(out) / out.a, out.a) : glm::vec4(0.0f);
    }
  }
  return image;
}

}  // namespace resoct::test
