#pragma once
// Shared set-up of the Vulkan tests: a validated backend (or a skip when the machine has no
// Vulkan device) and the CPU-oracle comparison of one frame.
#include <algorithm>
#include <iterator>
#include <map>
#include <utility>
#include <vector>
#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/vulkan/devices.hpp"
#include "resoct/vulkan/vulkan_backend.hpp"
#include "support/resident_scene.hpp"

namespace resoct::test {

/// A Vulkan backend with validation on, or nullptr when no device exists.
inline std::unique_ptr<vk::VulkanBackend> make_validated_vulkan() {
  if (vk::list_devices().empty()) return nullptr;
  BackendOptions o;
  o.validation = true;
  return std::make_unique<vk::VulkanBackend>(o);
}

/// Every recorded validation message fails the test.
inline void expect_no_validation_messages(const vk::VulkanBackend& b) {
  EXPECT_EQ(b.validation_messages(), 0u);
  for (const std::string& m : b.validation_log()) ADD_FAILURE() << "validation: " << m;
}

inline FrameResult render_on(Backend& backend, const ResidentScene& rs, const Scene& scene,
                             const FrameOptions& options) {
  rs.upload(backend);
  FrameResult r;
  backend.render(rs.tables(scene, options), r);
  return r;
}

/// Largest differences seen between the two backends (printed by the tests, quoted in reports).
struct OracleDiff {
  double colour = 0.0;           ///< per channel, [0, 1]
  std::uint64_t stat_abs = 0;    ///< integer statistics
  std::size_t request_keys = 0;  ///< keys in one set but not the other
  std::uint64_t request_hits = 0;
  std::size_t used_slots = 0;
};

// Keys present in exactly one of the lists, and the summed hit difference of the common keys.
inline std::pair<std::size_t, std::uint64_t> request_difference(const std::vector<Request>& a,
                                                                const std::vector<Request>& b) {
  std::map<std::uint32_t, std::uint32_t> ma, mb;
  for (const Request& r : a) ma[r.key] = r.hits;
  for (const Request& r : b) mb[r.key] = r.hits;
  std::size_t keys = 0;
  std::uint64_t hits = 0;
  for (const auto& [k, h] : ma) {
    auto it = mb.find(k);
    if (it == mb.end()) {
      ++keys;
      hits += h;
    } else {
      hits += std::uint64_t(std::abs(std::int64_t(h) - std::int64_t(it->second)));
    }
  }
  for (const auto& [k, h] : mb) {
    if (!ma.count(k)) {
      ++keys;
      hits += h;
    }
  }
  return {keys, hits};
}

/// Largest colour difference allowed between a Vulkan frame and the CPU frame (see below).
inline constexpr double kVulkanColourTolerance = 1e-4;

/// Compares a Vulkan frame with the CPU frame of the same state and tables.
///
/// Integer outputs must be identical (docs/architecture.md §3.4): statistics, request keys and
/// hit counts, and the used cache slots (the working set). Colours may differ by float rounding:
/// measured on lavapipe at most 1.4e-5 (oracle scenes), 4.5e-6 (effects), 2.7e-6 (slices),
/// asserted within kVulkanColourTolerance = 1e-4 (a real GPU's exp2/log2 and fused multiply-adds
/// round a little differently; 2/255 would hide a wrong sample). The march ends a sliver before
/// the exit (RESOCT_SEGMENT_EPS), so the last ulp of the device's division cannot add a sample.
/// `diff` accumulates the largest differences for the report line.
inline void expect_same_frame(const FrameResult& cpu, const FrameResult& gpu,
                              const std::string& what, OracleDiff& diff) {
  auto near = [&](std::uint64_t a, std::uint64_t b, const char* name) {
    const std::uint64_t d = a > b ? a - b : b - a;
    diff.stat_abs = std::max(diff.stat_abs, d);
    EXPECT_EQ(d, 0u) << what << " " << name << " cpu " << a << " vulkan " << b;
  };
  EXPECT_EQ(cpu.stats.rays, gpu.stats.rays) << what;
  near(cpu.stats.samples, gpu.stats.samples, "samples");
  near(cpu.stats.nodes_visited, gpu.stats.nodes_visited, "nodes_visited");
  near(cpu.stats.brick_accesses, gpu.stats.brick_accesses, "brick_accesses");
  near(cpu.stats.iterations, gpu.stats.iterations, "iterations");
  EXPECT_EQ(cpu.stats.cap_hits, gpu.stats.cap_hits) << what;
  near(cpu.stats.request_inserts, gpu.stats.request_inserts, "request_inserts");
  EXPECT_EQ(cpu.stats.requests_dropped, gpu.stats.requests_dropped) << what;
  using Requests = std::vector<Request> FrameResult::*;
  for (Requests sets : {&FrameResult::brick_requests, &FrameResult::node_requests}) {
    const auto& a = cpu.*sets;
    const auto& b = gpu.*sets;
    const auto [keys, hits] = request_difference(a, b);
    diff.request_keys = std::max(diff.request_keys, keys);
    diff.request_hits = std::max(diff.request_hits, hits);
    EXPECT_EQ(keys, 0u) << what << " request keys";
    EXPECT_EQ(hits, 0u) << what << " request hits";
    if (a.empty()) {
      EXPECT_TRUE(b.empty()) << what;
    }
  }
  std::vector<std::uint32_t> only;
  std::set_symmetric_difference(cpu.used_cache_slots.begin(), cpu.used_cache_slots.end(),
                                gpu.used_cache_slots.begin(), gpu.used_cache_slots.end(),
                                std::back_inserter(only));
  diff.used_slots = std::max(diff.used_slots, only.size());
  EXPECT_EQ(only.size(), 0u) << what << " used cache slots";
  // Distances are summed as per-ray fixed point (2^-20 box units) on the device.
  const double rays = double(cpu.stats.rays);
  EXPECT_NEAR(cpu.stats.distance_marched, gpu.stats.distance_marched,
              2e-3 * cpu.stats.distance_marched + rays * 1e-6)
      << what;
  EXPECT_NEAR(cpu.stats.distance_skipped, gpu.stats.distance_skipped,
              2e-3 * cpu.stats.distance_skipped + rays * 1e-6)
      << what;
  EXPECT_EQ(cpu.image.width(), gpu.image.width()) << what;
  EXPECT_EQ(cpu.image.height(), gpu.image.height()) << what;
  double worst = 0.0;
  const auto& a = cpu.image.pixels();
  const auto& b = gpu.image.pixels();
  if (a.size() != b.size()) return;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int c = 0; c < 4; ++c) {
      const double d = std::abs(double(a[i][c]) - double(b[i][c]));
      worst = std::isnan(d) ? 1.0 : std::max(worst, d);
    }
  }
  EXPECT_LE(worst, kVulkanColourTolerance) << what;
  diff.colour = std::max(diff.colour, worst);
}

}  // namespace resoct::test
