// resoct-view: an interactive viewer on the public API. A GLFW window with a Vulkan swapchain
// shows the renderer's frames (Vulkan backend: the frame stays on the device; CPU backend: its
// image goes through a staging buffer), refines progressively as bricks arrive, and can be
// driven by a script for tests and measurements (docs/viewer.md).
//
//   resoct-view --volume procedural:tubes:256x256x256:2 --size 800x600 --verbose
#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "resoct/base/error.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/io/overview_hints.hpp"
#include "resoct/render/frame_accumulator.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/scene/overview_scene.hpp"
#include "resoct/scene/scene.hpp"
#include "resoct/vulkan/vulkan_backend.hpp"
#include "support/cli_parse.hpp"
#include "support/output_path.hpp"
#include "support/source_options.hpp"
#include "support/tool_main.hpp"
#include "viewer/view_controls.hpp"
#include "viewer/text_panel.hpp"
#include "viewer/view_script.hpp"
#include "viewer/vk_window.hpp"

namespace {

using namespace resoct;
using namespace resoct::view;
using Clock = std::chrono::steady_clock;

struct Args {
  std::string volume;
  SourceOptions source;
  std::string scene;
  std::string backend = "vulkan";
  std::string device;
  bool validation = false;
  std::string mode = "residency";
  std::string size;
  std::string script;
  std::string screenshot;
  std::uint64_t exit_after_frames = 0;
  bool verbose = false;
  std::uint64_t cache_mb = 512;
  std::uint32_t threads = std::max(1u, std::thread::hardware_concurrency());
  std::uint32_t accumulate = 16;  // frames averaged for a still view; <= 1: none
  bool half_res_moving = false;
  bool no_panel = false;
};

/// "WxH" with each 1..16384.
Viewport parse_size(const std::string& s) {
  const auto x = s.find('x');
  std::uint32_t w = 0, h = 0;
  const auto num = [](const std::string& t, std::uint32_t& v) {
    if (t.empty() || t.size() > 6 || t.find_first_not_of("0123456789") != std::string::npos) {
      return false;
    }
    v = std::uint32_t(std::stoul(t));
    return v >= 1 && v <= 16384;
  };
  if (x == std::string::npos || !num(s.substr(0, x), w) || !num(s.substr(x + 1), h)) {
    throw invalid_parameter("size", "expected WxH with each 1..16384, got '" + s + "'");
  }
  return Viewport{w, h};
}

struct GlfwSession {
  GlfwSession() {
    if (glfwInit() != GLFW_TRUE) {
      throw Error(ErrorCode::device,
                  "window: GLFW cannot open a display (is DISPLAY set? run under xvfb-run "
                  "without one)");
    }
  }
  ~GlfwSession() { glfwTerminate(); }
  GlfwSession(const GlfwSession&) = delete;
  GlfwSession& operator=(const GlfwSession&) = delete;
};

// Input collected by the GLFW callbacks and applied by the loop.
struct Input {
  std::deque<std::string> keys;
  double orbit_x = 0, orbit_y = 0, pan_x = 0, pan_y = 0, zoom = 1.0;
  bool dragging_orbit = false, dragging_pan = false;
  double last_x = 0, last_y = 0;
};

const char* key_name(int key, int mods) {
  static const char* digits[] = {"1", "2", "3", "4", "5", "6", "7", "8", "9"};
  if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) return digits[key - GLFW_KEY_1];
  switch (key) {
    case GLFW_KEY_T: return (mods & GLFW_MOD_SHIFT) != 0 ? "T" : "t";
    case GLFW_KEY_PAGE_UP: return "pageup";
    case GLFW_KEY_PAGE_DOWN: return "pagedown";
    case GLFW_KEY_F1: return "f1";
    case GLFW_KEY_TAB: return "tab";
    case GLFW_KEY_P: return "p";
    case GLFW_KEY_C: return "c";
    case GLFW_KEY_R: return "r";
    case GLFW_KEY_LEFT_BRACKET: return "[";
    case GLFW_KEY_RIGHT_BRACKET: return "]";
    case GLFW_KEY_COMMA: return ",";
    case GLFW_KEY_PERIOD: return ".";
    case GLFW_KEY_M: return "m";
    case GLFW_KEY_S: return "s";
    case GLFW_KEY_H: return "h";
    case GLFW_KEY_I: return "i";
    case GLFW_KEY_O: return "o";
    case GLFW_KEY_X: return "x";
    case GLFW_KEY_Q: return "q";
    case GLFW_KEY_ESCAPE: return "escape";
    default: return nullptr;
  }
}

void install_callbacks(GLFWwindow* w, Input* input) {
  glfwSetWindowUserPointer(w, input);
  glfwSetKeyCallback(w, [](GLFWwindow* win, int key, int, int action, int mods) {
    auto* in = static_cast<Input*>(glfwGetWindowUserPointer(win));
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    if (const char* name = key_name(key, mods)) in->keys.emplace_back(name);
  });
  glfwSetMouseButtonCallback(w, [](GLFWwindow* win, int button, int action, int mods) {
    auto* in = static_cast<Input*>(glfwGetWindowUserPointer(win));
    const bool down = action == GLFW_PRESS;
    glfwGetCursorPos(win, &in->last_x, &in->last_y);
    if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT) == 0) {
      in->dragging_orbit = down;
    } else {
      in->dragging_pan = down;
    }
    if (!down) in->dragging_orbit = in->dragging_pan = false;
  });
  glfwSetCursorPosCallback(w, [](GLFWwindow* win, double x, double y) {
    auto* in = static_cast<Input*>(glfwGetWindowUserPointer(win));
    const double dx = x - in->last_x, dy = y - in->last_y;
    in->last_x = x;
    in->last_y = y;
    int fw = 1, fh = 1;
    glfwGetWindowSize(win, &fw, &fh);
    if (in->dragging_orbit) {
      in->orbit_x -= dx * 0.3;
      in->orbit_y += dy * 0.3;
    } else if (in->dragging_pan) {
      in->pan_x -= dx / double(std::max(fh, 1));
      in->pan_y += dy / double(std::max(fh, 1));
    }
  });
  glfwSetScrollCallback(w, [](GLFWwindow* win, double, double dy) {
    static_cast<Input*>(glfwGetWindowUserPointer(win))->zoom *= std::pow(1.1, dy);
  });
}

struct Series {
  std::vector<double> frame_ms;  // render_frame
  std::vector<double> loop_ms;   // render_frame + present + input
  void add(double f, double l) {
    frame_ms.push_back(f);
    loop_ms.push_back(l);
  }
  static double mean(const std::vector<double>& v) {
    return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
  }
  std::string summary(const char* what) const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%zu %s frames, %.2f ms render + present %.2f ms",
                  frame_ms.size(), what, mean(frame_ms), mean(loop_ms));
    return buf;
  }
};

int run(const Args& a) {
  if (a.volume.empty()) throw invalid_parameter("volume", "--volume is required");
  if (a.backend != "vulkan" && a.backend != "cpu") {
    throw invalid_parameter("backend", "expected cpu or vulkan, got '" + a.backend + "'");
  }
  const RenderMode initial_mode = parse_render_mode(a.mode);
  if (a.accumulate > 4096) throw invalid_parameter("accumulate", "must be 0..4096");
  if (a.cache_mb == 0 || a.cache_mb > (std::uint64_t(1) << 24)) {
    throw invalid_parameter("cache-mb", "must be 1..2^24");
  }
  std::optional<Viewport> size;
  if (!a.size.empty()) size = parse_size(a.size);
  // Everything that can be checked before a window opens is: scene, script, output paths.
  std::optional<Scene> from_file;
  if (!a.scene.empty()) from_file = load_scene(a.scene);
  std::vector<ScriptCommand> script;
  if (!a.script.empty()) script = load_view_script(a.script);
  if (!a.screenshot.empty()) tools::check_output_path("screenshot", a.screenshot);
  for (const ScriptCommand& c : script) {
    if (c.kind == ScriptCommand::Kind::screenshot || c.kind == ScriptCommand::Kind::save_scene ||
        c.kind == ScriptCommand::Kind::window_screenshot) {
      try {
        tools::check_output_path(c.where, c.text);
      } catch (const Error& e) {
        throw Error(e.code(), c.where + ": " + e.what());
      }
    }
  }
  const std::shared_ptr<const BrickSource> source(open_source(a.volume, {}, a.source));
  const VolumeDesc& volume = source->volume();
  const Viewport window_size =
      size ? *size : (from_file ? from_file->viewport : Viewport{800, 600});
  Scene initial =
      from_file ? *from_file : overview_scene(volume, window_size, overview_hints(*source));
  initial.viewport = window_size;
  // A time series shows its timepoint explicitly, so that 't' / 'T' step from it.
  if (source->timepoints() > 1 && !initial.timepoint) initial.timepoint = source->timepoint();
  initial.validate(volume, source->timepoints(), a.scene.empty() ? "scene" : a.scene);

  GlfwSession glfw;
  if (glfwVulkanSupported() != GLFW_TRUE) {
    throw Error(ErrorCode::device, "window: GLFW finds no Vulkan loader or surface support");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  GLFWwindow* window = glfwCreateWindow(int(window_size.width), int(window_size.height),
                                        "resoct-view", nullptr, nullptr);
  if (window == nullptr) throw Error(ErrorCode::device, "window: GLFW cannot create a window");
  struct WindowGuard {
    GLFWwindow* w;
    ~WindowGuard() { glfwDestroyWindow(w); }
  } window_guard{window};
  Input input;
  install_callbacks(window, &input);
  VkWindow vk(window, a.validation, a.device);

  ViewerOptions options;
  options.device_cache_bytes = a.cache_mb << 20;
  options.loader_threads = a.threads;
  options.output = FrameOutput::device;
  const auto make_renderer = [&](RenderMode mode) {
    options.mode = mode;
    std::unique_ptr<Backend> backend =
        a.backend == "vulkan"
            ? vk::make_backend(vk.instance(), vk.physical(), vk.device(), vk.queue_family())
            : cpu::make_backend();
    auto r = std::make_unique<Renderer>(source, std::move(backend), options);
    r->set_failure_callback([](const LoadFailure& f) {
      std::fprintf(stderr, "resoct-view: warning: %s\n", f.message.c_str());
    });
    return r;
  };
  std::unique_ptr<Renderer> renderer = make_renderer(initial_mode);
  std::fprintf(stderr, "resoct-view: %s on %s (%s backend)\n", source->name().c_str(),
               vk.device_name().c_str(), a.backend.c_str());

  ViewControls controls(initial, initial_mode, source->timepoints());
  // Still views average jittered frames (docs/viewer.md "Jittered accumulation").
  FrameAccumulator acc(std::max(a.accumulate, 1u));
  const bool accumulating = a.accumulate > 1;
  bool shown_accumulated = false;  // the window shows acc.image(), not the last frame
  bool last_plain_full = false;    // the last frame: unjittered, full resolution
  bool panel_on = !a.no_panel;
  std::string panel_state;
  FrameReport report;
  std::optional<Scene> shown;  // the scene of the last frame
  RenderMode shown_mode = initial_mode;
  bool converged = false;
  std::uint64_t frames = 0;
  Series moving, refining;
  std::size_t pc = 0;
  std::uint32_t wait_frames = 0;
  std::uint32_t converge_budget = 0;
  const ScriptCommand* converge_cmd = nullptr;
  std::uint32_t screenshot_counter = 0;
  auto last_title = Clock::now() - std::chrono::seconds(1);
  bool quit = false;

  const auto frame_image = [&]() -> Image {
    if (!shown) throw Error(ErrorCode::invalid_argument, "screenshot: no frame rendered yet");
    Image img(report.width, report.height);
    if (report.device_image.handle != 0) {
      img.pixels() = vk.read_device(vk::buffer_of(report.device_image), report.device_image.offset,
                                    report.width, report.height);
    } else {
      img = report.image;
    }
    return img;
  };
  // What the window shows without the panel: the average while accumulating, else the frame.
  const auto shown_image = [&]() -> Image {
    return shown_accumulated ? acc.image() : frame_image();
  };
  const auto screenshot = [&](const std::string& path) {
    write_png(shown_image(), path);
    std::fprintf(stderr, "resoct-view: wrote %s\n", path.c_str());
  };
  std::vector<std::string> panel_lines;
  const auto window_screenshot = [&](const std::string& path) {
    Image img = shown_image();
    if (panel_on) composite_panel(img, draw_panel(panel_lines));
    write_png(img, path);
    std::fprintf(stderr, "resoct-view: wrote %s\n", path.c_str());
  };
  const auto on_key = [&](const std::string& key) {
    const KeyAction act = controls.press(key);
    if (act == KeyAction::quit) quit = true;
    if (act == KeyAction::toggle_panel) {
      panel_on = !panel_on;
      if (!panel_on) vk.set_panel(nullptr, 0, 0);
    }
    if (act == KeyAction::screenshot) {
      char name[64];
      std::snprintf(name, sizeof name, "resoct-view-%04u.png", screenshot_counter++);
      screenshot(name);
    }
  };
  // Whether the last frame shows the current scene in the current mode.
  const auto up_to_date = [&] {
    return shown && *shown == controls.scene() && shown_mode == controls.mode();
  };
  std::uint32_t accumulate_budget = 0;
  const ScriptCommand* accumulate_cmd = nullptr;
  // The still view is averaged as far as it goes (or accumulation is off).
  const auto accumulated = [&] {
    return !accumulating ||
           (up_to_date() && converged && acc.accumulating(controls.scene()) && acc.done());
  };

  while (!quit) {
    glfwPollEvents();
    if (glfwWindowShouldClose(window)) break;
    while (!input.keys.empty()) {
      on_key(input.keys.front());
      input.keys.pop_front();
    }
    if (input.orbit_x != 0.0 || input.orbit_y != 0.0) controls.orbit(input.orbit_x, input.orbit_y);
    if (input.pan_x != 0.0 || input.pan_y != 0.0) controls.pan(input.pan_x, input.pan_y);
    if (input.zoom != 1.0) controls.zoom(input.zoom);
    input.orbit_x = input.orbit_y = input.pan_x = input.pan_y = 0.0;
    input.zoom = 1.0;

    // Script commands run until one waits for frames; a screenshot or save-scene first waits for
    // a frame of the current scene.
    while (!quit && wait_frames == 0 && converge_cmd == nullptr && accumulate_cmd == nullptr &&
           pc < script.size()) {
      const ScriptCommand& c = script[pc];
      using K = ScriptCommand::Kind;
      if ((c.kind == K::screenshot || c.kind == K::save_scene || c.kind == K::window_screenshot) &&
          !up_to_date()) {
        break;
      }
      ++pc;
      switch (c.kind) {
        case K::orbit: controls.orbit(c.x, c.y); break;
        case K::zoom: controls.zoom(c.x); break;
        case K::pan: controls.pan(c.x, c.y); break;
        case K::key: on_key(c.text); break;
        case K::wait: wait_frames = c.count; break;
        case K::wait_converged:
          if (!(up_to_date() && converged)) {
            converge_cmd = &c;
            converge_budget = c.count;
          }
          break;
        case K::wait_accumulated:
          if (!accumulated()) {
            accumulate_cmd = &c;
            accumulate_budget = c.count;
          }
          break;
        case K::screenshot: screenshot(c.text); break;
        case K::window_screenshot: window_screenshot(c.text); break;
        case K::save_scene: save_scene(controls.scene(), c.text); break;
        case K::quit: quit = true; break;
      }
    }
    if (quit) break;

    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    if (fw > 0 && fh > 0 &&
        (std::uint32_t(fw) != controls.scene().viewport.width ||
         std::uint32_t(fh) != controls.scene().viewport.height)) {
      controls.set_viewport(Viewport{std::uint32_t(fw), std::uint32_t(fh)});
    }
    if (controls.mode() != shown_mode) {
      vk.wait_idle();
      renderer.reset();
      renderer = make_renderer(controls.mode());
      shown.reset();
      acc = FrameAccumulator(std::max(a.accumulate, 1u));  // the bricks load again
    }
    const bool changed = !up_to_date();
    const bool scripted = wait_frames > 0 || converge_cmd != nullptr || accumulate_cmd != nullptr ||
                          pc < script.size();
    // --exit-after-frames renders its N frames even when nothing changes (measurements).
    if (!changed && converged && accumulated() && wait_frames == 0 && a.exit_after_frames == 0) {
      // Converged and nothing to do: sleep until input arrives.
      if (!scripted) glfwWaitEventsTimeout(0.1);
      continue;
    }
    if (fw == 0 || fh == 0) {  // minimized
      glfwWaitEventsTimeout(0.1);
      continue;
    }
    const auto t0 = Clock::now();
    // Moving with --half-res-moving: a quarter of the pixels, scaled up by the presenter's blit.
    const bool low_res = a.half_res_moving && changed;
    // Standing still on a converged frame: the next frame of the running average. Frames
    // rendered after it is complete (wait, --exit-after-frames) are plain and leave it shown.
    const bool acc_done =
        accumulating && !changed && acc.accumulating(controls.scene()) && acc.done();
    const bool jittered = accumulating && !changed && converged && !low_res && !acc_done;
    FrameJitter jitter;
    if (jittered) {
      jitter = acc.next(controls.scene());
      if (jitter.none() && last_plain_full) {
        // The average's first frame is the plain frame already shown: add it, render nothing.
        acc.add(frame_image(), false);
        shown_accumulated = true;
        continue;
      }
    }
    Scene scene = controls.scene();
    if (low_res) {
      scene.viewport = Viewport{std::max(1u, (scene.viewport.width + 1) / 2),
                                std::max(1u, (scene.viewport.height + 1) / 2)};
    }
    vk.wait_frame();  // the last copy to the screen may still read the frame's buffer
    renderer->render_frame(scene, report, jitter);
    shown = controls.scene();
    shown_mode = controls.mode();
    // A low-resolution frame is never the still view's last word.
    converged = report.converged && !low_res;
    last_plain_full = !jittered && !low_res;
    shown_accumulated = jittered || (acc_done && converged);
    if (jittered) acc.add(frame_image(), report.stats.bricks_uploaded != 0);
    ++frames;
    const FrameStats& s = report.stats;
    panel_state = changed     ? (low_res ? "moving, half resolution" : "moving")
                  : converged ? "converged"
                              : "refining";
    if (accumulating && !changed && converged) {
      // A plain converged frame is the first of the average about to start.
      const std::uint32_t n = acc.accumulating(controls.scene()) ? acc.frames() : 1;
      panel_state += ", accumulated " + std::to_string(n) + "/" + std::to_string(acc.max_frames());
    }
    if (panel_on) {
      char l0[96], l1[96], l2[96];
      std::snprintf(l0, sizeof l0, "frame %llu  %ux%u  %.1f ms",
                    static_cast<unsigned long long>(frames), report.width, report.height,
                    s.ms_frame);
      std::snprintf(l1, sizeof l1, "bricks: requested %llu  loaded %llu",
                    static_cast<unsigned long long>(s.brick_requests),
                    static_cast<unsigned long long>(s.bricks_uploaded));
      std::snprintf(l2, sizeof l2, "resident %u  in flight %llu", s.resident_bricks,
                    static_cast<unsigned long long>(s.loads_in_flight + s.loads_queued));
      panel_lines = {l0, l1, l2, panel_state};
      if (renderer->timepoints() > 1) {
        panel_lines.push_back("timepoint " + std::to_string(renderer->timepoint()) + " of " +
                              std::to_string(renderer->timepoints()));
      }
      const Image panel = draw_panel(panel_lines);
      vk.set_panel(panel.pixels().data(), panel.width(), panel.height());
    }
    if (shown_accumulated) {
      vk.present_host(acc.image().pixels().data(), acc.image().width(), acc.image().height());
    } else if (report.device_image.handle != 0) {
      vk.present_device(vk::buffer_of(report.device_image), report.device_image.offset,
                        report.width, report.height);
    } else {
      vk.present_host(report.image.pixels().data(), report.image.width(), report.image.height());
    }
    const double loop_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    (changed ? moving : refining).add(s.ms_frame, loop_ms);
    if (wait_frames > 0) --wait_frames;
    if (accumulate_cmd != nullptr) {
      if (accumulated()) {
        accumulate_cmd = nullptr;
      } else if (--accumulate_budget == 0) {
        throw Error(ErrorCode::invalid_argument,
                    accumulate_cmd->where + ": wait-accumulated: not accumulated after " +
                        std::to_string(accumulate_cmd->count) + " frames");
      }
    }
    if (converge_cmd != nullptr) {
      if (converged) {
        converge_cmd = nullptr;
      } else if (--converge_budget == 0) {
        throw Error(ErrorCode::invalid_argument,
                    converge_cmd->where + ": wait-converged: not converged after " +
                        std::to_string(converge_cmd->count) + " frames");
      }
    }
    std::string state = changed ? (converged ? "moving, converged" : "moving")
                                : (converged ? "refining, converged" : "refining");
    if (low_res) state += ", half resolution";
    if (jittered) {
      state +=
          ", accumulated " + std::to_string(acc.frames()) + "/" + std::to_string(acc.max_frames());
    }
    char line[256];
    std::snprintf(line, sizeof line,
                  "%.1f ms | requested %llu, loaded %llu, resident %u, in flight %llu | %s",
                  s.ms_frame, static_cast<unsigned long long>(s.brick_requests),
                  static_cast<unsigned long long>(s.bricks_uploaded), s.resident_bricks,
                  static_cast<unsigned long long>(s.loads_in_flight + s.loads_queued),
                  state.c_str());
    if (a.verbose) {
      std::fprintf(stderr, "resoct-view: frame %llu %ux%u: %s, %.1f ms with present\n",
                   static_cast<unsigned long long>(frames), report.width, report.height, line,
                   loop_ms);
    }
    if (Clock::now() - last_title > std::chrono::milliseconds(100) || converged) {
      glfwSetWindowTitle(window,
                         ("resoct-view: " + std::string(line) + " | " + controls.status()).c_str());
      last_title = Clock::now();
    }
    if (a.exit_after_frames != 0 && frames >= a.exit_after_frames) break;
    // Standing still while bricks load: give the loader threads the time rather than re-render
    // the same picture.
    if (!changed && !converged && s.bricks_uploaded == 0 && !scripted) glfwWaitEventsTimeout(0.005);
  }

  vk.wait_idle();
  if (!a.screenshot.empty()) screenshot(a.screenshot);
  std::fprintf(stderr, "resoct-view: %llu frames (%s; %s), %s\n",
               static_cast<unsigned long long>(frames), moving.summary("moving").c_str(),
               refining.summary("refining").c_str(), converged ? "converged" : "not converged");
  renderer.reset();
  if (a.validation) {
    for (const std::string& m : vk.validation_log()) {
      std::fprintf(stderr, "resoct-view: validation: %s\n", m.c_str());
    }
    std::fprintf(stderr, "resoct-view: %llu validation messages\n",
                 static_cast<unsigned long long>(vk.validation_messages()));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Interactive viewer: renders a volume progressively in a window (docs/viewer.md)"};
  Args a;
  app.add_option("--volume", a.volume, std::string(kSourceSpecForms) + " (required)");
  resoct::tools::add_source_options(app, a.source);
  app.add_option("--scene", a.scene,
                 "scene JSON (docs/scene.md); without it, the volume's overview with transfer "
                 "functions from its metadata (docs/viewer.md)");
  app.add_option("--backend", a.backend, "vulkan | cpu")->capture_default_str();
  app.add_option("--device", a.device, "Vulkan device index or name substring");
  app.add_flag("--validation", a.validation,
               "enable the Vulkan validation layers and print the messages at exit");
  app.add_option("--mode", a.mode, "residency | pagetable | octree")->capture_default_str();
  app.add_option("--size", a.size, "window size WxH (default: the scene's viewport, else 800x600)");
  app.add_option("--script", a.script, "command file (docs/viewer.md \"Scripts\")");
  app.add_option("--screenshot", a.screenshot, "PNG of the last frame, written at exit");
  app.add_option("--exit-after-frames", a.exit_after_frames,
                 "render N frames, rendering on after convergence, then quit (0 = never)");
  app.add_flag("--verbose", a.verbose, "print every frame's statistics");
  app.add_option("--accumulate", a.accumulate,
                 "jittered frames averaged while the view stands still (0 or 1: none; <= 4096)")
      ->capture_default_str();
  app.add_flag("--half-res-moving", a.half_res_moving,
               "render at half the window's resolution while the scene changes");
  app.add_flag("--no-panel", a.no_panel, "start with the statistics panel off (F1 toggles it)");
  app.add_option("--cache-mb", a.cache_mb, "device brick cache in MiB")->capture_default_str();
  app.add_option("--threads", a.threads, "loader threads (0 = load synchronously)")
      ->capture_default_str();
  resoct::tools::one_line_usage_errors(app, "resoct-view");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return resoct::tools::run_tool("resoct-view", [&] { return run(a); });
}
