#pragma once
// resoct-view's scene state: the camera moves, the keys (channel toggles, transfer-function
// presets and colour maps, LOD error, step scale, render mode, effects) and the scene they give.
// No window code: the GLFW callbacks and the --script commands both drive this class.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "resoct/backend/backend.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct::view {

/// Whether `name` is a key ViewControls::press (or the viewer) understands.
bool is_key_name(const std::string& name);
/// The key names, comma-separated, for messages.
std::string key_names();

/// What a key press asks of the application beyond changing the scene.
enum class KeyAction { none, screenshot, quit, toggle_panel };

/// Transfer-function presets and colour maps the 'p' and 'c' keys cycle through per channel.
inline constexpr const char* kPresetNames[] = {"scene", "ramp", "steep", "soft", "band"};
inline constexpr const char* kColourNames[] = {"scene", "white",   "red",    "green", "blue",
                                               "cyan",  "magenta", "yellow", "fire",  "ice"};

class ViewControls {
 public:
  /// `initial` is what 'r' returns the camera to; its channels are those 1-9 toggle.
  /// `timepoints`: the source's (BrickSource::timepoints()), which 't' / 'T' step through.
  ViewControls(const Scene& initial, RenderMode mode, std::uint32_t timepoints = 1);

  /// The scene to render now.
  const Scene& scene() const noexcept { return scene_; }
  RenderMode mode() const noexcept { return mode_; }

  /// A key press (is_key_name); unknown names do nothing.
  KeyAction press(const std::string& key);
  /// Turntable orbit: `dx` degrees about up through the target, `dy` degrees about the view's
  /// right axis (kept 2 degrees away from the poles).
  void orbit(double dx, double dy);
  /// The eye's distance to the target (orthographic: the view height) divided by `factor` > 0.
  void zoom(double factor);
  /// Eye and target moved by (dx, dy) view heights at the target along right and up.
  void pan(double dx, double dy);
  void set_viewport(const Viewport& viewport);

  /// One line for the window title: selected channel, its preset and colours, LOD, step, mode,
  /// effects.
  std::string status() const;

 private:
  struct Channel {
    ChannelSettings base;
    bool on = true;
    std::size_t preset = 0;
    std::size_t colour = 0;
  };
  void rebuild();
  TransferFunction tf_of(const Channel& c) const;

  Scene initial_;
  Scene scene_;
  RenderMode mode_;
  std::uint32_t timepoints_ = 1;
  std::vector<Channel> channels_;
  std::size_t selected_ = 0;
};

}  // namespace resoct::view
