#include "viewer/view_controls.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <numbers>

#include <glm/geometric.hpp>

#include "resoct/scene/camera.hpp"

namespace resoct::view {

namespace {

constexpr const char* kKeys[] = {
    "1", "2", "3", "4", "5", "6", "7", "8", "9", "tab",    "p", "c", "r",      "[",        "]",
    ",", ".", "m", "s", "h", "i", "o", "x", "q", "escape", "t", "T", "pageup", "pagedown", "f1"};

// Rotates v about the unit axis by `rad` (Rodrigues).
glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& axis, double rad) {
  return v * std::cos(rad) + glm::cross(axis, v) * std::sin(rad) +
         axis * glm::dot(axis, v) * (1.0 - std::cos(rad));
}

// The colour of map `map` (kColourNames, not "scene") at position t in [0, 1] of the window.
glm::dvec3 colour_at(std::size_t map, double t) {
  static const glm::dvec3 solid[] = {{1, 1, 1},     {1, 0.2, 0.2}, {0.2, 1, 0.2}, {0.3, 0.4, 1},
                                     {0.2, 0.9, 1}, {1, 0.2, 1},   {1, 0.85, 0.1}};
  if (map >= 1 && map <= std::size(solid)) return solid[map - 1];
  // Multi-stop maps: fire (dark red, orange, yellow, white), ice (blue, cyan, white).
  static const glm::dvec3 fire[] = {{0.5, 0, 0}, {1, 0.3, 0}, {1, 0.85, 0.1}, {1, 1, 1}};
  static const glm::dvec3 ice[] = {{0.1, 0.1, 0.8}, {0.1, 0.6, 1}, {0.5, 1, 1}, {1, 1, 1}};
  const glm::dvec3* stops = std::string_view(kColourNames[map]) == "fire" ? fire : ice;
  const double x = std::clamp(t, 0.0, 1.0) * 3.0;
  const int i = std::min(2, int(x));
  return glm::mix(stops[i], stops[i + 1], x - double(i));
}

bool multi_stop(std::size_t map) {
  const std::string_view n = kColourNames[map];
  return n == "fire" || n == "ice";
}

}  // namespace

bool is_key_name(const std::string& name) {
  return std::find_if(std::begin(kKeys), std::end(kKeys),
                      [&](const char* k) { return name == k; }) != std::end(kKeys);
}

std::string key_names() {
  std::string s;
  for (const char* k : kKeys) s += (s.empty() ? "" : ", ") + std::string(k);
  return s;
}

ViewControls::ViewControls(const Scene& initial, RenderMode mode, std::uint32_t timepoints)
    : initial_(initial), scene_(initial), mode_(mode), timepoints_(std::max(timepoints, 1u)) {
  for (const ChannelSettings& c : initial.channels) channels_.push_back(Channel{c});
  rebuild();
}

TransferFunction ViewControls::tf_of(const Channel& c) const {
  const TransferFunction& base = c.base.tf;
  if (c.preset == 0 && c.colour == 0) return base;
  // The window the presets and colour maps span: from where the base function becomes visible
  // to where its opacity first peaks (the whole range for a transparent one).
  double lo = 0.1, hi = 1.0;
  if (!base.fully_transparent()) {
    lo = std::clamp(base.visible_intervals().front().x, 0.0, 1.0);
    double peak = -1.0;
    for (const TfPoint& p : base.points()) {
      if (p.rgba.a > peak + 1e-12) {
        peak = p.rgba.a;
        hi = p.value;
      }
    }
    if (!(hi > lo + 1e-3)) hi = std::min(1.0, lo + 0.1);
    if (!(hi > lo + 1e-3)) lo = hi - 0.1;
  }
  const auto at = [&](double t) { return lo + (hi - lo) * t; };
  // Opacity profile: the base function's points, or the preset's.
  std::vector<TfPoint> profile;
  switch (c.preset) {
    case 0: profile = base.points(); break;
    case 1: profile = {{at(0.0), glm::dvec4(0.0)}, {at(1.0), glm::dvec4(0, 0, 0, 0.5)}}; break;
    case 2: profile = {{at(0.5), glm::dvec4(0.0)}, {at(1.0), glm::dvec4(0, 0, 0, 1.0)}}; break;
    case 3: profile = {{at(0.0), glm::dvec4(0.0)}, {at(1.0), glm::dvec4(0, 0, 0, 0.1)}}; break;
    default:
      profile = {{at(0.25), glm::dvec4(0.0)},
                 {at(0.5), glm::dvec4(0, 0, 0, 0.8)},
                 {at(0.75), glm::dvec4(0.0)}};
  }
  const TransferFunction alpha(profile);
  std::vector<TfPoint> points = profile;
  if (c.colour != 0 && multi_stop(c.colour)) {
    for (double t : {0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0}) {
      const double v = at(t);
      const bool present =
          std::any_of(points.begin(), points.end(), [&](const TfPoint& p) { return p.value == v; });
      if (!present) points.push_back(TfPoint{v, glm::dvec4(0, 0, 0, alpha.evaluate(v).a)});
    }
    std::stable_sort(points.begin(), points.end(),
                     [](const TfPoint& a, const TfPoint& b) { return a.value < b.value; });
  }
  for (TfPoint& p : points) {
    const glm::dvec3 rgb = c.colour == 0 ? glm::dvec3(base.evaluate(p.value))
                                         : colour_at(c.colour, (p.value - lo) / (hi - lo));
    p.rgba = glm::dvec4(rgb, p.rgba.a);
  }
  return TransferFunction(points);
}

void ViewControls::rebuild() {
  scene_.channels.clear();
  for (const Channel& c : channels_) {
    if (!c.on) continue;
    ChannelSettings s = c.base;
    s.tf = tf_of(c);
    scene_.channels.push_back(s);
  }
}

KeyAction ViewControls::press(const std::string& key) {
  if (key.size() == 1 && key[0] >= '1' && key[0] <= '9') {
    const std::size_t i = std::size_t(key[0] - '1');
    if (i < channels_.size()) {
      // A scene needs one channel: the last visible one stays on.
      const auto on =
          std::count_if(channels_.begin(), channels_.end(), [](const Channel& c) { return c.on; });
      if (!channels_[i].on || on > 1) channels_[i].on = !channels_[i].on;
      selected_ = i;
    }
  } else if (key == "tab") {
    if (!channels_.empty()) selected_ = (selected_ + 1) % channels_.size();
  } else if (key == "p") {
    if (!channels_.empty()) {
      channels_[selected_].preset = (channels_[selected_].preset + 1) % std::size(kPresetNames);
    }
  } else if (key == "c") {
    if (!channels_.empty()) {
      channels_[selected_].colour = (channels_[selected_].colour + 1) % std::size(kColourNames);
    }
  } else if (key == "r") {
    const Viewport vp = scene_.viewport;
    scene_.camera = initial_.camera;
    scene_.viewport = vp;
  } else if (key == "[") {
    scene_.lod_error_px = std::max(0.125, scene_.lod_error_px / 2.0);
  } else if (key == "]") {
    scene_.lod_error_px = std::min(64.0, scene_.lod_error_px * 2.0);
  } else if (key == ",") {
    scene_.step_scale = std::max(0.125, scene_.step_scale / 1.5);
  } else if (key == ".") {
    scene_.step_scale = std::min(16.0, scene_.step_scale * 1.5);
  } else if (key == "m") {
    mode_ = mode_ == RenderMode::residency   ? RenderMode::pagetable
            : mode_ == RenderMode::pagetable ? RenderMode::octree
                                             : RenderMode::residency;
  } else if (key == "s" || key == "h") {
    const Effect e = key == "s" ? Effect::shading : Effect::shadows;
    auto it = std::find(scene_.effects.begin(), scene_.effects.end(), e);
    if (it == scene_.effects.end()) {
      scene_.effects.push_back(e);
    } else {
      scene_.effects.erase(it);
    }
  } else if (key == "i") {
    scene_.preintegration = !scene_.preintegration;
  } else if (key == "o") {
    Camera& c = scene_.camera;
    const double distance = glm::length(c.eye - c.target);
    if (c.projection == Projection::perspective) {
      // The orthographic view as tall as the perspective one at the target.
      c.ortho_height = 2.0 * distance * std::tan(c.fov_deg * std::numbers::pi / 360.0);
      c.projection = Projection::orthographic;
    } else {
      c.projection = Projection::perspective;
    }
  } else if (key == "t" || key == "T" || key == "pageup" || key == "pagedown") {
    // Time series: the next (t, page down) or previous (T, page up) timepoint, wrapping.
    const std::uint32_t now = scene_.timepoint.value_or(0);
    const bool forward = key == "t" || key == "pagedown";
    if (timepoints_ > 1) {
      scene_.timepoint = forward ? (now + 1) % timepoints_ : (now + timepoints_ - 1) % timepoints_;
    }
  } else if (key == "f1") {
    return KeyAction::toggle_panel;
  } else if (key == "x") {
    return KeyAction::screenshot;
  } else if (key == "q" || key == "escape") {
    return KeyAction::quit;
  }
  rebuild();
  return KeyAction::none;
}

void ViewControls::orbit(double dx, double dy) {
  Camera c = resoct::orbit(scene_.camera, dx);
  const glm::dvec3 up = glm::normalize(c.up);
  glm::dvec3 offset = c.eye - c.target;
  const double distance = glm::length(offset);
  if (dy != 0.0 && distance > 0.0) {
    const glm::dvec3 right = glm::cross(up, offset);  // any vector perpendicular to both
    if (glm::length(right) > 1e-12) {
      // Elevation of the eye above the plane perpendicular to up, kept within +-88 degrees.
      const double elevation = std::asin(std::clamp(glm::dot(offset, up) / distance, -1.0, 1.0));
      const double limit = 88.0 * std::numbers::pi / 180.0;
      const double wanted = std::clamp(elevation + dy * std::numbers::pi / 180.0, -limit, limit);
      offset = rotate(offset, glm::normalize(right), -(wanted - elevation));
    }
  }
  c.eye = c.target + offset;
  scene_.camera = c;
}

void ViewControls::zoom(double factor) {
  if (!(factor > 0.0) || !std::isfinite(factor)) return;
  Camera& c = scene_.camera;
  if (c.projection == Projection::orthographic) {
    c.ortho_height = std::clamp(c.ortho_height / factor, 1e-4, 1e4);
    return;
  }
  const glm::dvec3 offset = c.eye - c.target;
  const double distance = std::clamp(glm::length(offset) / factor, 1e-4, 1e4);
  c.eye = c.target + glm::normalize(offset) * distance;
}

void ViewControls::pan(double dx, double dy) {
  Camera& c = scene_.camera;
  const CameraRays rays(c, scene_.viewport);
  const double distance = glm::length(c.eye - c.target);
  const double height = c.projection == Projection::orthographic
                            ? c.ortho_height
                            : 2.0 * distance * std::tan(c.fov_deg * std::numbers::pi / 360.0);
  const glm::dvec3 shift = (rays.right() * dx + rays.up() * dy) * height;
  c.eye += shift;
  c.target += shift;
}

void ViewControls::set_viewport(const Viewport& viewport) {
  scene_.viewport = viewport;
}

std::string ViewControls::status() const {
  std::string s;
  if (channels_.empty()) {
    s = "no channels";
  } else {
    std::string on;
    for (std::size_t i = 0; i < channels_.size(); ++i) {
      on += channels_[i].on ? char('1' + std::min<std::size_t>(i, 8)) : '-';
    }
    const Channel& c = channels_[selected_];
    s = "channels " + on + ", selected " + std::to_string(selected_ + 1) + " (" +
        kPresetNames[c.preset] + ", " + kColourNames[c.colour] + ")";
  }
  char buf[160];
  std::snprintf(buf, sizeof buf, " | lod %.3g px, step %.3g | %s", scene_.lod_error_px,
                scene_.step_scale, to_string(mode_));
  s += buf;
  for (Effect e : scene_.effects) s += std::string(", ") + to_string(e);
  if (scene_.preintegration) s += ", preintegrated";
  if (scene_.camera.projection == Projection::orthographic) s += ", orthographic";
  if (timepoints_ > 1) {
    s += " | t " + std::to_string(scene_.timepoint.value_or(0)) + "/" +
         std::to_string(timepoints_ - 1);
  }
  return s;
}

}  // namespace resoct::view
