// FrameStats as a dict: every field by its C++ name, the backend's under "backend", plus the
// per-ray averages resoct-render writes to stats.json.
#include "frame_stats.hpp"

namespace resoct::python {

namespace {

py::dict backend_dict(const BackendStats& b) {
  py::dict d;
  d["rays"] = b.rays;
  d["samples"] = b.samples;
  d["nodes_visited"] = b.nodes_visited;
  d["brick_accesses"] = b.brick_accesses;
  d["iterations"] = b.iterations;
  d["cap_hits"] = b.cap_hits;
  d["request_inserts"] = b.request_inserts;
  d["requests_dropped"] = b.requests_dropped;
  d["gradient_evals"] = b.gradient_evals;
  d["shadow_rays"] = b.shadow_rays;
  d["distance_skipped"] = b.distance_skipped;
  d["distance_marched"] = b.distance_marched;
  d["ms_render"] = b.ms_render;
  d["ms_device"] = b.ms_device;
  return d;
}

}  // namespace

py::dict stats_dict(const FrameStats& s) {
  py::dict d;
  d["frame_index"] = s.frame_index;
  d["backend"] = backend_dict(s.backend);
  d["samples_per_ray"] = per_ray(s.backend.samples, s.backend);
  d["nodes_per_ray"] = per_ray(s.backend.nodes_visited, s.backend);
  d["iterations_per_ray"] = per_ray(s.backend.iterations, s.backend);
  d["brick_accesses_per_ray"] = per_ray(s.backend.brick_accesses, s.backend);
  d["brick_requests"] = s.brick_requests;
  d["stale_requests"] = s.stale_requests;
  d["failed_requests"] = s.failed_requests;
  d["ancestor_requests"] = s.ancestor_requests;
  d["node_requests"] = s.node_requests;
  d["nodes_answered"] = s.nodes_answered;
  d["loads_queued"] = s.loads_queued;
  d["loads_in_flight"] = s.loads_in_flight;
  d["prefetch_queued"] = s.prefetch_queued;
  d["prefetch_next_timepoint"] = s.prefetch_next_timepoint;
  d["timepoint"] = s.timepoint;
  d["timepoint_switched"] = s.timepoint_switched;
  d["bricks_uploaded"] = s.bricks_uploaded;
  d["bytes_uploaded"] = s.bytes_uploaded;
  d["pages_empty"] = s.pages_empty;
  d["pages_homogeneous"] = s.pages_homogeneous;
  d["uploads_deferred"] = s.uploads_deferred;
  d["evictions"] = s.evictions;
  d["insert_failures"] = s.insert_failures;
  d["stale_loads"] = s.stale_loads;
  d["new_failures"] = s.new_failures;
  d["page_deltas"] = s.page_deltas;
  d["node_deltas"] = s.node_deltas;
  d["pages_full"] = s.pages_full;
  d["block_misses"] = s.block_misses;
  d["page_blocks"] = s.page_blocks;
  d["nodes_full"] = s.nodes_full;
  d["working_set_bricks"] = s.working_set_bricks;
  d["working_set_bytes"] = s.working_set_bytes;
  d["resident_bricks"] = s.resident_bricks;
  d["ms_upload"] = s.ms_upload;
  d["ms_update"] = s.ms_update;
  d["ms_render"] = s.ms_render;
  d["ms_requests"] = s.ms_requests;
  d["ms_frame"] = s.ms_frame;
  return d;
}

}  // namespace resoct::python
