#pragma once
// resoct-view's --script files: one command per line (docs/viewer.md "Scripts"), parsed up front
// so that a bad line fails before a window opens.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace resoct::view {

struct ScriptCommand {
  enum class Kind {
    orbit,           ///< orbit DX DY: degrees about up (turntable) and about the view's right axis
    zoom,            ///< zoom F: the eye's distance to the target divided by F (> 0)
    pan,             ///< pan DX DY: target and eye shifted by DX, DY view heights
    key,             ///< key NAME: as if the key was pressed (docs/viewer.md "Keys")
    wait,            ///< wait N: render N frames
    wait_converged,  ///< wait-converged [MAX]: render until a frame is converged (at most MAX)
    wait_accumulated,   ///< wait-accumulated [MAX]: render until the still view is accumulated
    window_screenshot,  ///< window-screenshot PATH: the frame as shown, panel included
    screenshot,         ///< screenshot PATH: the last frame as PNG
    save_scene,         ///< save-scene PATH: the current scene as JSON (docs/scene.md)
    quit,               ///< quit: end the viewer
  };
  Kind kind = Kind::wait;
  double x = 0.0;
  double y = 0.0;
  std::uint32_t count = 0;
  std::string text;
  std::string where;  ///< "FILE:LINE" for messages
};

/// Frames `wait-converged` renders at most when the script gives no MAX.
inline constexpr std::uint32_t kDefaultConvergeFrames = 5000;

/// Parses script text; `name` prefixes messages. Blank lines and lines starting with '#' are
/// skipped. Throws Error(invalid_argument) "NAME:LINE: why" for an unknown command, a missing or
/// extra argument, a number that does not parse or is out of range, or an unknown key name.
std::vector<ScriptCommand> parse_view_script(const std::string& text, const std::string& name);
/// Reads and parses a file; Error(io) naming the path when it cannot be read.
std::vector<ScriptCommand> load_view_script(const std::string& path);

}  // namespace resoct::view
