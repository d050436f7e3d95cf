// Test-only stand-in for build_frame_tables() until the traversal kernel's implementation is
// merged (then this file is deleted): fills just what RecordingBackend reads.
#include "resoct/frame_tables.hpp"

namespace resoct {

FrameTables build_frame_tables(const Scene& scene, const BrickHierarchy& hierarchy,
                               const OctreeLayout& layout, const ChannelMap& channels,
                               RenderMode mode, std::uint64_t frame_index) {
  FrameTables t;
  t.frame.width = scene.viewport.width;
  t.frame.height = scene.viewport.height;
  t.frame.mode = static_cast<std::uint32_t>(mode);
  t.frame.level_count = hierarchy.level_count();
  t.frame.depth_count = layout.depth_count();
  t.frame.frame_index = static_cast<std::uint32_t>(frame_index);
  t.frame.page_slot_count = channels.slot_count();
  t.frame.node_slot_count = channels.slot_count();
  t.frame.slot_count = static_cast<std::uint32_t>(scene.channels.size());
  for (const ChannelSettings& c : scene.channels) {
    kernel::ResoctSlotInfo s{};
    s.slot = channels.slot_of(c.channel).value_or(0u);
    t.slots.push_back(s);
  }
  return t;
}

}  // namespace resoct

namespace resoct::test {
// Referenced by the renderer tests so that static linking pulls this object in (the library
// that calls build_frame_tables comes after tests/support on the link line).
void link_frame_tables_stub() {}
}  // namespace resoct::test
