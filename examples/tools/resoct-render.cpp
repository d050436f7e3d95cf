// resoct-render: renders a scene of a volume (brick store or procedural) with the residency
// octree renderer and writes the image as PNG and the frame statistics as JSON.
//
//   resoct-render --volume procedural:tubes --scene examples/scenes/tubes.json
//                 --out tubes.png --stats tubes.json --converge   (one command line)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/io/overview_hints.hpp"
#include "resoct/render/frame_accumulator.hpp"
#include "resoct/render/reference_renderer.hpp"
#include "resoct/render/reference_voxels.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/overview_scene.hpp"
#include "resoct/scene/scene.hpp"
#include "support/cli_parse.hpp"
#include "support/source_options.hpp"
#include "support/output_path.hpp"
#include "support/tool_main.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#ifdef RESOCT_RENDER_WITH_VULKAN
#include "resoct/vulkan/devices.hpp"
#include "resoct/vulkan/vulkan_backend.hpp"
#endif

namespace {

using namespace resoct;

struct Args {
  std::string volume;
  resoct::SourceOptions source;
  std::string scene;
  std::string backend = "cpu";
  std::string device;
  bool validation = false;
  bool list_devices = false;
  std::string mode = "residency";
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::string out;
  std::string stats;
  std::uint32_t frames = 0;
  bool converge = false;
  std::uint32_t accumulate = 0;  // --accumulate N: jittered frames averaged after convergence
  std::uint32_t max_frames = 1000;
  std::uint32_t steady_frames = 5;
  std::uint64_t cache_mb = 512;
  std::uint32_t threads = std::max(1u, std::thread::hardware_concurrency());
  std::string strategy = "greedy";
  std::uint32_t leaf = 16;
  float skip_min_samples = resoct::kDefaultSkipMinSamples;
  std::optional<double> lod_error_color;  // overrides the scene's (error-bounded LOD)
  std::uint32_t retry_failed_ms = 0;
  std::optional<std::uint32_t> timepoint;  // overrides the scene's
  std::string play;                        // "FIRST:LAST": one image per timepoint
  bool no_play_prefetch = false;
  // --report-accuracy: the dense reference of the same view (docs/tools.md).
  bool report_accuracy = false;
  double reference_step = 0.125;      // in reference steps (one level-0 voxel)
  std::uint64_t reference_mb = 4096;  // level 0 of the shown channels, as floats
};

/// The --out path of timepoint t while playing: "{t}" replaced by the timepoint.
std::string out_path_of(const std::string& pattern, std::uint32_t t) {
  std::string out = pattern;
  for (std::size_t p; (p = out.find("{t}")) != std::string::npos;) {
    out.replace(p, 3, std::to_string(t));
  }
  return out;
}

/// One converged (or frame-capped) image of one timepoint while playing.
struct PlayedTimepoint {
  std::uint32_t timepoint = 0;
  std::uint32_t frames = 0;
  bool converged = false;
  double ms = 0.0;  // wall time of its frames
};

/// Totals over all frames rendered.
struct Totals {
  std::uint64_t requests = 0;
  std::uint64_t dropped = 0;
  std::uint64_t cap_hits = 0;
  std::uint64_t uploaded = 0;
  std::uint64_t bytes_uploaded = 0;
  std::vector<LoadFailure> failures;
  /// Vulkan only: validation-layer warnings and errors (0 without --validation).
  std::optional<std::uint64_t> validation_messages;
  void add(const FrameReport& r) {
    requests += r.stats.brick_requests + r.stats.node_requests;
    dropped += r.stats.backend.requests_dropped;
    cap_hits += r.stats.backend.cap_hits;
    uploaded += r.stats.bricks_uploaded;
    bytes_uploaded += r.stats.bytes_uploaded;
    failures.insert(failures.end(), r.failures.begin(), r.failures.end());
  }
};

/// The dataset channels a scene shows, each once, ascending.
std::vector<std::uint32_t> shown_channels(const Scene& scene) {
  std::vector<std::uint32_t> shown;
  for (const ChannelSettings& c : scene.channels) shown.push_back(c.channel);
  std::sort(shown.begin(), shown.end());
  shown.erase(std::unique(shown.begin(), shown.end()), shown.end());
  return shown;
}

/// --report-accuracy: the scene rendered by the dense reference renderer (level 0, double
/// precision, steps of `reference_step` voxels, reference_renderer.hpp) from the source's level 0,
/// and the image's error against it, beside the frame time. Returns the "accuracy" stats object.
nlohmann::json report_accuracy(const Args& a, const Renderer& renderer, const Scene& scene,
                               const Image& image, double steady_ms) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  std::shared_ptr<const BrickSource> timepoint_source;
  const BrickSource* source = &renderer.source();
  if (renderer.timepoints() > 1) {
    timepoint_source = renderer.source().open_timepoint(renderer.timepoint());
    source = timepoint_source.get();
  }
  const std::vector<std::uint32_t> channels = shown_channels(scene);
  std::uint32_t last_percent = 0;
  const reference::VoxelFunction voxels = reference::level0_voxels(
      *source, channels, a.reference_mb << 20, "reference-mb",
      [&](std::uint64_t done, std::uint64_t total) {
        const auto percent = std::uint32_t(100 * done / total);
        if (percent / 25 != last_percent / 25 || done == total) {
          std::fprintf(stderr, "resoct-render: reading level 0 for the reference: %u%%\n", percent);
        }
        last_percent = percent;
      });
  const auto t1 = Clock::now();
  std::fprintf(stderr, "resoct-render: rendering the dense reference (%ux%u, step %g voxel)\n",
               scene.viewport.width, scene.viewport.height, a.reference_step);
  reference::ReferenceOptions ro;
  ro.step = a.reference_step;
  ro.threads = 0;
  const Image ref = reference::render_reference(scene, source->volume(), voxels, ro);
  const auto t2 = Clock::now();
  const ImageDiff d = compare_images(image, ref);
  const double max_rgb = std::max({d.max_abs.r, d.max_abs.g, d.max_abs.b});
  const double s_read = std::chrono::duration<double>(t1 - t0).count();
  const double s_render = std::chrono::duration<double>(t2 - t1).count();
  std::fprintf(stderr,
               "resoct-render: accuracy against the dense reference: RMSE %.3f/255, PSNR %.2f "
               "dB, max %.1f/255 (RGB) at %.2f ms/frame steady (reference: %.1f s reading, "
               "%.1f s rendering)\n",
               255.0 * d.rmse_rgb, d.psnr_rgb, 255.0 * max_rgb, steady_ms, s_read, s_render);
  nlohmann::json j;
  j["rmse_rgb"] = d.rmse_rgb;
  // JSON has no infinity: an identical image reports a PSNR of null.
  j["psnr_rgb_db"] = std::isfinite(d.psnr_rgb) ? nlohmann::json(d.psnr_rgb) : nlohmann::json();
  j["max_abs_rgb"] = max_rgb;
  j["max_abs_alpha"] = d.max_abs.a;
  j["reference_step"] = a.reference_step;
  j["reference_level"] = 0;
  j["ms_per_frame_steady"] = steady_ms;
  j["s_reference_read"] = s_read;
  j["s_reference_render"] = s_render;
  return j;
}

void write_stats(const std::string& path, const Args& a, const FrameReport& last,
                 std::uint32_t frames, bool converged, double steady_ms, std::uint32_t steady_count,
                 const Totals& t, const Renderer& r, const std::vector<PlayedTimepoint>& played,
                 const nlohmann::json& accuracy) {
  const FrameStats& s = last.stats;
  nlohmann::json j;
  j["volume"] = a.volume;
  j["scene"] = a.scene.empty() ? std::string("overview") : a.scene;
  j["backend"] = a.backend;
  j["mode"] = a.mode;
  j["strategy"] = a.strategy;
  j["width"] = last.image.width();
  j["height"] = last.image.height();
  j["frames"] = frames;
  j["converged"] = converged;
  j["ms_per_frame_steady"] = steady_ms;
  j["steady_frames"] = steady_count;
  j["ms_render_last"] = s.ms_render;
  j["ms_device_last"] = s.backend.ms_device;
  j["rays"] = s.backend.rays;
  j["samples_per_ray"] = per_ray(s.backend.samples, s.backend);
  j["nodes_per_ray"] = per_ray(s.backend.nodes_visited, s.backend);
  j["iterations_per_ray"] = per_ray(s.backend.iterations, s.backend);
  j["brick_accesses_per_ray"] = per_ray(s.backend.brick_accesses, s.backend);
  // Effects (last frame): gradients computed and shadow rays cast; 0 without effects.
  j["gradient_evals"] = s.backend.gradient_evals;
  j["shadow_rays"] = s.backend.shadow_rays;
  j["bricks_touched"] = s.working_set_bricks;
  j["working_set_bytes"] = s.working_set_bytes;
  j["resident_bricks"] = s.resident_bricks;
  j["cache_slots"] = inspect::cache(r).slot_count();
  j["requests_total"] = t.requests;
  j["requests_dropped"] = t.dropped;
  j["cap_hits"] = t.cap_hits;
  j["bricks_uploaded"] = t.uploaded;
  j["bytes_uploaded"] = t.bytes_uploaded;
  j["loads"] = inspect::loader(r).stats().loads;
  j["host_cache_hits"] = inspect::loader(r).stats().host_hits;
  // Time series (docs/renderer.md "Time series").
  const BrickLoaderStats ls = inspect::loader(r).stats();
  j["timepoint"] = r.timepoint();
  j["timepoints"] = r.timepoints();
  j["prefetched"] = ls.prefetched;
  j["prefetch_hits"] = ls.prefetch_hits;
  j["stale_loads_dropped"] = ls.stale_dropped;
  if (!a.play.empty()) {
    nlohmann::json p = nlohmann::json::array();
    for (const PlayedTimepoint& x : played) {
      p.push_back({{"timepoint", x.timepoint},
                   {"frames", x.frames},
                   {"converged", x.converged},
                   {"ms", x.ms}});
    }
    j["play"] = p;
  }
  nlohmann::json f = nlohmann::json::array();
  for (const LoadFailure& x : t.failures) f.push_back(x.message);
  j["load_failures"] = f;
  if (t.validation_messages) j["validation_messages"] = *t.validation_messages;
  if (!accuracy.is_null()) j["accuracy"] = accuracy;
  const std::string text = j.dump(2) + "\n";
  AtomicFileWriter w(path);
  w.append(std::as_bytes(std::span(text.data(), text.size())));
  w.commit();
}

#ifdef RESOCT_RENDER_WITH_VULKAN
int print_devices() {
  const auto devices = resoct::vk::list_devices();
  if (devices.empty()) std::printf("no Vulkan device\n");
  for (const auto& d : devices) {
    std::printf("%u: %s (%s, Vulkan %s, %.0f MiB device-local%s)\n", d.index, d.name.c_str(),
                d.type.c_str(), resoct::vk::api_version_string(d.api_version).c_str(),
                double(d.device_local_bytes) / 1048576.0,
                d.has_compute_queue ? "" : ", no compute");
  }
  return 0;
}
#endif

int run(const Args& a) {
#ifdef RESOCT_RENDER_WITH_VULKAN
  if (a.list_devices) return print_devices();
  resoct::vk::register_backend();
#else
  if (a.list_devices) throw invalid_parameter("list-devices", "this build has no Vulkan backend");
#endif
  if (a.volume.empty()) throw invalid_parameter("volume", "--volume is required");
  resoct::cpu::register_backend();
  RendererOptions o;
  o.backend = a.backend;
  o.backend_options.device = a.device;
  o.backend_options.validation = a.validation;
  o.mode = parse_render_mode(a.mode);
  o.strategy = parse_request_strategy(a.strategy);
  if (a.cache_mb == 0 || a.cache_mb > (std::uint64_t(1) << 24)) {
    throw invalid_parameter("cache-mb", "must be 1..2^24");
  }
  o.device_cache_bytes = a.cache_mb << 20;
  o.loader_threads = a.threads;
  o.retry_failed_after_ms = a.retry_failed_ms;
  if (a.leaf == 0) throw invalid_parameter("leaf", "must be > 0");
  o.leaf_size = glm::uvec3(a.leaf);
  if (!std::isfinite(a.skip_min_samples) || a.skip_min_samples < 0.0f) {
    throw invalid_parameter("skip-min-samples", "must be finite and >= 0");
  }
  o.skip_min_samples = a.skip_min_samples;
  if (a.accumulate > 4096) throw invalid_parameter("accumulate", "must be 0..4096");
  if (a.accumulate > 1 && !a.converge) {
    throw invalid_parameter("accumulate", "needs --converge (it averages the converged view)");
  }
  if (a.frames == 0 && !a.converge)
    throw invalid_parameter("frames", "give --frames N or --converge");
  if (a.lod_error_color && !(*a.lod_error_color >= 0.0 && *a.lod_error_color <= 1.0)) {
    throw invalid_parameter("lod-error-color", "must be in [0, 1]");
  }
  if (!(a.reference_step > 0.0 && a.reference_step <= 1.0)) {
    throw invalid_parameter("reference-step", "must be in (0, 1] voxel");
  }
  if (a.reference_mb == 0 || a.reference_mb > (std::uint64_t(1) << 24)) {
    throw invalid_parameter("reference-mb", "must be 1..2^24");
  }
  std::optional<std::pair<std::uint32_t, std::uint32_t>> play;
  if (!a.play.empty()) {
    play = resoct::tools::parse_index_range(a.play, "play");
    if (!a.out.empty() && a.out.find("{t}") == std::string::npos) {
      throw invalid_parameter("out", "with --play it must contain {t} (one image per timepoint)");
    }
    // While one timepoint is shown, the loader reads the next one's bricks into host memory.
    o.prefetch.next_timepoint = !a.no_play_prefetch;
  }
  // Both outputs are checked before rendering: a bad --stats path must not fail after the PNG
  // has already replaced an existing one, nor after minutes of rendering.
  if (!a.out.empty()) {
    resoct::tools::check_output_path("out", play ? out_path_of(a.out, play->first) : a.out);
  }
  if (!a.stats.empty()) resoct::tools::check_output_path("stats", a.stats);

  // A scene file is read before the volume is opened, so that a bad one fails at once.
  std::optional<Scene> from_file;
  if (!a.scene.empty()) from_file = load_scene(a.scene);
  // Error-bounded LOD needs the loader to measure every coarse brick's error.
  o.brick_errors = (a.lod_error_color && *a.lod_error_color > 0.0) ||
                   (from_file && from_file->lod_error_color > 0.0);
  Renderer renderer(std::shared_ptr<const BrickSource>(open_source(a.volume, {}, a.source)), o);
  // Without --scene, the volume's overview: the whole box in view, up to four channels in
  // distinct colours, each a ramp over its value range or, where the source's metadata has
  // them, its OMERO colour and window (overview_scene.hpp, io/overview_hints.hpp).
  Scene scene = from_file ? *from_file
                          : overview_scene(renderer.hierarchy().volume(), Viewport{},
                                           overview_hints(renderer.source()));
  if (a.width != 0) scene.viewport.width = a.width;
  if (a.height != 0) scene.viewport.height = a.height;
  if (a.lod_error_color) scene.lod_error_color = *a.lod_error_color;
  // Checked before rendering, naming the option rather than the scene field.
  const std::uint32_t timepoints = renderer.timepoints();
  const auto check_timepoint = [&](const char* option, std::uint32_t t) {
    if (t >= timepoints) {
      throw invalid_parameter(option, std::to_string(t) + " but " + a.volume + " has " +
                                          std::to_string(timepoints) + " timepoint" +
                                          (timepoints == 1 ? "" : "s") + " (0.." +
                                          std::to_string(timepoints - 1) + ")");
    }
  };
  if (a.timepoint) {
    check_timepoint("timepoint", *a.timepoint);
    scene.timepoint = *a.timepoint;
  }
  if (play) check_timepoint("play", play->second);
  // The reference models emission-absorption, shading, isosurfaces and projections, not shadows,
  // slice planes or a lens: refuse before rendering rather than report a meaningless error.
  if (a.report_accuracy) {
    const char* unmodelled = scene.has_effect(Effect::shadows) ? "shadows"
                             : !scene.slices.empty()           ? "slice planes"
                             : scene.lens                      ? "a lens"
                                                               : nullptr;
    if (unmodelled != nullptr) {
      throw invalid_parameter("report-accuracy", std::string("the dense reference does not "
                                                             "model the scene's ") +
                                                     unmodelled);
    }
    // Level 0 of the shown channels must fit the limit: checked now, not after the render.
    const VolumeDesc& v = renderer.hierarchy().volume();
    const long double need = (long double)v.extent.x * v.extent.y * v.extent.z * 4.0L *
                             (long double)shown_channels(scene).size();
    if (need > (long double)(a.reference_mb << 20)) {
      throw invalid_parameter("reference-mb",
                              "the dense reference needs " +
                                  std::to_string(std::uint64_t(need / 1048576.0L) + 1) +
                                  " MiB for level 0 of the shown channels; raise --reference-mb");
    }
  }
  renderer.set_failure_callback([](const LoadFailure& f) {
    std::fprintf(stderr, "resoct-render: warning: %s\n", f.message.c_str());
  });

  Totals totals;
  FrameReport last;
  std::uint32_t frames = 0;
  bool converged = false;
  auto frame = [&] {
    last = renderer.render_frame(scene);
    ++frames;
    totals.add(last);
    std::fprintf(stderr, "%s\n", format_frame_line(last.stats).c_str());
    return last.converged;
  };
  std::vector<double> ms;  // render_frame wall time of every frame
  // One image: until converged (capped by --max-frames) or exactly --frames frames.
  const auto render_image = [&] {
    const std::uint32_t start = frames;
    if (a.converge) {
      while (frames - start < a.max_frames && !(converged = frame())) {
        ms.push_back(last.stats.ms_frame);
        // Frames while loads run would only re-render the same state; wait for them.
        renderer.wait_for_loads();
      }
      ms.push_back(last.stats.ms_frame);
    } else {
      for (std::uint32_t i = 0; i < a.frames; ++i) {
        converged = frame();
        ms.push_back(last.stats.ms_frame);
      }
    }
  };
  std::vector<PlayedTimepoint> played;
  if (play) {
    for (std::uint32_t t = play->first;; ++t) {
      scene.timepoint = t;
      const std::size_t first_frame = ms.size();
      const std::uint32_t before = frames;
      render_image();
      PlayedTimepoint p{t, frames - before, converged, 0.0};
      for (std::size_t i = first_frame; i < ms.size(); ++i) p.ms += ms[i];
      played.push_back(p);
      std::fprintf(stderr, "resoct-render: timepoint %u: %u frames, %s\n", t, p.frames,
                   converged ? "converged" : "not converged");
      if (!a.out.empty()) write_png(last.image, out_path_of(a.out, t));
      if (t == play->second) break;
    }
  } else {
    render_image();
  }
  // --accumulate N: the converged frame and N - 1 jittered ones averaged (FrameAccumulator; the
  // average restarts if a jittered frame brings new bricks, as in resoct-view).
  std::optional<FrameAccumulator> acc;
  if (a.accumulate > 1 && !play) {
    acc.emplace(a.accumulate);
    acc->next(scene);
    acc->add(last.image, false);
    for (std::uint32_t i = 0; !acc->done() && i < 4 * a.accumulate + a.max_frames; ++i) {
      const FrameJitter j = acc->next(scene);
      renderer.render_frame(scene, last, j);
      ++frames;
      totals.add(last);
      std::fprintf(stderr, "%s\n", format_frame_line(last.stats).c_str());
      acc->add(last);
      if (!last.converged) renderer.wait_for_loads();
    }
    std::fprintf(stderr, "resoct-render: accumulated %u jittered frames\n", acc->frames());
  }
  // Steady state: extra frames after convergence, which load and upload nothing.
  for (std::uint32_t i = 0; a.converge && converged && i < a.steady_frames; ++i) {
    frame();
    ms.push_back(last.stats.ms_frame);
  }
  // ms_per_frame_steady: mean over the last steady_frames frames (the extra frames after
  // convergence with --converge); fewer when fewer were rendered.
  const std::size_t n = std::min<std::size_t>(ms.size(), a.steady_frames);
  double steady = 0.0;
  for (std::size_t i = ms.size() - n; i < ms.size(); ++i) steady += ms[i];
  if (n != 0) steady /= double(n);
  const std::uint32_t tail = std::uint32_t(n);

#ifdef RESOCT_RENDER_WITH_VULKAN
  if (const auto* vb =
          dynamic_cast<const resoct::vk::VulkanBackend*>(&inspect::backend(renderer))) {
    totals.validation_messages = vb->validation_messages();
    for (const std::string& m : vb->validation_log()) {
      std::fprintf(stderr, "resoct-render: validation: %s\n", m.c_str());
    }
    if (a.validation) {
      std::fprintf(stderr, "resoct-render: %llu validation messages\n",
                   static_cast<unsigned long long>(*totals.validation_messages));
    }
  }
#endif
  // The accuracy report comes first: if it fails, no output is left half written.
  nlohmann::json accuracy;
  if (a.report_accuracy) {
    accuracy = report_accuracy(a, renderer, scene, acc ? acc->image() : last.image, steady);
  }
  if (!a.out.empty() && !play) write_png(acc ? acc->image() : last.image, a.out);
  if (!a.stats.empty()) {
    write_stats(a.stats, a, last, frames, converged, steady, tail, totals, renderer, played,
                accuracy);
  }
  std::fprintf(stderr, "resoct-render: %u frames, %s, %.2f ms/frame steady\n", frames,
               converged ? "converged" : "not converged", steady);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Render a volume with the residency octree renderer"};
  Args a;
  app.add_option("--volume", a.volume, std::string(kSourceSpecForms) + " (required)");
  resoct::tools::add_source_options(app, a.source);
  app.add_option("--scene", a.scene,
                 "scene JSON (docs/scene.md); without it, an overview of the whole volume "
                 "(up to 4 channels, each a colour ramp over its value range, or its OMERO colour "
                 "and window where the metadata has them)");
  app.add_option("--backend", a.backend, "cpu | vulkan (when built) | registered backend name")
      ->capture_default_str();
  app.add_option("--device", a.device, "Vulkan device index or name substring");
  app.add_flag("--validation", a.validation, "Vulkan: enable the validation layers");
  app.add_flag("--list-devices", a.list_devices, "list Vulkan devices and exit");
  app.add_option("--mode", a.mode, "residency | pagetable | octree")->capture_default_str();
  app.add_option("--width", a.width, "image width (overrides the scene viewport)");
  app.add_option("--height", a.height, "image height (overrides the scene viewport)");
  app.add_option("--out", a.out, "output PNG");
  app.add_option("--stats", a.stats, "output statistics JSON");
  auto* frames = app.add_option("--frames", a.frames, "render exactly N frames");
  app.add_flag("--converge", a.converge, "render until converged (capped by --max-frames)")
      ->excludes(frames);
  app.add_option("--max-frames", a.max_frames, "frame cap of --converge")->capture_default_str();
  app.add_option("--accumulate", a.accumulate,
                 "with --converge: average the converged frame and N - 1 jittered ones "
                 "(docs/rendering.md \"Jittered accumulation\"; not with --play)");
  app.add_option("--steady-frames", a.steady_frames, "frames averaged for ms_per_frame_steady")
      ->capture_default_str();
  app.add_option("--cache-mb", a.cache_mb, "device brick cache in MiB")->capture_default_str();
  app.add_option("--threads", a.threads, "loader threads (0 = load synchronously)")
      ->capture_default_str();
  app.add_option("--strategy", a.strategy, "greedy | global")->capture_default_str();
  app.add_option("--retry-failed-ms", a.retry_failed_ms,
                 "load a brick that failed with a network or I/O error again after MS "
                 "(doubling up to 32x; 0 = never)")
      ->capture_default_str();
  app.add_option("--leaf", a.leaf, "residency octree leaf size (voxels per axis)")
      ->capture_default_str();
  app.add_option("--skip-min-samples", a.skip_min_samples,
                 "residency mode: descend below a node only where what it hides saves a ray more "
                 "than this many samples (0 = wherever anything is hidden; docs/rendering.md "
                 "\"Visible subtrees\")")
      ->capture_default_str();
  app.add_option("--lod-error-color", a.lod_error_color,
                 "error-bounded LOD: sample the coarsest level whose measured error moves a "
                 "sample's RGBA by at most this (0..1; overrides the scene's; 0 = off; "
                 "docs/rendering.md)");
  auto* timepoint = app.add_option("--timepoint", a.timepoint,
                                   "timepoint of a time series (overrides the scene's)");
  app.add_option("--play", a.play,
                 "FIRST:LAST: one image per timepoint, prefetching the next one; --out must "
                 "contain {t}")
      ->excludes(timepoint);
  app.add_flag("--no-play-prefetch", a.no_play_prefetch,
               "with --play: do not prefetch the next timepoint (for comparisons)");
  app.add_flag("--report-accuracy", a.report_accuracy,
               "render the dense reference of the same view (level 0, double precision) and "
               "print RMSE, PSNR and max error beside ms/frame (docs/renderer.md; not with --play)")
      ->excludes("--play");
  app.add_option("--reference-step", a.reference_step,
                 "with --report-accuracy: the reference's step in level-0 voxels")
      ->capture_default_str();
  app.add_option("--reference-mb", a.reference_mb,
                 "with --report-accuracy: memory for level 0 of the shown channels (4 bytes per "
                 "voxel and channel)")
      ->capture_default_str();
  resoct::tools::one_line_usage_errors(app, "resoct-render");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Exit codes as every tool's (tool_main.hpp): CLI11's own codes (105, 109, ...) would not
    // tell a usage error from a crash to a script.
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return resoct::tools::run_tool("resoct-render", [&] { return run(a); });
}
