#include "viewer/view_script.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "resoct/base/error.hpp"
#include "viewer/view_controls.hpp"

namespace resoct::view {

namespace {

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string s; in >> s;) w.push_back(s);
  return w;
}

double number(const std::string& s, const std::string& where, const char* what) {
  double v = 0.0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v)) {
    throw Error(ErrorCode::invalid_argument,
                where + ": " + what + ": expected a finite number, got '" + s + "'");
  }
  return v;
}

std::uint32_t count(const std::string& s, const std::string& where, const char* what) {
  std::uint32_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || v == 0 || v > 1000000) {
    throw Error(ErrorCode::invalid_argument,
                where + ": " + what + ": expected an integer 1..1000000, got '" + s + "'");
  }
  return v;
}

}  // namespace

std::vector<ScriptCommand> parse_view_script(const std::string& text, const std::string& name) {
  std::vector<ScriptCommand> out;
  std::istringstream in(text);
  std::size_t line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    const std::vector<std::string> w = words(line);
    if (w.empty() || w[0][0] == '#') continue;
    ScriptCommand c;
    c.where = name + ":" + std::to_string(line_no);
    const std::string& cmd = w[0];
    const auto args = [&](std::size_t lo, std::size_t hi, const char* usage) {
      if (w.size() - 1 < lo || w.size() - 1 > hi) {
        throw Error(ErrorCode::invalid_argument, c.where + ": usage: " + usage);
      }
    };
    if (cmd == "orbit" || cmd == "pan") {
      args(2, 2, cmd == "orbit" ? "orbit DX_DEGREES DY_DEGREES" : "pan DX DY (view heights)");
      c.kind = cmd == "orbit" ? ScriptCommand::Kind::orbit : ScriptCommand::Kind::pan;
      c.x = number(w[1], c.where, cmd.c_str());
      c.y = number(w[2], c.where, cmd.c_str());
    } else if (cmd == "zoom") {
      args(1, 1, "zoom FACTOR (> 0; 2 halves the distance)");
      c.kind = ScriptCommand::Kind::zoom;
      c.x = number(w[1], c.where, "zoom");
      if (!(c.x > 0.0)) {
        throw Error(ErrorCode::invalid_argument, c.where + ": zoom: the factor must be > 0");
      }
    } else if (cmd == "key") {
      args(1, 1, "key NAME (docs/viewer.md lists the keys)");
      c.kind = ScriptCommand::Kind::key;
      c.text = w[1];
      if (!is_key_name(c.text)) {
        throw Error(ErrorCode::invalid_argument,
                    c.where + ": key: unknown key '" + c.text + "' (known: " + key_names() + ")");
      }
    } else if (cmd == "wait") {
      args(1, 1, "wait FRAMES");
      c.kind = ScriptCommand::Kind::wait;
      c.count = count(w[1], c.where, "wait");
    } else if (cmd == "wait-converged") {
      args(0, 1, "wait-converged [MAX_FRAMES]");
      c.kind = ScriptCommand::Kind::wait_converged;
      c.count = w.size() == 2 ? count(w[1], c.where, "wait-converged") : kDefaultConvergeFrames;
    } else if (cmd == "wait-accumulated") {
      args(0, 1, "wait-accumulated [MAX_FRAMES]");
      c.kind = ScriptCommand::Kind::wait_accumulated;
      c.count = w.size() == 2 ? count(w[1], c.where, "wait-accumulated") : kDefaultConvergeFrames;
    } else if (cmd == "window-screenshot") {
      args(1, 1, "window-screenshot PATH.png");
      c.kind = ScriptCommand::Kind::window_screenshot;
      c.text = w[1];
    } else if (cmd == "screenshot" || cmd == "save-scene") {
      args(1, 1, cmd == "screenshot" ? "screenshot PATH.png" : "save-scene PATH.json");
      c.kind =
          cmd == "screenshot" ? ScriptCommand::Kind::screenshot : ScriptCommand::Kind::save_scene;
      c.text = w[1];
    } else if (cmd == "quit") {
      args(0, 0, "quit");
      c.kind = ScriptCommand::Kind::quit;
    } else {
      throw Error(ErrorCode::invalid_argument,
                  c.where + ": unknown command '" + cmd +
                      "' (orbit, zoom, pan, key, wait, wait-converged, wait-accumulated, "
                      "screenshot, window-screenshot, save-scene, quit)");
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<ScriptCommand> load_view_script(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error(ErrorCode::io, path + ": cannot read the script");
  std::ostringstream text;
  text << f.rdbuf();
  return parse_view_script(text.str(), path);
}

}  // namespace resoct::view
