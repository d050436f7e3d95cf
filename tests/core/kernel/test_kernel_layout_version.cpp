// What RESOCT_KERNEL_LAYOUT_VERSION 7 means (2: ResoctFrame gained the jitter; 4:
// ResoctLevelInfo gained node_depth, the standard-octree mode's culling node; 5: ResoctFrame
// gained the step levels of kernel/step_lut.glsl.h; 6: ResoctSlotInfo gained lod_error_code and
// MAPPED / HOMOGENEOUS page entries an error code in bits 26-29; 7: ResoctLevelInfo gained
// depth_cap and ResoctDepthInfo shortest_side, the traversal's depth rules precomputed): the sizes
// of the records the host shares with the device and the encodings of their packed words. A change
// to any of them fails here until the version is incremented and this table updated
// (kernel/layout_version.glsl.h), so applications and backends built against another layout can
// tell.
#include <gtest/gtest.h>

#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct/engine/page_table.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "resoct/scene/transfer_function.hpp"
#include "resoct/version.hpp"

namespace resoct::test {
namespace {

namespace k = resoct::kernel;

TEST(KernelLayoutVersion, RecordsAreThoseOfTheDeclaredVersion) {
  ASSERT_EQ(k::RESOCT_KERNEL_LAYOUT_VERSION, 7u)
      << "the layout version changed: update the table of this test to the new layout";
  const char* bump = "a shared record changed: increment RESOCT_KERNEL_LAYOUT_VERSION";
  EXPECT_EQ(sizeof(k::ResoctFrame), 524u) << bump;
  EXPECT_EQ(sizeof(k::ResoctFxFrame), 44u) << bump;
  EXPECT_EQ(sizeof(k::ResoctSlotInfo), 68u) << bump;
  EXPECT_EQ(sizeof(k::ResoctLevelInfo), 48u) << bump;
  EXPECT_EQ(sizeof(k::ResoctDepthInfo), 72u) << bump;
  EXPECT_EQ(sizeof(k::ResoctRayStats), 40u) << bump;
  EXPECT_EQ(sizeof(PageDelta), 8u) << bump;
  EXPECT_EQ(sizeof(OctreeWordDelta), 8u) << bump;
  EXPECT_EQ(k::RESOCT_PAGE_STATE_SHIFT, 30u) << bump;
  EXPECT_EQ(k::RESOCT_PAGE_STATE_HOMOGENEOUS, 3u) << bump;
  EXPECT_EQ(k::RESOCT_PAGE_ERROR_SHIFT, 26u) << bump;
  EXPECT_EQ(k::RESOCT_PAGE_MAX_CACHE_SLOT, (1u << 26) - 1u) << bump;
  EXPECT_EQ(k::RESOCT_NODE_WORDS, 4u) << bump;
  EXPECT_EQ(k::RESOCT_NODE_FLAGS, 3u) << bump;
  EXPECT_EQ(k::RESOCT_REQUEST_IN_BLOCK_BITS, 12u) << bump;
  EXPECT_EQ(k::RESOCT_REQUEST_BLOCK_MISS_BIT, 0x80000000u) << bump;
  EXPECT_EQ(kTfLutSize, 1024u) << bump;  // RESOCT_TF_LUT_SIZE (tf.glsl.h is not standalone)
  EXPECT_EQ(k::RESOCT_MAX_SLOTS, 32u) << bump;
}

TEST(KernelLayoutVersion, TheLibraryWasBuiltWithTheseHeaders) {
  EXPECT_EQ(library_kernel_layout_version(), kKernelLayoutVersion);
  EXPECT_EQ(kKernelLayoutVersion, k::RESOCT_KERNEL_LAYOUT_VERSION);
}

}  // namespace
}  // namespace resoct::test
