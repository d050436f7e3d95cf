#include "resoct/render/reference_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <thread>
#include <limits>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "resoct/base/error.hpp"

namespace resoct::reference {

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

namespace {

double normalized(const VolumeDesc& v, const VoxelFunction& voxels, std::uint32_t c,
                  const glm::dvec3& pos) {
  const ValueRange r = v.range(c);
  return (sample_trilinear(voxels, c, v.extent, pos) - r.lo) / (r.hi - r.lo);
}

// Clamps a level-0 position into [0, extent) like the kernel's sample positions.
glm::dvec3 clamp_position(const VolumeDesc& v, glm::dvec3 p) {
  for (int a = 0; a < 3; ++a) p[a] = std::clamp(p[a], 0.0, double(v.extent[a]) - 1e-7);
  return p;
}

}  // namespace

glm::dvec3 reference_gradient(const VolumeDesc& volume, const VoxelFunction& voxels,
                              std::uint32_t channel, const glm::dvec3& pos, bool forward) {
  const glm::dvec3 h = box_voxel_size(volume);
  glm::dvec3 g(0.0);
  const double f0 = normalized(volume, voxels, channel, pos);
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 e(0.0);
    e[a] = 1.0;
    const double fp = normalized(volume, voxels, channel, clamp_position(volume, pos + e));
    if (forward) {
      g[a] = (fp - f0) / h[a];
    } else {
      const double fm = normalized(volume, voxels, channel, clamp_position(volume, pos - e));
      g[a] = (fp - fm) / (2.0 * h[a]);
    }
  }
  return g;
}

glm::dvec3 reference_shade(const Scene& scene, const glm::dvec3& rgb, const glm::dvec3& gradient,
                           const glm::dvec3& pos_box, const glm::dvec3& view_dir) {
  const double g2 = glm::dot(gradient, gradient);
  if (!(g2 > 0.0)) return rgb;
  const Light& l = scene.light;
  glm::dvec3 light = -view_dir;
  if (l.kind == Light::Kind::directional) light = -glm::normalize(l.vector);
  if (l.kind == Light::Kind::point && glm::length(l.vector - pos_box) > 0.0) {
    light = glm::normalize(l.vector - pos_box);
  }
  glm::dvec3 n = -gradient / std::sqrt(g2);
  const glm::dvec3 v = -view_dir;
  if (glm::dot(n, v) < 0.0) n = -n;
  const double ndl = std::max(glm::dot(n, light), 0.0);
  const glm::dvec3 hv = light + v;
  double spec = 0.0;
  if (glm::length(hv) > 0.0 && ndl > 0.0) {
    spec = std::pow(std::max(glm::dot(n, glm::normalize(hv)), 0.0), l.shininess);
  }
  return glm::clamp(rgb * (l.ambient + l.diffuse * ndl) + glm::dvec3(l.specular * spec),
                    glm::dvec3(0.0), glm::dvec3(1.0));
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
  const bool shading = scene.has_effect(Effect::shading);
  const bool forward = scene.gradient == GradientStencil::forward;
  const std::size_t n = scene.channels.size();
  std::vector<double> proj(n, 0.0), prev_v(n, 0.0), prev_t(n, 0.0);
  std::vector<bool> have_prev(n, false);
  auto position = [&](double t) { return (ray.origin + ray.dir * t) * to_voxels; };
  const auto segments = std::uint64_t(std::ceil((t_exit - t_enter) / step));
  for (std::uint64_t k = 0; k < segments; ++k) {
    const double t0 = t_enter + double(k) * step;
    const double t1 = std::min(t0 + step, t_exit);
    if (!(t1 > t0)) break;
    const double tm = 0.5 * (t0 + t1);
    const glm::dvec3 pos = position(tm);
    // Intermixing: α = 1 − Π(1 − α'_c), colour weighted by α'_c (docs/rendering.md).
    double transmit = 1.0;
    double weight = 0.0;
    glm::dvec3 weighted(0.0);
    for (std::size_t ci = 0; ci < n; ++ci) {
      const ChannelSettings& c = scene.channels[ci];
      const double x = normalized(volume, voxels, c.channel, pos);
      if (c.mode == ChannelMode::mip) {
        proj[ci] = std::max(proj[ci], std::clamp(x, 0.0, 1.0));
        continue;
      }
      if (c.mode == ChannelMode::aip) {
        proj[ci] += std::clamp(x, 0.0, 1.0) * (t1 - t0);
        continue;
      }
      if (c.mode == ChannelMode::iso) {
        const double pv = prev_v[ci];
        double iso = 0.0;
        bool crossed = false;
        for (double v : c.isovalues) {
          if (have_prev[ci] && (pv < v) != (x < v) &&
              (!crossed || std::abs(v - pv) < std::abs(iso - pv))) {
            iso = v;
            crossed = true;
          }
        }
        if (crossed) {
          double a = prev_t[ci], b = tm;
          const bool below = pv < iso;
          for (int i = 0; i < 60; ++i) {
            const double m = 0.5 * (a + b);
            const bool mb = normalized(volume, voxels, c.channel, position(m)) < iso;
            (mb == below ? a : b) = m;
          }
          const double th = 0.5 * (a + b);
          const glm::dvec4 rgba = c.tf.evaluate(iso);
          const glm::dvec3 hit = clamp_position(volume, position(th));
          const glm::dvec3 lit = reference_shade(
              scene, glm::dvec3(rgba), reference_gradient(volume, voxels, c.channel, hit, forward),
              ray.origin + ray.dir * th, ray.dir);
          const double sa = std::min(rgba.a, 1.0);
          acc += (1.0 - acc.a) * glm::dvec4(lit * sa, sa);
        }
        prev_v[ci] = x;
        prev_t[ci] = tm;
        have_prev[ci] = true;
        continue;
      }
      glm::dvec4 rgba = c.tf.evaluate(x);
      if (options.sample_offset != glm::dvec3(0.0)) {
        rgba = c.tf.evaluate(normalized(volume, voxels, c.channel, pos + options.sample_offset));
      }
      rgba.a = std::min(rgba.a * options.opacity_scale, 1.0);
      const double a = rgba.a >= 1.0 ? 1.0 : -std::expm1((t1 - t0) / delta0 * std::log1p(-rgba.a));
      glm::dvec3 rgb(rgba);
      if (shading && a > 0.0) {
        rgb = reference_shade(
            scene, rgb,
            reference_gradient(volume, voxels, c.channel, clamp_position(volume, pos), forward),
            ray.origin + ray.dir * tm, ray.dir);
      }
      transmit *= 1.0 - a;
      weight += a;
      weighted += a * rgb;
    }
    const double alpha = 1.0 - transmit;
    if (weight > 0.0) {
      const glm::dvec4 sample(weighted * (alpha / weight), alpha);
      acc += (1.0 - acc.a) * sample;
    }
    if (options.early_termination && acc.a >= scene.ert_opacity) break;
  }
  // Projections: through their TF, intermixed like one sample, behind the accumulated colour.
  double transmit = 1.0, weight = 0.0;
  glm::dvec3 weighted(0.0);
  for (std::size_t ci = 0; ci < n; ++ci) {
    const ChannelSettings& c = scene.channels[ci];
    if (c.mode != ChannelMode::mip && c.mode != ChannelMode::aip) continue;
    const double v = c.mode == ChannelMode::aip ? proj[ci] / (t_exit - t_enter) : proj[ci];
    const glm::dvec4 rgba = c.tf.evaluate(v);
    const double a = std::clamp(rgba.a, 0.0, 1.0);
    transmit *= 1.0 - a;
    weight += a;
    weighted += a * glm::dvec3(rgba);
  }
  if (weight > 0.0)
    acc += (1.0 - acc.a) * glm::dvec4(weighted * ((1.0 - transmit) / weight), 1.0 - transmit);
  return acc;
}

Image render_reference(const Scene& scene, const VolumeDesc& volume, const VoxelFunction& voxels,
                       const ReferenceOptions& options) {
  scene.validate(volume);
  const CameraRays rays(scene.camera, scene.viewport);
  Image image(scene.viewport.width, scene.viewport.height);
  const glm::dvec4 bg = scene.background;
  const auto rows = [&](std::uint32_t first, std::uint32_t stride) {
    for (std::uint32_t y = first; y < scene.viewport.height; y += stride) {
      for (std::uint32_t x = 0; x < scene.viewport.width; ++x) {
        const glm::dvec4 acc = reference_ray(scene, volume, voxels, rays.pixel_ray(x, y), options);
        const glm::dvec4 out = acc + (1.0 - acc.a) * glm::dvec4(glm::dvec3(bg) * bg.a, bg.a);
        image.at(x, y) = out.a > 0.0 ? glm::vec4(glm::dvec3(out) / out.a, out.a) : glm::vec4(0.0f);
      }
    }
  };
  const std::uint32_t threads = std::min(
      options.threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : options.threads,
      scene.viewport.height);
  if (threads <= 1) {
    rows(0, 1);
    return image;
  }
  // Rows interleaved over the threads; the first error any of them meets is rethrown.
  std::vector<std::exception_ptr> errors(threads);
  {
    std::vector<std::jthread> pool;
    for (std::uint32_t t = 0; t < threads; ++t) {
      pool.emplace_back([&, t] {
        try {
          rows(t, threads);
        } catch (...) {
          errors[t] = std::current_exception();
        }
      });
    }
  }
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return image;
}

}  // namespace resoct::reference
