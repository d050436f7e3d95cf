#include "resoct/render/renderer.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include <glm/vec3.hpp>

#include "renderer_impl.hpp"
#include "resoct/base/error.hpp"
#include "resoct/engine/prefetch.hpp"
#include "resoct/engine/request_set.hpp"
#include "resoct/render/frame_tables.hpp"
#include "resoct/sources/brick_error.hpp"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct {

namespace {

using Clock = std::chrono::steady_clock;
using detail::page_unmapped;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace

Renderer::~Renderer() = default;

std::uint32_t Renderer::timepoint() const noexcept {
  return impl_->timepoint_;
}
std::uint32_t Renderer::timepoints() const noexcept {
  return impl_->timepoints();
}
void Renderer::wait_for_loads() {
  impl_->loader_->wait_idle();
}
void Renderer::set_failure_callback(std::function<void(const LoadFailure&)> fn) {
  impl_->on_failure_ = std::move(fn);
}
const RendererOptions& Renderer::options() const noexcept {
  return impl_->options_;
}
const BrickSource& Renderer::source() const noexcept {
  return *impl_->source_;
}
const BrickHierarchy& Renderer::hierarchy() const noexcept {
  return impl_->hierarchy_;
}
std::uint64_t Renderer::frame_index() const noexcept {
  return impl_->frame_;
}

void Renderer::Impl::assign_channels(const Scene& scene) {
  // Load priority among channels: ascending importance, ties in scene order.
  std::vector<std::size_t> order(scene.channels.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return scene.channels[a].importance < scene.channels[b].importance;
  });
  channel_rank_.assign(hierarchy_.volume().channels, std::uint32_t(order.size()));
  for (std::size_t r = 0; r < order.size(); ++r) {
    channel_rank_[scene.channels[order[r]].channel] = std::uint32_t(r);
  }

  const std::uint32_t slots = channels_.slot_count();
  std::vector<bool> wanted_slot(slots, false);
  std::vector<std::uint32_t> missing;
  for (const ChannelSettings& c : scene.channels) {
    if (auto s = channels_.slot_of(c.channel)) {
      wanted_slot[*s] = true;
    } else {
      missing.push_back(c.channel);
    }
  }
  // Slots of channels the scene no longer shows keep their bricks until a new channel needs the
  // slot, so toggling a channel off and on again costs nothing. Unassigned slots go first.
  std::vector<std::uint32_t> free_slots;
  for (std::uint32_t s = 0; s < slots; ++s) {
    if (!wanted_slot[s] && !channels_.channel(s)) free_slots.push_back(s);
  }
  for (std::uint32_t s = 0; s < slots; ++s) {
    if (!wanted_slot[s] && channels_.channel(s)) free_slots.push_back(s);
  }
  for (std::size_t i = 0; i < missing.size(); ++i) {
    const std::uint32_t slot = free_slots.at(i);  // count checked by render_frame
    SlotRemap remap = channels_.assign(slot, missing[i], pages_);
    for (std::uint32_t cs : remap.released_cache_slots) cache_->release(cs);
    octree_->remap_slot(slot, hierarchy_.volume().range(missing[i]));
  }
}

void Renderer::Impl::switch_timepoint(std::uint32_t t) {
  // Opened first: if opening fails nothing has changed yet.
  std::shared_ptr<const BrickSource> next = loader_->timepoint_sources().at(t);
  loader_->set_timepoint(t);
  timepoint_ = t;
  timepoint_source_ = std::move(next);
  // Everything on the device and in the octree describes the old timepoint's voxels: page
  // entries (MAPPED, and EMPTY / HOMOGENEOUS values), residency and node metadata (value ranges
  // and occupancy that empty-space skipping trusts). Reassigning every slot to its channel is
  // the remap path a channel change takes: it clears the slot's page tables, releases its cache
  // slots and starts a new epoch, and remap_slot forgets the slot's node metadata, which the
  // device then requests again and answer_nodes() takes from the new timepoint's source.
  for (std::uint32_t s = 0; s < channels_.slot_count(); ++s) {
    const auto ch = channels_.channel(s);
    if (!ch) continue;
    for (const std::optional<std::uint32_t> c : {std::optional<std::uint32_t>(), ch}) {
      const SlotRemap remap = channels_.assign(s, c, pages_);
      for (std::uint32_t cs : remap.released_cache_slots) cache_->release(cs);
    }
    octree_->remap_slot(s, hierarchy_.volume().range(*ch));
  }
  // Loaded or requested for the old timepoint: never applied.
  staged_.clear();
  waiting_since_.clear();
  pending_nodes_.clear();
}

void Renderer::Impl::evict(BrickKey key) {
  const auto addr = channels_.address_of(key);
  if (!addr) return;  // released with its slot already
  pages_.set_unmapped(*addr);
  octree_->brick_evicted(addr->slot, addr->level, addr->brick);
}

bool Renderer::Impl::apply_one(const LoadedBrick& b, FrameStats& stats) {
  const HostBrick& hb = *b.brick;
  const PageAddress addr = *channels_.address_of(hb.key);
  if (hb.meta.constant) {
    // A brick of only NaN (min = +inf) has nothing to sample either: EMPTY, marked as holding no
    // finite value so that it stays transparent where the transfer function shows 0.
    if (!(hb.meta.min <= hb.meta.max)) {
      pages_.set_no_finite(addr);
      ++stats.pages_empty;
    } else if (hb.meta.all_zero()) {
      pages_.set_empty(addr);
      ++stats.pages_empty;
    } else {
      pages_.set_homogeneous(addr, hb.meta.min, hierarchy_.volume().range(hb.key.channel()),
                             brick_error_code(hb.error));
      ++stats.pages_homogeneous;
    }
    octree_->brick_added(addr.slot, addr.level, addr.brick);
    if (addr.level == 0) octree_->metadata_from_constant_brick(addr.slot, addr.brick, hb.meta);
    return true;
  }
  const auto ins = cache_->insert(hb.key);
  if (!ins) {
    ++stats.insert_failures;
    return false;
  }
  if (ins->evicted) {
    evict(*ins->evicted);
    ++stats.evictions;
  }
  pages_.set_mapped(addr, ins->slot, brick_error_code(hb.error));
  octree_->brick_added(addr.slot, addr.level, addr.brick);
  // A level-0 brick's voxels give its leaves exact culling metadata, often much tighter than the
  // source's region answer (docs/residency-octree.md §4). The loader scanned them on its thread
  // (LoadedBrick::leaves); a brick it did not scan for these leaves is scanned here.
  if (addr.level == 0) {
    if (b.leaf_size == layout_.leaf_size()) {
      octree_->leaf_metadata(addr.slot, addr.brick, b.leaves);
    } else {
      octree_->metadata_from_brick(addr.slot, 0, addr.brick, hb.voxels);
    }
  }
  uploads_.push_back(BrickUpload{ins->slot, hb.voxels});
  upload_data_.push_back(b.brick);
  ++stats.bricks_uploaded;
  stats.bytes_uploaded += hb.voxels.size();
  return true;
}

void Renderer::Impl::apply_loaded(FrameStats& stats) {
  std::vector<LoadedBrick> fresh = loader_->take_ready();
  std::unordered_set<BrickKey> seen;
  std::vector<LoadedBrick> all;
  all.reserve(staged_.size() + fresh.size());
  for (auto* list : {&staged_, &fresh}) {
    for (LoadedBrick& b : *list) {
      if (seen.insert(b.brick->key).second) all.push_back(std::move(b));
    }
  }
  staged_.clear();
  std::sort(all.begin(), all.end(), [](const LoadedBrick& a, const LoadedBrick& b) {
    return load_before(a.request(), b.request());
  });

  // Constant bricks only change a page entry, so they bypass the upload budget; the others are
  // admitted in priority order while the bricks and bytes of the budget last.
  std::vector<UploadCandidate> candidates;
  std::vector<const LoadedBrick*> candidate_bricks;
  for (const LoadedBrick& b : all) {
    const auto addr = channels_.address_of(b.brick->key);
    // The loader delivers only the current timepoint (it drops stale loads); checked here too
    // because a brick of another timepoint must never reach the image.
    if (!addr || !page_unmapped(pages_.entry(*addr)) || b.brick->timepoint != timepoint_) {
      ++stats.stale_loads;  // channel left the visible slots, or mapped meanwhile
      continue;
    }
    if (b.brick->meta.constant) {
      apply_one(b, stats);
      continue;
    }
    candidates.push_back(UploadCandidate{b.brick->key, cache_->slot_bytes()});
    candidate_bricks.push_back(&b);
  }
  const UploadPlan plan = plan_uploads(candidates, options_.upload_budget);
  std::size_t i = 0;
  for (; i < plan.admitted.size(); ++i) {
    // Every slot pinned: the rest waits for pins to expire (uploads pin for ttl frames only).
    if (!apply_one(*candidate_bricks[i], stats)) break;
  }
  for (; i < candidate_bricks.size(); ++i) staged_.push_back(*candidate_bricks[i]);
  // Waiting bricks beyond what the cache could hold are dropped (worst first); they stay in the
  // host cache, so a renewed request is cheap.
  const std::size_t keep = std::max<std::size_t>(cache_->slot_count(), 64);
  if (staged_.size() > keep) staged_.resize(keep);
  stats.uploads_deferred = staged_.size();
}

void Renderer::Impl::answer_nodes(FrameStats& stats) {
  std::uint64_t answered = 0;
  for (std::uint32_t node : pending_nodes_) {
    if (node >= layout_.node_count()) continue;  // device data is not trusted
    const Box3 box = layout_.sampling_support(node);
    if (box.empty()) continue;
    for (std::uint32_t s = 0; s < channels_.slot_count(); ++s) {
      const auto ch = channels_.channel(s);
      if (!ch) continue;
      if (answered >= options_.max_node_answers) break;
      octree_->node_metadata(s, node, timepoint_source_->region_meta(*ch, box));
      ++answered;
    }
    if (answered >= options_.max_node_answers) break;
  }
  pending_nodes_.clear();
  stats.nodes_answered = answered;
}

void Renderer::Impl::send_update(FrameStats& stats) {
  FrameUpdate u;
  u.bricks = uploads_;
  const PageTableDeltas page_deltas = pages_.take_deltas();
  // Past a quarter of the words a full upload is cheaper than scattering deltas.
  const std::size_t words = pages_.pool().size() + pages_.directory().size();
  if (send_full_ || page_deltas.pool.size() + page_deltas.directory.size() > words / 4) {
    u.pages_full = true;
    u.all_pages = pages_.pool();
    u.all_directory = pages_.directory();
    u.directory_offsets = pages_.directory_offsets();
    stats.page_deltas = words;
  } else {
    u.page_deltas = page_deltas.pool;
    u.directory_deltas = page_deltas.directory;
    stats.page_deltas = page_deltas.pool.size() + page_deltas.directory.size();
  }
  const OctreeDeltas node_deltas = octree_->take_deltas();
  visible_subtrees_.note_sent(node_deltas, send_full_ || node_deltas.full, octree_->slot_count());
  if (send_full_ || node_deltas.full) {
    u.nodes_full = true;
    u.all_nodes = octree_->words();
    stats.node_deltas = octree_->words().size();
  } else {
    u.node_deltas = node_deltas.words;
    stats.node_deltas = node_deltas.words.size();
  }
  stats.pages_full = u.pages_full;
  stats.nodes_full = u.nodes_full;
  backend_->update(u);
  send_full_ = false;
  uploads_.clear();
  upload_data_.clear();
}

bool Renderer::Impl::handle_requests(const FrameResult& result, std::uint64_t epoch,
                                     FrameStats& stats) {
  const ResolvedRequests resolved = channels_.resolve(result.brick_requests, epoch, pages_);
  stats.brick_requests = result.brick_requests.size();
  stats.stale_requests = resolved.stale;
  stats.node_requests = result.node_requests.size();

  std::unordered_set<BrickKey> skip;
  for (const LoadedBrick& b : staged_) skip.insert(b.brick->key);
  std::vector<LoadRequest> wanted;
  std::unordered_map<BrickKey, std::uint64_t> still_waiting;
  bool outstanding = false;
  const auto available = [this](const PageAddress& a) { return !page_unmapped(pages_.entry(a)); };
  for (std::size_t i = 0; i < resolved.bricks.size(); ++i) {
    const BrickKey key = resolved.bricks[i];
    if (loader_->has_failed(key)) {
      ++stats.failed_requests;
      continue;
    }
    outstanding = true;
    if (uses_wish_list()) wish_keys_.push_back(key);
    const PageAddress target = *channels_.address_of(key);
    const auto chain = bricks_to_request(hierarchy_, target, options_.strategy, available);
    for (std::size_t j = 0; j < chain.size(); ++j) {
      const BrickKey k(chain[j].level, key.channel(), chain[j].brick);
      if (j > 0 && loader_->has_failed(k)) continue;
      if (!page_unmapped(pages_.entry(chain[j])) || !skip.insert(k).second) continue;
      const auto w = waiting_since_.find(k);
      const std::uint64_t since = w == waiting_since_.end() ? frame_ : w->second;
      still_waiting.emplace(k, since);
      wanted.push_back(LoadRequest{k, resolved.hits[i], since, channel_rank_[key.channel()]});
      if (j > 0) ++stats.ancestor_requests;
    }
  }
  // Allocated at the start of the next frame, with the other page-table changes, so that the
  // device mirrors the host between frames (allocation may reclaim blocks).
  pending_blocks_ = resolved.block_misses;
  stats.block_misses = resolved.block_misses.size();
  if (!resolved.block_misses.empty()) outstanding = true;
  waiting_since_ = std::move(still_waiting);
  loader_->request(wanted);
  sync_loaded_ = 0;
  if (loader_->thread_count() == 0) {
    const std::uint64_t n =
        std::min<std::uint64_t>(wanted.size(), options_.upload_budget.max_bricks);
    sync_loaded_ = loader_->run_queued(std::size_t(n));
  }
  stats.loads_queued = loader_->queued();
  stats.loads_in_flight = loader_->in_flight();

  pending_nodes_.clear();
  for (const Request& r : result.node_requests) pending_nodes_.push_back(r.key);
  return outstanding || !pending_nodes_.empty() || result.stats.requests_dropped != 0;
}

bool Renderer::Impl::uses_wish_list() const noexcept {
  return options_.eviction == Eviction::octreemizer ||
         options_.host_eviction == Eviction::octreemizer;
}

void Renderer::Impl::publish_wish_list() {
  auto tree = std::make_shared<WishListDistance>(hierarchy_);
  tree->assign(wish_keys_);
  {
    std::lock_guard lock(wish_list_->mutex);
    wish_list_->tree = std::move(tree);
  }
  // Every resident brick's d may have changed: the policies re-read them before their next
  // victim (not now, so a frame that evicts nothing pays nothing).
  cache_->policy().distances_changed();
  loader_->host_cache().distances_changed();
}

void Renderer::Impl::prefetch_next_timepoint(const Scene& scene, std::size_t max,
                                             std::vector<TimedBrickKey>& keys) {
  const std::uint32_t next = (timepoint_ + 1) % timepoints();
  if (next == timepoint_) return;
  // Only what would still have to be read. The device holds nothing of another timepoint, so
  // the host cache (and earlier failures, which the loader reports) decide alone.
  const auto want = [&](BrickKey k) { return !loader_->host_cache().contains(k, next); };
  try {
    for (const BrickKey k : view_bricks(hierarchy_, scene, max, want)) {
      keys.push_back(TimedBrickKey{k, next});
    }
  } catch (const Error&) {
    // A camera view_bricks cannot enumerate renders nothing either: nothing to prefetch.
  }
}

void Renderer::Impl::prefetch(const Scene& scene, FrameStats& stats) {
  predictor_.observe(scene.camera);
  const PrefetchOptions& po = options_.prefetch;
  if (po.lookahead_frames == 0 && !po.next_timepoint) return;
  const std::vector<Camera> poses = predictor_.predict(po.lookahead_frames);
  const std::uint64_t brick_bytes =
      hierarchy_.layout().padded_voxels() * voxel_size(hierarchy_.volume().type);
  const std::size_t max =
      std::size_t(std::min<std::uint64_t>(po.max_bricks, po.max_bytes / brick_bytes));
  std::vector<BrickKey> keys;
  std::unordered_set<BrickKey> seen;
  // Only what would still have to be read: not on the device, not in the host cache, not failed.
  const auto want = [&](BrickKey k) {
    const auto addr = channels_.address_of(k);
    if (!addr || !page_unmapped(pages_.entry(*addr))) return false;
    if (loader_->has_failed(k) || loader_->host_cache().contains(k, timepoint_)) return false;
    return seen.insert(k).second;
  };
  Scene predicted = scene;
  for (const Camera& c : poses) {
    if (keys.size() >= max) break;
    predicted.camera = c;
    try {
      const std::vector<BrickKey> more =
          view_bricks(hierarchy_, predicted, max - keys.size(), want);
      keys.insert(keys.end(), more.begin(), more.end());
    } catch (const Error&) {
      break;  // the extrapolated camera degenerated (eye on target, up along the view)
    }
  }
  std::vector<TimedBrickKey> timed;
  for (const BrickKey k : keys) timed.push_back(TimedBrickKey{k, timepoint_});
  // The next timepoint's bricks come after the current one's: they matter only after a switch.
  if (po.next_timepoint) prefetch_next_timepoint(scene, max, timed);
  stats.prefetch_next_timepoint = timed.size() - keys.size();
  // Replaces the previous frame's prefetches: the prediction moved on.
  loader_->prefetch(std::span<const TimedBrickKey>(timed));
  if (loader_->thread_count() == 0 && loader_->queued() == 0) {
    // Synchronous loading stands for a loader that reads the brick budget per frame: prefetches
    // take what the requests left of it, and only when no request waits (a worker thread takes a
    // prefetch only then too), so a frame never reads more than the budget.
    const std::size_t left = std::size_t(options_.upload_budget.max_bricks) - sync_loaded_;
    loader_->run_prefetch(std::min(timed.size(), left));
  }
  stats.prefetch_queued = timed.size();
}

void Renderer::Impl::report_failures(FrameReport& report) {
  report.failures = loader_->take_failures();
  report.stats.new_failures = report.failures.size();
  if (on_failure_) {
    for (const LoadFailure& f : report.failures) on_failure_(f);
  }
}

const FrameTables& Renderer::Impl::frame_tables(const Scene& scene, const FrameJitter& jitter) {
  FrameOptions fo;
  fo.jitter = jitter;
  fo.mode = options_.mode;
  fo.frame_index = std::uint32_t(frame_);
  fo.request_strategy = options_.strategy;
  fo.start_depth = options_.start_depth;
  fo.max_iterations = options_.max_iterations;
  // Rebuilt every frame into the same tables: no per-frame allocation, and only the LUTs of
  // transfer functions that changed are computed again (FrameTables::lut_sources).
  build_frame_tables(scene, hierarchy_, layout_, channels_, fo, tables_);
  tables_.image_to_host = options_.output != FrameOutput::device;
  visible_subtrees_.refresh(*octree_, options_.mode, options_.skip_min_samples, tables_);
  return tables_;
}

FrameReport Renderer::render_frame(const Scene& scene) {
  FrameReport report;
  render_frame(scene, report);
  return report;
}

void Renderer::Impl::take_pixels(FrameReport& report) {
  const Image& rendered = result_.image;
  report.device_image = result_.device_image;
  if (result_.device_image.handle != 0) {
    // Output device on a device backend: the pixels stay there; nothing is copied.
    report.width = result_.device_image.width;
    report.height = result_.device_image.height;
    report.image = Image();
    report.rgba8.clear();
    return;
  }
  report.width = rendered.width();
  report.height = rendered.height();
  // Output device on a host backend (CPU) gives the float image, as rgba32f does.
  if (options_.output == FrameOutput::rgba32f || options_.output == FrameOutput::device) {
    report.rgba8.clear();
  } else {
    rendered.to_rgba8(report.rgba8);
  }
  if (options_.output == FrameOutput::rgba8) {
    report.image = Image();  // the float pixels stay with the backend, which renders into them
  } else {
    // The backend renders the next frame into the report's previous buffer (backends reuse an
    // image of the right size), so two buffers alternate instead of one being made per frame.
    std::swap(report.image, result_.image);
  }
}

void Renderer::render_frame(const Scene& scene, FrameReport& report) {
  impl_->render_frame(scene, report, FrameJitter{});
}

void Renderer::render_frame(const Scene& scene, FrameReport& report, const FrameJitter& jitter) {
  impl_->render_frame(scene, report, jitter);
}

void Renderer::Impl::render_frame(const Scene& scene, FrameReport& report,
                                  const FrameJitter& jitter) {
  const auto t_frame = Clock::now();
  scene.validate(hierarchy_.volume(), timepoints(), "scene");
  jitter.validate();
  if (scene.channels.size() > channels_.slot_count()) {
    throw invalid_parameter("scene", std::to_string(scene.channels.size()) +
                                         " channels exceed the renderer's " +
                                         std::to_string(channels_.slot_count()) + " visible slots");
  }
  if (scene.lod_error_color > 0.0 && !options_.brick_errors) {
    throw invalid_parameter("scene.lod_error_color",
                            "error-bounded LOD needs bricks with measured errors: create the "
                            "renderer with ViewerOptions::brick_errors (resoct-render: "
                            "--lod-error-color sets it)");
  }
  ++frame_;
  cache_->begin_frame(frame_);
  {
    // Box space has its longest physical axis spanning [0, 1] (docs/scene.md).
    const glm::dvec3 phys = physical_size(hierarchy_.volume());
    camera_ = scene.camera.eye * std::max({phys.x, phys.y, phys.z});
    std::lock_guard lock(host_camera_->mutex);
    host_camera_->eye = camera_;
  }
  loader_->host_cache().set_frame(frame_);
  report.stats = FrameStats{};
  FrameStats& stats = report.stats;
  stats.frame_index = frame_;

  auto t = Clock::now();
  if (const std::uint32_t wanted = scene.timepoint.value_or(source_->timepoint());
      wanted != timepoint_) {
    switch_timepoint(wanted);
    stats.timepoint_switched = true;
  }
  stats.timepoint = timepoint_;
  assign_channels(scene);
  for (std::uint32_t d : pending_blocks_) pages_.allocate_block(d);
  pending_blocks_.clear();
  apply_loaded(stats);
  stats.page_blocks = pages_.allocated_blocks();
  answer_nodes(stats);
  stats.ms_upload = ms_since(t);

  t = Clock::now();
  send_update(stats);
  stats.ms_update = ms_since(t);

  t = Clock::now();
  const std::uint64_t epoch = channels_.epoch();
  backend_->render(frame_tables(scene, jitter), result_);
  stats.ms_render = ms_since(t);
  stats.backend = result_.stats;

  t = Clock::now();
  // Bricks sampled this frame count as used now; the next frame's uploads may evict them
  // (unless pinned by ttl), which is what lets a cache smaller than the working set progress.
  std::unordered_set<std::uint32_t> used;
  for (std::uint32_t s : result_.used_cache_slots) {
    if (s < cache_->slot_count() && cache_->key_of(s) && used.insert(s).second) cache_->touch(s);
  }
  stats.working_set_bricks = used.size();
  stats.working_set_bytes = used.size() * cache_->slot_bytes();
  wish_keys_.clear();
  if (uses_wish_list()) {
    for (std::uint32_t s : used) wish_keys_.push_back(*cache_->key_of(s));
  }
  const bool outstanding = handle_requests(result_, epoch, stats);
  if (uses_wish_list()) publish_wish_list();
  prefetch(scene, stats);
  stats.ms_requests = ms_since(t);
  report_failures(report);
  stats.resident_bricks = cache_->resident_count();

  report.converged =
      !outstanding && staged_.empty() && loader_->idle() && loader_->retries_pending() == 0;
  take_pixels(report);
  stats.ms_frame = ms_since(t_frame);
}

ConvergeReport Renderer::render_until_converged(const Scene& scene, std::uint32_t max_frames) {
  if (max_frames == 0) throw invalid_parameter("max_frames", "must be >= 1");
  ConvergeReport out;
  std::vector<LoadFailure> failures;
  for (out.frames = 1;; ++out.frames) {
    render_frame(scene, out.last);
    failures.insert(failures.end(), out.last.failures.begin(), out.last.failures.end());
    out.converged = out.last.converged;
    if (out.converged || out.frames >= max_frames) break;
    // With loader threads, waiting for the requested bricks makes every frame count instead of
    // re-rendering the same state while the loads run.
    impl_->loader_->wait_idle();
  }
  out.last.failures = std::move(failures);
  return out;
}

}  // namespace resoct
