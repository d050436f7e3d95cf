// Minimal embedding: describe a volume, build its brick hierarchy and print the level chain.
// Exits non-zero if the library does not behave, so the packaging test checks more than linking.
#include <cstdio>

#include "resoct/cpu/threads.hpp"
#include "resoct/volume/hierarchy.hpp"
#ifdef CONSUMER_WITH_IO
#include "resoct/io/open_source.hpp"
#include "resoct/sources/brick_source.hpp"
#endif
#ifdef CONSUMER_WITH_VULKAN
#include "resoct/vulkan/devices.hpp"
#endif

int main() {
  resoct::VolumeDesc volume;
  volume.extent = {1024, 1024, 40};
  volume.type = resoct::VoxelType::u16;
  const resoct::BrickHierarchy h(volume, resoct::BrickLayout{});
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const auto& li = h.level(l);
    std::printf("level %u: %llux%llux%llu voxels, %llu bricks\n", l,
                static_cast<unsigned long long>(li.extent.x),
                static_cast<unsigned long long>(li.extent.y),
                static_cast<unsigned long long>(li.extent.z),
                static_cast<unsigned long long>(li.brick_count));
  }
  std::printf("cpu threads: %d\n", resoct::cpu::thread_count());
#ifdef CONSUMER_WITH_IO
  // resoct::io: a source opened by its spec string.
  const auto source = resoct::open_source("procedural:cells:64x64x16");
  std::printf("io: procedural:cells:64x64x16 has %u levels\n", source->hierarchy().level_count());
  if (source->hierarchy().level_count() == 0) return 1;
#endif
#ifdef CONSUMER_WITH_VULKAN
  std::printf("vulkan devices: %zu\n", resoct::vk::list_devices().size());
#endif
  return h.level_count() == 6 && h.level(h.level_count() - 1).brick_count == 1 ? 0 : 1;
}
