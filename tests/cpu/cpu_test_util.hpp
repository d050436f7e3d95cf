#pragma once
// Shared set-up of the CPU traversal tests: procedural sources, scenes, rendering through the
// CPU backend with everything resident, and the dense reference voxels of a source.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/reference_renderer.hpp"
#include "support/resident_scene.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/sources/procedural_source.hpp"

namespace resoct::test {

inline ChannelSettings make_channel(std::uint32_t c, std::vector<TfPoint> tf,
                                    std::uint32_t finest = 0, std::uint32_t coarsest = 15) {
  ChannelSettings s;
  s.channel = c;
  s.tf = TransferFunction(std::move(tf));
  s.finest_level = finest;
  s.coarsest_level = coarsest;
  return s;
}

inline Scene make_scene(std::uint32_t size, Camera cam = {}) {
  Scene s;
  s.camera = cam;
  s.viewport = {size, size};
  s.step_scale = 0.25;
  s.background = {0.0, 0.0, 0.0, 1.0};
  return s;
}

struct Rendered {
  Image image;
  BackendStats stats;
  std::vector<Request> bricks;
  std::vector<Request> nodes;
};

inline Rendered render_cpu(const ResidentScene& rs, const Scene& scene,
                           const FrameOptions& options = {},
                           float skip_min_samples = kDefaultSkipMinSamples) {
  cpu::CpuBackend backend(1);
  rs.upload(backend);
  FrameResult r;
  backend.render(rs.tables(scene, options, skip_min_samples), r);
  return {r.image, r.stats, r.brick_requests, r.node_requests};
}

/// The level-0 voxels of every channel of a source as doubles (reference renderer input).
inline VoxelFunction level0_voxels(const ProceduralSource& src) {
  const VolumeDesc& v = src.hierarchy().volume();
  const Box3 all{glm::i64vec3(0), glm::i64vec3(v.extent)};
  std::vector<std::vector<double>> chans;
  const std::size_t n = std::size_t(v.voxel_count());
  for (std::uint32_t c = 0; c < v.channels; ++c) {
    std::vector<std::byte> bytes(n * voxel_size(v.type));
    src.read_region(0, c, all, bytes);
    std::vector<double> d(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (v.type == VoxelType::u8) {
        d[i] = double(std::uint8_t(bytes[i]));
      } else if (v.type == VoxelType::u16) {
        std::uint16_t x;
        std::memcpy(&x, bytes.data() + 2 * i, 2);
        d[i] = x;
      } else {
        float x;
        std::memcpy(&x, bytes.data() + 4 * i, 4);
        d[i] = x;
      }
    }
    chans.push_back(std::move(d));
  }
  return dense_voxels(v.extent, std::move(chans));
}

/// Largest absolute per-channel difference of two images.
inline double max_diff(const Image& a, const Image& b) {
  const ImageDiff d = compare_images(a, b);
  return std::max({d.max_abs[0], d.max_abs[1], d.max_abs[2], d.max_abs[3]});
}

inline bool has_nan(const Image& img) {
  for (const auto& p : img.pixels()) {
    if (std::isnan(p.r) || std::isnan(p.g) || std::isnan(p.b) || std::isnan(p.a)) return true;
  }
  return false;
}

inline bool all_background(const Image& img, glm::vec4 bg, float tol = 1e-6f) {
  for (const auto& p : img.pixels()) {
    if (glm::any(glm::greaterThan(glm::abs(p - bg), glm::vec4(tol)))) return false;
  }
  return true;
}

}  // namespace resoct::test
