#pragma once
// Shared fixtures of the renderer tests: a small three-channel volume with empty, constant and
// varying bricks, a source wrapper that counts reads and fails chosen keys, and a brute-force
// consistency check of the renderer's host state against the source and the backend's mirror.

#include <gtest/gtest.h>

#include <map>
#include <mutex>
#include <set>

#include "resoct/base/error.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "support/function_source.hpp"
#include "support/recording_backend.hpp"

namespace resoct::test {

/// Registers the recording backend.
inline void register_test_backend() {
  register_recording_backend();
}

/// 32³ u8, bricks 8³ + halo 1 (levels 4³, 2³, 1³ bricks). Level 0: x-brick 0 is all zero,
/// x-brick 3 is constant 100 + channel, the others vary.
inline std::shared_ptr<FunctionSource> make_test_source(std::uint32_t channels = 3) {
  VolumeDesc v;
  v.extent = {32, 32, 32};
  v.type = VoxelType::u8;
  v.channels = channels;
  return std::make_shared<FunctionSource>(
      v, BrickLayout{glm::uvec3(8), 1},
      [](std::uint32_t c, const glm::u64vec3& p) {
        if (p.x <= 8) return 0.0;
        if (p.x >= 23) return 100.0 + c;
        return double((p.x * 7 + p.y * 3 + p.z * 5 + c * 13) % 200 + 1);
      },
      "test-volume");
}

/// Counts reads per key and throws Error(io) "injected failure" for chosen keys.
class CountingSource : public BrickSource {
 public:
  CountingSource(std::shared_ptr<const BrickSource> inner, std::set<BrickKey> failing)
      : inner_(std::move(inner)), failing_(std::move(failing)) {}
  const BrickHierarchy& hierarchy() const override { return inner_->hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    {
      std::lock_guard lock(mutex_);
      ++reads_[key];
    }
    if (failing_.count(key)) throw Error(ErrorCode::io, "injected failure");
    inner_->read_brick(key, out);
  }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_->region_meta(c, b);
  }
  std::string name() const override { return "counting-source"; }
  int reads(BrickKey k) const {
    std::lock_guard lock(mutex_);
    auto it = reads_.find(k);
    return it == reads_.end() ? 0 : it->second;
  }

 private:
  std::shared_ptr<const BrickSource> inner_;
  std::set<BrickKey> failing_;
  mutable std::mutex mutex_;
  mutable std::map<BrickKey, int> reads_;
};

inline RendererOptions test_options(std::uint32_t cache_slots, std::uint64_t budget_bricks) {
  RendererOptions o;
  o.backend = "recording";
  o.loader_threads = 0;
  o.device_cache_bytes = std::uint64_t(cache_slots) * 10 * 10 * 10;  // u8, padded 10³
  o.host_cache_bytes = 1 << 20;
  o.upload_budget.max_bricks = budget_bricks;
  o.leaf_size = glm::uvec3(8);
  o.visible_slots = 1;
  return o;
}

inline Scene test_scene(std::uint32_t channel) {
  Scene s;
  s.viewport = {8, 6};
  ChannelSettings c;
  c.channel = channel;
  s.channels.push_back(c);
  return s;
}

/// All level-0 bricks of a slot.
inline std::vector<PageAddress> level0_bricks(const BrickHierarchy& h, std::uint32_t slot) {
  std::vector<PageAddress> out;
  const glm::uvec3 n = h.level(0).bricks;
  for (std::uint32_t z = 0; z < n.z; ++z)
    for (std::uint32_t y = 0; y < n.y; ++y)
      for (std::uint32_t x = 0; x < n.x; ++x) out.push_back(PageAddress{slot, 0, {x, y, z}});
  return out;
}

/// Creates a renderer whose recording backend asks for every level-0 brick of the first scene
/// channel's slot each frame (requests for UNMAPPED, uses for MAPPED entries).
struct Rig {
  std::unique_ptr<Renderer> renderer;
  RecordingBackend* backend = nullptr;
  std::vector<std::vector<std::uint32_t>> used;  // per frame: cache slots reported as used
  Rig(std::shared_ptr<const BrickSource> src, RendererOptions o) {
    register_test_backend();
    renderer = std::make_unique<Renderer>(std::move(src), std::move(o));
    backend = last_recording_backend();
    Renderer* r = renderer.get();
    backend->set_script([r, this](const FrameTables& t, FrameResult& res, RecordingBackend& b) {
      const auto bricks = level0_bricks(r->hierarchy(), t.slots.at(0).slot);
      b.want(inspect::page_table(*r), bricks, res);
      used.push_back(res.used_cache_slots);
    });
  }
};

/// Brute-force check of the renderer's state against the source: octree invariants, every page
/// entry against its brick's metadata, every resident cache slot against its entry; with a
/// recording backend `b` also its mirrors of the pool, directory, nodes and slot voxels. Returns
/// the first problem or "".
inline std::string check_renderer_state(const Renderer& r, const RecordingBackend* b,
                                        const BrickSource& src) {
  if (auto e = inspect::octree(r).check_invariants()) return "octree: " + *e;
  if (b) {
    const auto& pool = inspect::page_table(r).pool();
    if (b->pages().size() < pool.size() ||
        !std::equal(pool.begin(), pool.end(), b->pages().begin()) ||
        !std::all_of(b->pages().begin() + std::ptrdiff_t(pool.size()), b->pages().end(),
                     [](std::uint32_t w) { return w == 0u; })) {
      return "page pool mirror differs from host";
    }
    if (b->directory() != inspect::page_table(r).directory())
      return "directory mirror differs from host";
    const auto words = inspect::octree(r).words();
    if (!std::equal(words.begin(), words.end(), b->nodes().begin(), b->nodes().end())) {
      return "node mirror differs from host";
    }
  }
  const BrickHierarchy& h = r.hierarchy();
  const std::size_t bytes = h.layout().padded_voxels();
  std::vector<std::byte> voxels(bytes);
  for (std::uint32_t s = 0; s < inspect::channel_map(r).slot_count(); ++s) {
    const auto ch = inspect::channel_map(r).channel(s);
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      const glm::uvec3 n = h.level(l).bricks;
      for (std::uint32_t z = 0; z < n.z; ++z)
        for (std::uint32_t y = 0; y < n.y; ++y)
          for (std::uint32_t x = 0; x < n.x; ++x) {
            const PageAddress a{s, l, {x, y, z}};
            const std::uint32_t e = inspect::page_table(r).entry(a);
            const std::uint32_t state = kernel::resoct_page_state(e);
            if (state == kernel::RESOCT_PAGE_STATE_UNMAPPED) continue;
            if (!ch) return "entry set in an unassigned slot";
            const BrickKey key(l, *ch, {x, y, z});
            const BrickMeta meta = src.brick_meta(key);
            const std::string where = "slot " + std::to_string(s) + " level " + std::to_string(l) +
                                      " brick " + std::to_string(x) + "," + std::to_string(y) +
                                      "," + std::to_string(z) + ": ";
            if (state == kernel::RESOCT_PAGE_STATE_EMPTY) {
              if (!meta.all_zero()) return where + "EMPTY but not all zero";
            } else if (state == kernel::RESOCT_PAGE_STATE_HOMOGENEOUS) {
              if (!meta.constant || meta.all_zero()) return where + "HOMOGENEOUS but not constant";
              if (inspect::page_table(r).homogeneous_value(a) != meta.min)
                return where + "wrong value";
            } else {
              if (meta.constant) return where + "constant brick holds a cache slot";
              const std::uint32_t slot = kernel::resoct_page_cache_slot(e);
              if (inspect::cache(r).key_of(slot) != key)
                return where + "cache slot holds another key";
              if (!b) continue;
              src.read_brick(key, voxels);
              const auto dev = b->slot_voxels(slot);
              if (!std::equal(dev.begin(), dev.end(), voxels.begin(), voxels.end())) {
                return where + "device slot voxels differ from the source";
              }
            }
          }
    }
  }
  // Every resident cache slot is referenced by exactly its page entry.
  for (std::uint32_t cs = 0; cs < inspect::cache(r).slot_count(); ++cs) {
    const auto key = inspect::cache(r).key_of(cs);
    if (!key) continue;
    const auto addr = inspect::channel_map(r).address_of(*key);
    if (!addr) return "resident brick of an invisible channel";
    const std::uint32_t e = inspect::page_table(r).entry(*addr);
    if (!kernel::resoct_page_is_mapped(e) || kernel::resoct_page_cache_slot(e) != cs) {
      return "resident cache slot " + std::to_string(cs) + " not mapped by its page entry";
    }
  }
  return "";
}

/// check_renderer_state with the recording backend's mirrors.
inline std::string check_state(const Renderer& r, const RecordingBackend& b,
                               const BrickSource& src) {
  return check_renderer_state(r, &b, src);
}

}  // namespace resoct::test
