#include "support/converge_run.hpp"

#include <chrono>

#include "resoct/render/renderer_inspection.hpp"
#include "support/bench_rig.hpp"

namespace resoct::bench {

Scene source_scene(const VolumeDesc& volume, std::uint32_t visible, std::uint32_t image,
                   bool duplicated, double angle) {
  Scene sc;
  sc.camera = orbit_camera(volume, angle);
  sc.viewport = {image, image};
  for (std::uint32_t c = 0; c < visible; ++c) {
    ChannelSettings s;
    s.channel = c;
    s.tf = duplicated ? duplicate_tf(c, visible) : bench_tf(c, visible);
    sc.channels.push_back(s);
  }
  return sc;
}

ConvergeRun converge(std::shared_ptr<const BrickSource> source, const Scene& scene,
                     const RendererOptions& options, std::uint32_t max_frames,
                     std::uint32_t steady_frames) {
  using Clock = std::chrono::steady_clock;
  Renderer renderer(std::move(source), options);
  ConvergeRun run;
  run.cache_slots = inspect::backend_config(renderer).cache_slots;
  run.brick_bytes = renderer.hierarchy().layout().padded_voxels() *
                    voxel_size(renderer.hierarchy().volume().type);
  FrameReport report;
  const auto start = Clock::now();
  while (run.frames < max_frames) {
    const auto t0 = Clock::now();
    report = renderer.render_frame(scene);
    run.ms_last_frame = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    ++run.frames;
    run.bricks_uploaded += report.stats.bricks_uploaded;
    run.bytes_uploaded += report.stats.bytes_uploaded;
    run.evictions += report.stats.evictions;
    if (report.converged) break;
    // With loader threads, wait so that every frame counts (as render_until_converged does).
    renderer.wait_for_loads();
  }
  run.ms_total = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  run.converged = report.converged;
  {
    const PageTable& pt = inspect::page_table(renderer);
    run.page_blocks = pt.allocated_blocks();
    run.page_pool_blocks = pt.pool_block_count();
    run.page_table_bytes =
        4u * (std::uint64_t(pt.directory().size()) +
              (std::uint64_t(pt.allocated_blocks()) + 1u) * kernel::RESOCT_PAGE_BLOCK_ENTRIES);
  }
  run.working_set_bricks = report.stats.working_set_bricks;
  run.working_set_bytes = report.stats.working_set_bytes;
  const BrickLoaderStats loads = inspect::loader(renderer).stats();
  run.bricks_loaded = loads.loads;
  run.host_hits = loads.host_hits;
  if (run.converged && steady_frames > 0) {
    const auto t0 = Clock::now();
    for (std::uint32_t i = 0; i < steady_frames; ++i) report = renderer.render_frame(scene);
    run.ms_steady = std::chrono::duration<double, std::milli>(Clock::now() - t0).count() /
                    double(steady_frames);
  }
  run.last = report.stats;
  run.image = std::move(report.image);
  return run;
}

}  // namespace resoct::bench
