#include "core/render/test_renderer_support.hpp"

#include <algorithm>

#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/render/visible_subtrees.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/expect_error.hpp"

namespace resoct::test {
namespace {

std::uint64_t slot_bytes(const Renderer& r) {
  return inspect::cache(r).slot_bytes();
}

TEST(Renderer, UploadsStayWithinTheBrickBudgetAndStateMatchesTheSource) {
  auto src = make_test_source();
  Rig rig(src, test_options(256, 5));
  const Scene scene = test_scene(0);
  bool converged = false;
  std::uint32_t frames = 0;
  std::uint64_t uploads = 0;
  while (!converged && frames < 200) {
    const FrameReport rep = rig.renderer->render_frame(scene);
    ++frames;
    converged = rep.converged;
    const RecordedUpdate& u = rig.backend->updates().back();
    EXPECT_LE(u.upload_slots.size(), 5u);
    EXPECT_EQ(u.upload_bytes, u.upload_slots.size() * slot_bytes(*rig.renderer));
    EXPECT_EQ(rep.stats.bricks_uploaded, u.upload_slots.size());
    EXPECT_EQ(rep.image.width(), 8u);
    uploads += u.upload_slots.size();
    ASSERT_EQ(check_state(*rig.renderer, *rig.backend, *src), "") << "frame " << frames;
  }
  ASSERT_TRUE(converged);
  // Every level-0 brick of the scene is available, non-constant ones as cache slots.
  std::uint64_t varying = 0;
  for (const PageAddress& a : level0_bricks(rig.renderer->hierarchy(), 0)) {
    const std::uint32_t e = inspect::page_table(*rig.renderer).entry(a);
    EXPECT_NE(kernel::resoct_page_state(e), kernel::RESOCT_PAGE_STATE_UNMAPPED);
    if (!src->brick_meta(BrickKey(0, 0, a.brick)).constant) ++varying;
  }
  EXPECT_EQ(varying, 32u);  // x-bricks 1 and 2 of 4, brute force from the definition
  EXPECT_GE(uploads, varying);
  EXPECT_GE(frames, varying / 5 + 1);
  // A converged frame changes nothing.
  const FrameReport again = rig.renderer->render_frame(scene);
  EXPECT_TRUE(again.converged);
  EXPECT_EQ(again.stats.bricks_uploaded, 0u);
  EXPECT_EQ(again.stats.brick_requests, 0u);
  EXPECT_EQ(again.stats.working_set_bricks, varying);
  EXPECT_EQ(again.stats.working_set_bytes, varying * slot_bytes(*rig.renderer));
}

// Region answers as wide as the value range: conservative but useless for culling, as a coarse
// metadata pyramid gives around sharp features.
class WideRegionSource : public BrickSource {
 public:
  explicit WideRegionSource(std::shared_ptr<const BrickSource> inner) : inner_(std::move(inner)) {}
  const BrickHierarchy& hierarchy() const override { return inner_->hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    inner_->read_brick(key, out);
  }
  BrickMeta brick_meta(BrickKey key) const override { return inner_->brick_meta(key); }
  RegionMeta region_meta(std::uint32_t c, const Box3&) const override {
    const ValueRange r = hierarchy().volume().range(c);
    return RegionMeta{r.lo, r.hi, occupancy_span(r.lo, r.hi, r)};
  }
  std::string name() const override { return "wide-region-source"; }

 private:
  std::shared_ptr<const BrickSource> inner_;
};

// Each applied level-0 brick gives the leaves inside it the exact metadata of their sampling
// support (ResidencyOctree::metadata_from_brick, metadata_from_constant_brick), however wide the
// source's region answers.
TEST(Renderer, AppliedLevel0BricksGiveTheirLeavesExactMetadata) {
  auto inner = make_test_source(1);
  auto src = std::make_shared<WideRegionSource>(inner);
  Rig rig(src, test_options(256, 256));
  ASSERT_TRUE(rig.renderer->render_until_converged(test_scene(0), 50).converged);
  const OctreeLayout& layout = inspect::layout(*rig.renderer);
  const BrickHierarchy& h = rig.renderer->hierarchy();
  const ValueRange range = h.volume().range(0);
  const ResidencyOctree& octree = inspect::octree(*rig.renderer);
  const std::uint32_t leaf = layout.leaf_depth();
  std::size_t checked = 0;
  std::size_t constant = 0;
  for (std::uint64_t node = layout.depth(leaf).first_node; node < layout.node_count(); ++node) {
    const Box3 box = layout.node_box(node);
    if (box.empty()) continue;
    const glm::uvec3 brick(glm::u64vec3(box.lo) / glm::u64vec3(h.layout().brick_size));
    // Constant bricks are mapped without voxels (metadata_from_constant_brick).
    constant += src->brick_meta(BrickKey(0, 0, brick)).constant ? 1u : 0u;
    const RegionMeta truth = inner->region_meta(0, layout.sampling_support(node));
    EXPECT_EQ(octree.word(node, 0, kernel::RESOCT_NODE_MINMAX),
              octree_pack_range(truth.min, truth.max, range))
        << "leaf " << node;
    EXPECT_EQ(octree.word(node, 0, kernel::RESOCT_NODE_OCCUPANCY), truth.occupancy)
        << "leaf " << node;
    ++checked;
  }
  EXPECT_GT(checked, constant);
  EXPECT_GT(constant, 0u);
  EXPECT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
}

TEST(Renderer, ConstantBricksMapWithoutCacheSlots) {
  auto src = make_test_source();
  Rig rig(src, test_options(256, 256));
  const ConvergeReport rep = rig.renderer->render_until_converged(test_scene(1), 20);
  ASSERT_TRUE(rep.converged);
  const auto& pt = inspect::page_table(*rig.renderer);
  for (std::uint32_t y = 0; y < 4; ++y) {
    for (std::uint32_t z = 0; z < 4; ++z) {
      const std::uint32_t e0 = pt.entry(PageAddress{0, 0, {0, y, z}});
      EXPECT_EQ(kernel::resoct_page_state(e0), kernel::RESOCT_PAGE_STATE_EMPTY);
      const PageAddress h{0, 0, {3, y, z}};
      EXPECT_EQ(kernel::resoct_page_state(pt.entry(h)), kernel::RESOCT_PAGE_STATE_HOMOGENEOUS);
      EXPECT_EQ(pt.homogeneous_value(h), 101.0);  // 100 + channel 1
    }
  }
  EXPECT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
}

TEST(Renderer, ByteBudgetLimitsUploads) {
  auto src = make_test_source();
  RendererOptions o = test_options(256, 1000);
  o.upload_budget.max_bytes = 2500;  // two and a half padded 10³ u8 bricks
  Rig rig(src, o);
  bool saw_two = false;
  for (int f = 0; f < 30; ++f) {
    rig.renderer->render_frame(test_scene(0));
    const std::size_t n = rig.backend->updates().back().upload_slots.size();
    EXPECT_LE(n, 2u);
    saw_two = saw_two || n == 2;
  }
  EXPECT_TRUE(saw_two);
}

TEST(Renderer, FirstUpdateIsFullLaterOnesAreDeltas) {
  auto src = make_test_source();
  Rig rig(src, test_options(256, 4));
  for (int f = 0; f < 6; ++f) rig.renderer->render_frame(test_scene(0));
  const auto& ups = rig.backend->updates();
  ASSERT_EQ(ups.size(), 6u);
  EXPECT_TRUE(ups[0].pages_full);
  EXPECT_TRUE(ups[0].nodes_full);
  for (std::size_t i = 2; i < ups.size(); ++i) {
    EXPECT_FALSE(ups[i].pages_full) << i;
    EXPECT_FALSE(ups[i].nodes_full) << i;
  }
  EXPECT_EQ(rig.backend->configure_calls(), 1u);
  EXPECT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
}

TEST(Renderer, NodeRequestsAreAnsweredFromRegionMetadata) {
  auto src = make_test_source();
  register_test_backend();
  Renderer r(src, test_options(64, 16));
  RecordingBackend* b = last_recording_backend();
  const OctreeLayout& layout = inspect::layout(r);
  const std::uint32_t leaf_depth = layout.leaf_depth();
  const std::uint64_t first_leaf = layout.depth(leaf_depth).first_node;
  b->set_script([&](const FrameTables&, FrameResult& res, RecordingBackend&) {
    if (res.image.width() != 0 && r.frame_index() == 1) {
      for (std::uint32_t i = 0; i < 4; ++i) {
        res.node_requests.push_back(Request{std::uint32_t(first_leaf + i), 1, 0});
      }
      res.node_requests.push_back(Request{0xFFFFFFF0u, 1, 0});  // garbage from the device
    }
  });
  const FrameReport f1 = r.render_frame(test_scene(2));
  EXPECT_FALSE(f1.converged);
  EXPECT_EQ(f1.stats.node_requests, 5u);
  const FrameReport f2 = r.render_frame(test_scene(2));
  EXPECT_EQ(f2.stats.nodes_answered, 4u);
  EXPECT_TRUE(f2.converged);
  const ValueRange range = src->volume().range(2);
  for (std::uint32_t i = 0; i < 4; ++i) {
    const std::uint64_t node = first_leaf + i;
    const RegionMeta m = src->region_meta(2, layout.sampling_support(node));
    EXPECT_EQ(inspect::octree(r).word(node, 0, kernel::RESOCT_NODE_MINMAX),
              octree_pack_range(m.min, m.max, range));
    EXPECT_EQ(inspect::octree(r).word(node, 0, kernel::RESOCT_NODE_FLAGS) &
                  kernel::RESOCT_NODE_STATE_MASK,
              kernel::RESOCT_NODE_VALID);
  }
  EXPECT_EQ(check_state(r, *b, *src), "");
}

// The renderer rebuilds the visible-subtree bits only when the octree's words or the transfer
// functions changed, yet every frame's bits are those of its octree and scene: compared with a
// fresh build from the octree as the backend holds it, on each frame of a converging cache
// (node metadata answered, brick metadata arriving) and after a change of transfer function.
TEST(Renderer, VisibleSubtreeBitsFollowTheOctreeAndTheTransferFunctions) {
  auto src = make_test_source();
  register_test_backend();
  RendererOptions o = test_options(256, 8);
  o.start_depth = 0;  // the tree has three depths: bits at the root and its children
  Renderer r(src, o);
  RecordingBackend* b = last_recording_backend();
  std::uint32_t frames = 0, rebuilt = 0, with_bits = 0;
  std::uint64_t last_version = 0;
  const std::uint32_t nodes = std::uint32_t(inspect::layout(r).node_count());
  b->set_script([&](const FrameTables& t, FrameResult& res, RecordingBackend&) {
    ++frames;
    // The recording backend does not march: ask for the nodes' metadata, as rays would, one node
    // per frame, so that the octree changes by a few words at a time (deltas, not full uploads).
    if (frames <= nodes) res.node_requests.push_back(Request{frames - 1, 1, 0});
    FrameTables fresh = t;
    build_visible_subtrees(inspect::octree(r), fresh);
    EXPECT_EQ(t.visible_subtrees, fresh.visible_subtrees) << "frame " << frames;
    if (t.visible_subtrees_version != last_version) ++rebuilt;
    last_version = t.visible_subtrees_version;
    if (std::any_of(t.visible_subtrees.begin(), t.visible_subtrees.end(),
                    [](std::uint32_t w) { return w != 0u; })) {
      ++with_bits;
    }
  });
  Scene scene = test_scene(1);
  // Shows every value but 0 (the zeros below x = 9 are hidden).
  scene.channels[0].tf =
      TransferFunction({{0.0, {1, 1, 1, 0}}, {0.002, {1, 1, 1, 0.5}}, {1.0, {1, 1, 1, 1}}});
  for (std::uint32_t i = 0; i < nodes + 5; ++i) r.render_frame(scene);
  const std::uint32_t rebuilt_before = rebuilt;
  EXPECT_GT(with_bits, 0u) << "the comparison saw bits";
  scene.channels[0].tf =
      TransferFunction({{0.0, {1, 1, 1, 0}}, {0.6, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 1}}});
  for (int i = 0; i < 5; ++i) r.render_frame(scene);
  EXPECT_GT(rebuilt, rebuilt_before) << "a new transfer function rebuilds them";
  EXPECT_LT(rebuilt, frames) << "frames with nothing changed reuse them";
}

TEST(Renderer, RejectsBadOptionsAndScenes) {
  auto src = make_test_source();
  register_test_backend();
  RendererOptions o = test_options(16, 4);
  EXPECT_RESOCT_ERROR(parse_eviction("fifo"), ErrorCode::invalid_argument, "eviction");
  o.eviction = static_cast<Eviction>(7);
  EXPECT_RESOCT_ERROR(Renderer(src, o), ErrorCode::invalid_argument, "eviction");
  o = test_options(16, 4);
  o.ttl = 0;
  EXPECT_RESOCT_ERROR(Renderer(src, o), ErrorCode::invalid_argument, "ttl");
  o = test_options(16, 4);
  o.upload_budget.max_bricks = 0;
  EXPECT_RESOCT_ERROR(Renderer(src, o), ErrorCode::invalid_argument, "upload_budget");
  o = test_options(16, 4);
  o.visible_slots = 33;
  EXPECT_RESOCT_ERROR(Renderer(src, o), ErrorCode::invalid_argument, "visible_slots");
  o = test_options(16, 4);
  o.backend = "no-such-backend";
  EXPECT_RESOCT_ERROR(Renderer(src, o), ErrorCode::invalid_argument, "backend");
  EXPECT_RESOCT_ERROR(Renderer(nullptr, test_options(16, 4)), ErrorCode::invalid_argument,
                      "source");
  Renderer r(src, test_options(16, 4));
  Scene two = test_scene(0);
  two.channels.push_back(test_scene(1).channels[0]);
  EXPECT_RESOCT_ERROR(r.render_frame(two), ErrorCode::invalid_argument, "visible slots");
  EXPECT_RESOCT_ERROR(r.render_frame(test_scene(7)), ErrorCode::invalid_argument, "scene");
  EXPECT_RESOCT_ERROR(r.render_until_converged(test_scene(0), 0), ErrorCode::invalid_argument,
                      "max_frames");
}

TEST(Renderer, MoreImportantChannelsLoadFirstWithinALevel) {
  auto src = make_test_source();
  register_test_backend();
  RendererOptions o = test_options(64, 3);
  o.visible_slots = 2;
  Renderer r(src, o);
  RecordingBackend* b = last_recording_backend();
  b->set_script([&](const FrameTables& t, FrameResult& res, RecordingBackend& rb) {
    for (const auto& slot : t.slots)
      rb.want(inspect::page_table(r), level0_bricks(r.hierarchy(), slot.slot), res);
  });
  Scene scene = test_scene(0);
  scene.channels.push_back(test_scene(2).channels[0]);
  scene.channels[1].importance = -1;  // channel 2 before channel 0
  r.render_frame(scene);              // block misses: the page-table blocks are allocated
  r.render_frame(scene);  // requests; loads 3 bricks: level 2 of both channels, then level 1
  r.render_frame(scene);  // applies them
  auto level1_set = [&](std::uint32_t channel) {
    const std::uint32_t slot = *inspect::channel_map(r).slot_of(channel);
    int n = 0;
    for (std::uint32_t z = 0; z < 2; ++z)
      for (std::uint32_t y = 0; y < 2; ++y)
        for (std::uint32_t x = 0; x < 2; ++x) {
          n += inspect::page_table(r).entry(PageAddress{slot, 1, {x, y, z}}) !=
                       kernel::RESOCT_PAGE_UNMAPPED_WORD
                   ? 1
                   : 0;
        }
    return n;
  };
  EXPECT_EQ(level1_set(2), 1);
  EXPECT_EQ(level1_set(0), 0);
  EXPECT_NE(
      inspect::page_table(r).entry(PageAddress{*inspect::channel_map(r).slot_of(0), 2, {0, 0, 0}}),
      kernel::RESOCT_PAGE_UNMAPPED_WORD);
  EXPECT_EQ(check_state(r, *b, *src), "");
}

TEST(Renderer, ExampleScenesFitTheirProceduralDatasets) {
  const char* names[] = {"tubes", "noisefloor", "turbulence", "mandelbulb",
                         "cells", "constant",   "ramp",       "sphere"};
  for (const char* name : names) {
    const std::string path = std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/" + name + ".json";
    const Scene s = load_scene(path);
    const auto src = make_procedural_source(std::string("procedural:") + name);
    EXPECT_NO_THROW(s.validate(src->volume(), path)) << name;
    EXPECT_EQ(s.channels.size(), std::string(name) == "cells" ? 4u : 1u) << name;
  }
}

}  // namespace
}  // namespace resoct::test
