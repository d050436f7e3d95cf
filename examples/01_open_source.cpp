// Open any source the tools open (procedural, brick store, OME-Zarr, NIfTI, NRRD, TIFF, over
// HTTP or S3) and describe it, as a viewer does before it renders.
#include <cstdio>
#include <string>

#include "resoct/resoct.hpp"

int main(int argc, char** argv) {
  const char* spec = argc > 1 ? argv[1] : "procedural:cells:256x256x32";
  const auto source = resoct::open_source(spec);
  const resoct::BrickHierarchy& h = source->hierarchy();
  const resoct::VolumeDesc& v = h.volume();
  std::printf("%s: %u channels of %s, %u timepoints\n", source->name().c_str(), v.channels,
              std::string(resoct::to_string(v.file_type())).c_str(), source->timepoints());
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const resoct::LevelInfo& level = h.level(l);
    std::printf("level %u: %llux%llux%llu voxels in %llu bricks\n", l,
                static_cast<unsigned long long>(level.extent.x),
                static_cast<unsigned long long>(level.extent.y),
                static_cast<unsigned long long>(level.extent.z),
                static_cast<unsigned long long>(level.brick_count));
  }
  // Value range of every channel from the source's metadata, without reading voxels.
  const resoct::Box3 all{{0, 0, 0}, glm::i64vec3(v.extent)};
  for (std::uint32_t c = 0; c < v.channels; ++c) {
    const resoct::RegionMeta m = source->region_meta(c, all);
    std::printf("channel %u: values %g..%g\n", c, m.min, m.max);
  }
  return h.level_count() > 0 ? 0 : 1;
}
