// Brick cache: capacity, pinning (current frame and ttl), LRU and Octreemizer victims against a
// brute-force model over random operation sequences, and the upload budget.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "resoct/engine/brick_cache.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

const BrickLayout kLayout{glm::uvec3(8), 1};  // 10^3 padded voxels
constexpr std::uint32_t kLevels = 4;

BrickKey key_of_id(std::uint32_t id) {
  return BrickKey(id % kLevels, (id / kLevels) % 3, {id, id % 5, 0});
}

// The definition of both policies, by exhaustive search over the resident slots.
struct Model {
  struct Slot {
    BrickKey key;
    std::uint64_t last_use = 0, uploaded = 0, seq = 0;
    double distance = 0;
  };
  std::map<std::uint32_t, Slot> resident;
  std::uint64_t frame = 0, seq = 0;
  std::uint32_t ttl = 2;

  bool pinned(const Slot& s) const { return s.last_use == frame || frame < s.uploaded + ttl; }
  void use(Slot& s) {
    if (s.last_use != frame || s.seq == 0) s.seq = ++seq;  // first use within the frame
    s.last_use = frame;
  }
  // LRU: least recent frame, then earliest first use in that frame.
  std::optional<std::uint32_t> lru_victim() const {
    std::optional<std::uint32_t> best;
    for (const auto& [slot, s] : resident) {
      if (pinned(s)) continue;
      const Slot& b = best ? resident.at(*best) : s;
      if (!best || s.last_use < b.last_use || (s.last_use == b.last_use && s.seq < b.seq)) {
        best = slot;
      }
    }
    return best;
  }
  double priority(const Slot& s, const OctreemizerWeights& w) const {
    return w.ka * double(frame - s.last_use) + w.kl * double(kLevels - 1 - s.key.level()) +
           w.kd * s.distance;
  }
  std::optional<double> max_priority(const OctreemizerWeights& w) const {
    std::optional<double> best;
    for (const auto& [slot, s] : resident) {
      if (!pinned(s) && (!best || priority(s, w) > *best)) best = priority(s, w);
    }
    return best;
  }
};

// octreemizer_refresh: every frame moves the camera and calls distances_changed(), so every
// resident slot's distance is the new camera's (the published Octreemizer's per-frame wish list).
enum class Kind { lru, octreemizer, octreemizer_refresh };

// Runs random frames of touches, inserts and releases and checks every eviction decision.
void run_random(Kind kind, std::uint32_t ttl, std::uint32_t slots, std::uint32_t seed) {
  std::mt19937 gen(seed);
  auto rnd = [&](std::uint32_t n) { return std::uint32_t(gen() % n); };
  double camera = 0.0;
  const OctreemizerWeights w{1.0, 16.0, 0.5};
  std::unique_ptr<EvictionPolicy> policy;
  if (kind != Kind::lru) {
    policy = std::make_unique<OctreemizerPolicy>(
        kLevels, w, [&](BrickKey k) { return std::abs(double(k.brick().x % 40) - camera); });
  }
  BrickCache cache(kLayout, VoxelType::u8, kLayout.padded_voxels() * slots + 7, ttl,
                   std::move(policy));
  ASSERT_EQ(cache.slot_count(), slots);
  Model m;
  m.ttl = ttl;
  std::uint64_t failures = 0, evictions = 0;
  for (std::uint64_t frame = 1; frame <= 150; ++frame) {
    frame += rnd(4) == 0 ? 1 : 0;  // sometimes skip a frame
    cache.begin_frame(frame);
    m.frame = frame;
    camera = double(rnd(40));
    if (kind == Kind::octreemizer_refresh) {
      cache.policy().distances_changed();
      for (auto& [slot, s] : m.resident) {
        s.distance = std::abs(double(s.key.brick().x % 40) - camera);
      }
    }
    const std::uint32_t ops = 1 + rnd(3 * slots);
    for (std::uint32_t op = 0; op < ops; ++op) {
      const std::uint32_t what = rnd(10);
      if (what < 4 && !m.resident.empty()) {  // touch
        auto it = m.resident.begin();
        std::advance(it, rnd(std::uint32_t(m.resident.size())));
        cache.touch(it->first);
        m.use(it->second);
        it->second.distance = std::abs(double(it->second.key.brick().x % 40) - camera);
      } else if (what < 5 && !m.resident.empty()) {  // release
        auto it = m.resident.begin();
        std::advance(it, rnd(std::uint32_t(m.resident.size())));
        cache.release(it->first);
        m.resident.erase(it);
      } else {  // insert a key that may or may not be resident
        const BrickKey key = key_of_id(rnd(4 * slots));
        std::optional<std::uint32_t> existing;
        for (const auto& [slot, s] : m.resident)
          if (s.key == key) existing = slot;
        const bool full = m.resident.size() == slots;
        const std::optional<std::uint32_t> lru = m.lru_victim();
        const std::optional<double> pmax = m.max_priority(w);
        std::optional<double> victim_p;
        const std::optional<CacheInsertion> ins = cache.insert(key);
        if (existing) {
          ASSERT_TRUE(ins.has_value());
          EXPECT_EQ(ins->slot, *existing);
          EXPECT_FALSE(ins->evicted.has_value());
          m.use(m.resident[*existing]);
          m.resident[*existing].distance = std::abs(double(key.brick().x % 40) - camera);
          continue;
        }
        if (full && !lru) {  // everything pinned
          ASSERT_FALSE(ins.has_value()) << "frame " << frame;
          ++failures;
          continue;
        }
        ASSERT_TRUE(ins.has_value());
        if (full) {
          ASSERT_TRUE(ins->evicted.has_value());
          ASSERT_TRUE(m.resident.count(ins->slot));
          const Model::Slot& victim = m.resident[ins->slot];
          EXPECT_EQ(*ins->evicted, victim.key);
          EXPECT_FALSE(m.pinned(victim)) << "evicted a pinned brick";
          if (kind == Kind::lru) {
            EXPECT_EQ(ins->slot, *lru) << "frame " << frame;
          } else {
            victim_p = m.priority(victim, w);
            EXPECT_DOUBLE_EQ(*victim_p, *pmax) << "frame " << frame;
          }
          ++evictions;
        } else {
          EXPECT_FALSE(ins->evicted.has_value());
          EXPECT_FALSE(m.resident.count(ins->slot)) << "reused an occupied slot";
        }
        Model::Slot s;
        s.key = key;
        s.uploaded = frame;
        s.last_use = frame;
        s.seq = ++m.seq;
        s.distance = std::abs(double(key.brick().x % 40) - camera);
        m.resident[ins->slot] = s;
      }
    }
    ASSERT_EQ(cache.resident_count(), m.resident.size());
    for (const auto& [slot, s] : m.resident) {
      ASSERT_EQ(cache.key_of(slot), s.key);
      ASSERT_EQ(cache.find(s.key), slot);
      ASSERT_EQ(cache.pinned(slot), m.pinned(s));
    }
  }
  EXPECT_EQ(cache.stats().allocation_failures, failures);
  EXPECT_EQ(cache.stats().evictions, evictions);
  EXPECT_GT(evictions, 0u);  // the scenario really exercised eviction
}

}  // namespace

TEST(BrickCache, CapacityIsWholePaddedBricksPerPool) {
  for (VoxelType t : {VoxelType::u8, VoxelType::u16, VoxelType::f32}) {
    const std::uint64_t brick = 10ull * 10 * 10 * voxel_size(t);
    BrickCache c(kLayout, t, brick * 37 + brick - 1);
    EXPECT_EQ(c.slot_bytes(), brick);
    EXPECT_EQ(c.slot_count(), 37u);
    EXPECT_EQ(BrickCache(kLayout, t, brick).slot_count(), 1u);
  }
  EXPECT_RESOCT_ERROR(BrickCache(kLayout, VoxelType::u8, 0), ErrorCode::invalid_argument,
                      "capacity_bytes");
  EXPECT_RESOCT_ERROR(BrickCache(kLayout, VoxelType::u16, 1999), ErrorCode::invalid_argument,
                      "hold no brick");
  EXPECT_RESOCT_ERROR(BrickCache(BrickLayout{glm::uvec3(2), 1}, VoxelType::u8, 1 << 20),
                      ErrorCode::invalid_argument, "brick_size");
}

TEST(BrickCache, LruMatchesBruteForceModel) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) run_random(Kind::lru, 2, 12, seed);
}

TEST(BrickCache, LruNeverEvictsPinnedForAnyTtl) {
  for (std::uint32_t ttl : {0u, 1u, 3u, 6u}) run_random(Kind::lru, ttl, 9, 100 + ttl);
}

TEST(BrickCache, OctreemizerEvictsTheHighestDiscardPriority) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) run_random(Kind::octreemizer, 2, 12, seed);
  for (std::uint32_t ttl : {0u, 1u, 4u}) run_random(Kind::octreemizer, ttl, 7, 50 + ttl);
}

// distances_changed() re-reads every resident slot's distance (parked ones included) before the
// next victim, so the victim is the highest priority under the new distances.
TEST(BrickCache, OctreemizerRereadsDistancesAfterTheyChange) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    run_random(Kind::octreemizer_refresh, 2, 12, seed);
  }
  for (std::uint32_t ttl : {0u, 1u, 4u}) run_random(Kind::octreemizer_refresh, ttl, 7, 70 + ttl);
}

TEST(BrickCache, TtlProtectsFreshUploads) {
  BrickCache c(kLayout, VoxelType::u8, kLayout.padded_voxels() * 2, 3);
  c.begin_frame(1);
  const auto a = c.insert(key_of_id(1));
  c.begin_frame(2);
  const auto b = c.insert(key_of_id(2));
  ASSERT_TRUE(a && b);
  c.begin_frame(3);  // a uploaded at 1: pinned while frame < 1 + 3
  EXPECT_TRUE(c.pinned(a->slot));
  EXPECT_FALSE(c.insert(key_of_id(3)).has_value());
  EXPECT_EQ(c.stats().allocation_failures, 1u);
  c.begin_frame(4);
  EXPECT_FALSE(c.pinned(a->slot));
  EXPECT_TRUE(c.pinned(b->slot));
  const auto n = c.insert(key_of_id(3));
  ASSERT_TRUE(n.has_value());
  EXPECT_EQ(n->slot, a->slot);
  EXPECT_EQ(n->evicted, key_of_id(1));
  // A brick used this frame is pinned regardless of ttl.
  c.begin_frame(10);
  c.touch(b->slot);
  const auto m = c.insert(key_of_id(4));
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->evicted, key_of_id(3));
  EXPECT_FALSE(c.insert(key_of_id(5)).has_value());
}

TEST(BrickCache, ReleaseFreesASlotAndErrorsAreReported) {
  BrickCache c(kLayout, VoxelType::u8, kLayout.padded_voxels() * 2);
  c.begin_frame(1);
  const auto a = c.insert(key_of_id(1));
  ASSERT_TRUE(a.has_value());
  c.release(a->slot);
  c.release(a->slot);  // no-op
  EXPECT_FALSE(c.find(key_of_id(1)).has_value());
  EXPECT_EQ(c.resident_count(), 0u);
  EXPECT_EQ(c.stats().releases, 1u);
  EXPECT_RESOCT_ERROR(c.touch(a->slot), ErrorCode::out_of_range, "not resident");
  EXPECT_RESOCT_ERROR(c.touch(99), ErrorCode::out_of_range, "not resident");
  EXPECT_RESOCT_ERROR(c.begin_frame(1), ErrorCode::invalid_argument, "frame");
  EXPECT_RESOCT_ERROR(OctreemizerPolicy(0), ErrorCode::invalid_argument, "level_count");
  EXPECT_RESOCT_ERROR(OctreemizerPolicy(4, OctreemizerWeights{-1, 1, 1}),
                      ErrorCode::invalid_argument, "ka");
}

TEST(BrickCache, OctreemizerSetDistanceReordersVictims) {
  auto policy = std::make_unique<OctreemizerPolicy>(kLevels, OctreemizerWeights{1, 0, 1});
  OctreemizerPolicy* p = policy.get();
  BrickCache c(kLayout, VoxelType::u8, kLayout.padded_voxels() * 3, 0, std::move(policy));
  c.begin_frame(1);
  std::vector<std::uint32_t> s;
  for (std::uint32_t i = 0; i < 3; ++i) s.push_back(c.insert(key_of_id(i))->slot);
  c.begin_frame(2);
  p->set_distance(s[0], 1.0);
  p->set_distance(s[1], 50.0);
  p->set_distance(s[2], 10.0);
  EXPECT_DOUBLE_EQ(p->priority(s[1], 2), 1.0 + 50.0);
  EXPECT_EQ(c.insert(key_of_id(10))->evicted, key_of_id(1));
  EXPECT_EQ(c.insert(key_of_id(11))->evicted, key_of_id(2));
}

TEST(UploadBudget, AdmitsInOrderUntilEitherBudgetIsExhausted) {
  std::vector<UploadCandidate> c;
  for (std::uint32_t i = 0; i < 10; ++i) c.push_back({key_of_id(i), i == 4 ? 0u : 1000u});
  UploadPlan p = plan_uploads(c, UploadBudget{3, 1u << 30});
  EXPECT_EQ(p.admitted.size(), 3u);
  EXPECT_EQ(p.deferred.size(), 7u);
  EXPECT_EQ(p.admitted_bytes, 3000u);
  EXPECT_EQ(p.deferred.front().key, key_of_id(3));
  p = plan_uploads(c, UploadBudget{100, 3500});  // bytes bind: 3 x 1000, the 4th does not fit
  EXPECT_EQ(p.admitted.size(), 3u);
  EXPECT_EQ(p.admitted_bytes, 3000u);
  // The zero-byte 5th candidate would fit, but priority order is not overtaken.
  EXPECT_EQ(p.deferred.size(), 7u);
  p = plan_uploads(c, UploadBudget{100, 5000});
  EXPECT_EQ(p.admitted.size(), 6u);  // 5 x 1000 + one free page update
  EXPECT_EQ(p.admitted_bytes, 5000u);
  p = plan_uploads(c, UploadBudget{});
  EXPECT_EQ(p.admitted.size(), 10u);
  EXPECT_TRUE(p.deferred.empty());
  p = plan_uploads(c, UploadBudget{0, 1u << 30});
  EXPECT_TRUE(p.admitted.empty());
  EXPECT_EQ(p.deferred.size(), 10u);
  p = plan_uploads({}, UploadBudget{1, 1});
  EXPECT_TRUE(p.admitted.empty() && p.deferred.empty());
}

TEST(BrickCache, KeySlotIndexMatchesAMapUnderChurn) {
  detail::KeySlotIndex index;
  index.reset(64);  // 128 cells: long probe runs and many backward shifts
  std::map<std::uint64_t, std::uint32_t> ref;
  std::mt19937_64 gen(77);
  for (int i = 0; i < 20000; ++i) {
    const std::uint64_t key = gen() % 200;
    if (ref.count(key)) {
      index.erase(key);
      ref.erase(key);
    } else if (ref.size() < 64) {
      const auto slot = std::uint32_t(gen() % 1000);
      index.insert(key, slot);
      ref[key] = slot;
    }
    if (i % 97 == 0) {
      for (std::uint64_t k = 0; k < 200; ++k) {
        const auto it = ref.find(k);
        ASSERT_EQ(index.find(k), it == ref.end() ? std::nullopt : std::optional(it->second));
      }
    }
  }
  index.erase(12345);  // absent: no-op
}

TEST(BrickCache, BrickCameraDistanceUsesTheLevel0FootprintCentre) {
  VolumeDesc v;
  v.extent = {40, 33, 17};
  v.spacing = {1.0, 2.0, 0.5};
  const BrickHierarchy h(v, BrickLayout{glm::uvec3(8), 1});
  // Level 0 brick (4, 4, 2) covers voxels [32, 40) x [32, 33) x [16, 17): centre (36, 32.5, 16.5).
  const glm::dvec3 c(36.0 * 1.0, 32.5 * 2.0, 16.5 * 0.5);
  EXPECT_DOUBLE_EQ(brick_camera_distance(h, BrickKey(0, 0, {4, 4, 2}), c + glm::dvec3(3, 4, 0)),
                   5.0);
  // The coarsest brick covers the whole volume.
  const glm::dvec3 mid = glm::dvec3(20.0, 16.5 * 2.0, 8.5 * 0.5);
  EXPECT_DOUBLE_EQ(brick_camera_distance(h, BrickKey(h.level_count() - 1, 0, {0, 0, 0}), mid), 0.0);
  EXPECT_RESOCT_ERROR(brick_camera_distance(h, BrickKey(0, 0, {5, 0, 0}), mid),
                      ErrorCode::out_of_range, "outside");
}
