// resoct.Renderer and resoct.Frame: a renderer over a source with a backend chosen by name
// ("cpu" or "vulkan"), the viewer options as keyword arguments, and frames whose pixels are
// numpy views of the frame's own buffers (no copy; each frame has buffers of its own).
#include <memory>
#include <optional>
#include <string>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "frame_stats.hpp"
#include "numpy_image.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/base/error.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#ifdef RESOCT_PYTHON_WITH_VULKAN
#include "resoct/vulkan/vulkan_backend.hpp"
#endif

namespace resoct::python {

namespace {

struct Frame {
  FrameReport report;
  std::uint32_t frames = 1;  // frames rendered to get it (render_until_converged)
};

std::unique_ptr<Backend> make_named_backend(const std::string& name, int threads,
                                            const std::string& device, bool validation) {
  if (name == "cpu") return cpu::make_backend(threads);
#ifdef RESOCT_PYTHON_WITH_VULKAN
  if (name == "vulkan") return vk::make_backend(BackendOptions{0, device, validation});
  throw invalid_parameter("backend", "'" + name + "' is not one of cpu, vulkan");
#else
  (void)device;
  (void)validation;
  throw invalid_parameter("backend", "'" + name + "' is not one of cpu (this build has no Vulkan)");
#endif
}

std::uint64_t mebibytes(std::uint64_t mb, const char* parameter) {
  if (mb == 0 || mb > (std::uint64_t(1) << 24))
    throw invalid_parameter(parameter, "must be 1..2^24");
  return mb << 20;
}

std::unique_ptr<Renderer> make_renderer(std::shared_ptr<BrickSource> source,
                                        const std::string& backend, int threads,
                                        const std::string& device, bool validation,
                                        std::uint64_t device_cache_mb, std::uint64_t host_cache_mb,
                                        std::optional<std::uint32_t> loader_threads,
                                        const std::string& mode, const std::string& strategy,
                                        const std::string& eviction,
                                        const std::string& host_eviction, const std::string& output,
                                        std::uint32_t prefetch_frames, bool brick_errors) {
  ViewerOptions o;
  o.device_cache_bytes = mebibytes(device_cache_mb, "device_cache_mb");
  o.host_cache_bytes = mebibytes(host_cache_mb, "host_cache_mb");
  if (loader_threads) o.loader_threads = *loader_threads;
  o.mode = parse_render_mode(mode);
  o.strategy = parse_request_strategy(strategy);
  o.eviction = parse_eviction(eviction);
  o.host_eviction = parse_eviction(host_eviction, "host_eviction");
  o.output = parse_frame_output(output);
  if (o.output == FrameOutput::device) {
    // Python reads frames as numpy arrays: an image left in GPU memory would arrive empty.
    throw invalid_parameter("output",
                            "\"device\" leaves the image in GPU memory, which Python "
                            "cannot read; use \"rgba32f\", \"rgba8\" or \"both\"");
  }
  o.prefetch.lookahead_frames = prefetch_frames;
  o.brick_errors = brick_errors;
  o.validate();  // before a device is created for options that would be refused anyway
  std::unique_ptr<Backend> b = make_named_backend(backend, threads, device, validation);
  py::gil_scoped_release release;  // configuring a device allocates its memory
  return std::make_unique<Renderer>(std::move(source), std::move(b), o);
}

Frame render_frame(Renderer& r, py::handle scene) {
  Scene storage;
  const Scene& s = scene_arg(scene, storage);
  Frame f;
  py::gil_scoped_release release;
  r.render_frame(s, f.report);
  return f;
}

Frame render_until_converged(Renderer& r, py::handle scene, std::uint32_t max_frames) {
  Scene storage;
  const Scene& s = scene_arg(scene, storage);
  Frame f;
  {
    py::gil_scoped_release release;
    ConvergeReport c = r.render_until_converged(s, max_frames);
    f.report = std::move(c.last);
    f.frames = c.frames;
  }
  return f;
}

py::list failure_messages(const FrameReport& report) {
  py::list out;
  for (const LoadFailure& f : report.failures) out.append(f.message);
  return out;
}

}  // namespace

void bind_renderer(py::module_& m) {
  py::class_<Frame>(m, "Frame", "One rendered frame: pixels, convergence and statistics.")
      .def_property_readonly(
          "image",
          [](py::object self) -> py::object {
            const Image& image = self.cast<const Frame&>().report.image;
            if (image.width() == 0) return py::none();
            return float_view(image, self);
          },
          "float32 RGBA (straight alpha) shaped (height, width, 4), or None with output='rgba8'.")
      .def_property_readonly(
          "rgba8",
          [](py::object self) -> py::object {
            const FrameReport& r = self.cast<const Frame&>().report;
            if (r.rgba8.empty()) return py::none();
            return rgba8_view(r.rgba8, r.width, r.height, self);
          },
          "uint8 RGBA shaped (height, width, 4), or None with output='rgba32f'.")
      .def_property_readonly("width", [](const Frame& f) { return f.report.width; })
      .def_property_readonly("height", [](const Frame& f) { return f.report.height; })
      .def_property_readonly(
          "converged", [](const Frame& f) { return f.report.converged; },
          "True when the frame needed nothing it did not have.")
      .def_property_readonly(
          "frames", [](const Frame& f) { return f.frames; },
          "Frames rendered to get this one (1 for render_frame).")
      .def_property_readonly("stats", [](const Frame& f) { return stats_dict(f.report.stats); })
      .def_property_readonly(
          "failures", [](const Frame& f) { return failure_messages(f.report); },
          "Messages of the bricks that failed to load (reported once each).");

  py::class_<Renderer>(m, "Renderer",
                       "Renders scenes of one source, loading bricks as views need them. Not "
                       "thread-safe: drive a renderer from one thread.")
      .def(py::init(&make_renderer), py::arg("source"), py::arg("backend") = "cpu", py::kw_only(),
           py::arg("threads") = 0, py::arg("device") = "", py::arg("validation") = false,
           py::arg("device_cache_mb") = 512u, py::arg("host_cache_mb") = 1024u,
           py::arg("loader_threads") = py::none(), py::arg("mode") = "residency",
           py::arg("strategy") = "greedy", py::arg("eviction") = "lru",
           py::arg("host_eviction") = "lru", py::arg("output") = "rgba32f",
           py::arg("prefetch_frames") = 0u, py::arg("brick_errors") = false,
           "backend: 'cpu' (threads: 0 = all cores) or 'vulkan' (device: index or name "
           "substring, '' = best; validation: Khronos validation layers). loader_threads: None "
           "= one per core, 0 = load inside render calls (deterministic). mode: residency, "
           "pagetable or octree; strategy: greedy or global; eviction, host_eviction: lru, "
           "octreemizer (the published priority: distance to the wish list) or "
           "octreemizer-camera (distance from the eye); output: rgba32f, rgba8 or both; "
           "prefetch_frames: camera lookahead; brick_errors: measure coarse bricks' errors "
           "while loading, for scenes with lod_error_color (error-bounded LOD).")
      .def("render_frame", &render_frame, py::arg("scene"),
           "Renders one frame of a Scene (or scene dict) and returns a Frame.")
      .def("render_until_converged", &render_until_converged, py::arg("scene"),
           py::arg("max_frames") = 1000u,
           "Renders until a frame converged or max_frames were rendered; returns the last "
           "Frame, its failures those of all frames.")
      .def("wait_for_loads", &Renderer::wait_for_loads, py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("backend",
                             [](Renderer& r) { return std::string(inspect::backend(r).name()); })
      .def_property_readonly("timepoint", &Renderer::timepoint)
      .def_property_readonly("timepoints", &Renderer::timepoints)
      .def_property_readonly("frame_index", &Renderer::frame_index);
}

}  // namespace resoct::python
