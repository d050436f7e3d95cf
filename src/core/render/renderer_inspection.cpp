// resoct::inspect (renderer_inspection.hpp): the engine's structures behind a Renderer, for
// tests, tools, benchmarks and the Python module.
#include "resoct/render/renderer_inspection.hpp"

#include "renderer_impl.hpp"

namespace resoct {

namespace inspect {

// The one friend of Renderer: the functions below reach its Impl through it.
struct Access {
  static const Renderer::Impl& impl(const Renderer& r) noexcept { return *r.impl_; }
  static Renderer::Impl& impl(Renderer& r) noexcept { return *r.impl_; }
};

const OctreeLayout& layout(const Renderer& r) noexcept {
  return Access::impl(r).layout_;
}
const PageTable& page_table(const Renderer& r) noexcept {
  return Access::impl(r).pages_;
}
const BrickCache& cache(const Renderer& r) noexcept {
  return *Access::impl(r).cache_;
}
const ResidencyOctree& octree(const Renderer& r) noexcept {
  return *Access::impl(r).octree_;
}
const ChannelMap& channel_map(const Renderer& r) noexcept {
  return Access::impl(r).channels_;
}
const BrickLoader& loader(const Renderer& r) noexcept {
  return *Access::impl(r).loader_;
}
Backend& backend(Renderer& r) noexcept {
  return *Access::impl(r).backend_;
}
const BackendConfig& backend_config(const Renderer& r) noexcept {
  return Access::impl(r).config_;
}

}  // namespace inspect

}  // namespace resoct
