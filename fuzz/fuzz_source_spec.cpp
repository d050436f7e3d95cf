// Fuzz target: source spec strings (`procedural:NAME[:WxHxD[:CHANNELS]]`, open_source). A spec
// that parses must build its source; the source's canonical name must parse back to the same
// spec; and the cheap queries a viewer makes first (hierarchy, region metadata, the coarsest
// brick) must answer or throw resoct::Error at any extent the parser accepts.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "fuzz_support.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/sources/procedural_source.hpp"

namespace {

using namespace resoct;

void exercise(const ProceduralSource& src) {
  const BrickHierarchy& h = src.hierarchy();
  const ProceduralSpec again = parse_procedural_spec(src.name());
  const ProceduralSpec& spec = src.spec();
  if (again.name != spec.name || again.extent != spec.extent || again.channels != spec.channels ||
      again.type != spec.type) {
    fuzz::fail("canonical name '" + src.name() + "' does not parse back to the same spec");
  }
  const std::uint32_t last = h.level_count() - 1;
  const Box3 all{glm::i64vec3(0), glm::i64vec3(spec.extent)};
  std::vector<std::byte> buf(std::size_t(h.layout().padded_voxels()) * voxel_size(spec.type));
  for (std::uint32_t c : {0u, spec.channels - 1}) {
    (void)src.region_meta(c, all);
    (void)src.coarse_error_bound(last, c);
    // Small bricks (see the layout below) keep a coarse brick at a few thousand field samples.
    src.read_brick(BrickKey(last, c, glm::uvec3(0)), buf);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view spec(reinterpret_cast<const char*>(data), size);
  fuzz::errors_only([&] { (void)parse_procedural_spec(spec); });
  // open_source treats anything else as a path; fuzzing the file system is not the point.
  if (!spec.starts_with("procedural:") && !spec.empty()) return 0;
  fuzz::errors_only([&] { (void)open_source(spec); });
  fuzz::errors_only([&] {
    const ProceduralSource src(spec, BrickLayout{glm::uvec3(4), 1}, 1);
    exercise(src);
  });
  return 0;
}
