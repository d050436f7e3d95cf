// The README's embedding example, built and run by ctest so that it cannot rot.
#include <cstdio>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/open_source.hpp"

int main() {
  // Any brick source: a procedural volume, an in-memory one, or a brick store file.
  auto source = resoct::open_source("procedural:tubes:128x128x128");
  const resoct::BrickHierarchy& h = source->hierarchy();
  std::printf("%u levels, %llu bricks per channel\n", h.level_count(),
              static_cast<unsigned long long>(h.bricks_per_channel()));

  // Convert it to resoct's own random-access, checksummed store (written atomically).
  resoct::StoreWriteOptions options;
  options.codec = resoct::Codec::zstd;
  resoct::write_brick_store(*source, "tubes.rbs", options);

  // Culling metadata of the finest voxels of any region, without touching voxels.
  resoct::BrickStoreSource store("tubes.rbs");
  const resoct::RegionMeta m = store.region_meta(0, resoct::Box3{{0, 0, 0}, {64, 64, 64}});
  std::printf("region range [%g, %g]\n", m.min, m.max);
  return m.max >= m.min ? 0 : 1;
}
