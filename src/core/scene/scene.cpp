#include "resoct/scene/scene.hpp"

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <sstream>

#include <nlohmann/json.hpp>

#include "resoct/base/file_io.hpp"
#include "resoct/base/error.hpp"
#include "scene/scene_slices.hpp"

namespace resoct {
namespace {

using nlohmann::json;

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Builds "<name>: <path>: why" errors while walking the JSON document.
class Reader {
 public:
  explicit Reader(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& why) const {
    throw Error(ErrorCode::invalid_argument, name_ + ": " + path + ": " + why);
  }

  // Unknown keys are rejected rather than ignored: a misspelt "ert_opacty" would otherwise
  // silently render with the default.
  void only_keys(const json& obj, const std::string& path,
                 std::initializer_list<const char*> keys) const {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      bool known = false;
      for (const char* k : keys) known = known || it.key() == k;
      if (!known) fail(join(path, it.key()), "unknown key");
    }
  }

  const json& object(const json& j, const std::string& path) const {
    if (!j.is_object()) fail(path, "must be an object");
    return j;
  }
  const json& array(const json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, "must be an array");
    return j;
  }
  const json* find(const json& obj, const char* key) const {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
  const json& require(const json& obj, const std::string& path, const char* key) const {
    const json* j = find(obj, key);
    if (j == nullptr) fail(join(path, key), "missing");
    return *j;
  }
  double number(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "must be a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(path, "must be finite");
    return v;
  }
  std::int64_t integer(const json& j, const std::string& path) const {
    if (!j.is_number_integer()) fail(path, "must be an integer");
    if (j.is_number_unsigned() && j.get<std::uint64_t>() > std::uint64_t(INT64_MAX)) {
      fail(path, "out of range");
    }
    return j.get<std::int64_t>();
  }
  std::string string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, "must be a string");
    return j.get<std::string>();
  }
  template <int N>
  glm::vec<N, double> vector(const json& j, const std::string& path) const {
    array(j, path);
    if (j.size() != std::size_t(N)) fail(path, "must have " + std::to_string(N) + " numbers");
    glm::vec<N, double> v{};
    for (int i = 0; i < N; ++i) v[i] = number(j[std::size_t(i)], index(path, std::size_t(i)));
    return v;
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string index(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }
  const std::string& name() const noexcept { return name_; }

 private:
  std::string name_;
};

Camera read_camera(const Reader& r, const json& j) {
  const std::string path = "camera";
  r.object(j, path);
  r.only_keys(j, path, {"eye", "target", "up", "fov_deg", "ortho_height", "projection"});
  Camera c;
  c.eye = r.vector<3>(r.require(j, path, "eye"), "camera.eye");
  c.target = r.vector<3>(r.require(j, path, "target"), "camera.target");
  if (const json* up = r.find(j, "up")) c.up = r.vector<3>(*up, "camera.up");
  if (const json* fov = r.find(j, "fov_deg")) c.fov_deg = r.number(*fov, "camera.fov_deg");
  if (const json* h = r.find(j, "ortho_height")) {
    c.ortho_height = r.number(*h, "camera.ortho_height");
  }
  if (const json* p = r.find(j, "projection")) {
    const std::string s = r.string(*p, "camera.projection");
    if (s == "perspective") {
      c.projection = Projection::perspective;
    } else if (s == "orthographic") {
      c.projection = Projection::orthographic;
    } else {
      r.fail("camera.projection", "'" + s + "' is not \"perspective\" or \"orthographic\"");
    }
  }
  return c;
}

Viewport read_viewport(const Reader& r, const json& j) {
  r.object(j, "viewport");
  r.only_keys(j, "viewport", {"width", "height"});
  Viewport v;
  const std::int64_t w = r.integer(r.require(j, "viewport", "width"), "viewport.width");
  const std::int64_t h = r.integer(r.require(j, "viewport", "height"), "viewport.height");
  if (w < 1 || w > 16384) r.fail("viewport.width", "must be in 1..16384");
  if (h < 1 || h > 16384) r.fail("viewport.height", "must be in 1..16384");
  v.width = std::uint32_t(w);
  v.height = std::uint32_t(h);
  return v;
}

TransferFunction read_tf(const Reader& r, const json& j, const std::string& path) {
  r.array(j, path);
  std::vector<TfPoint> points;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string p = Reader::index(path, i);
    r.array(j[i], p);
    if (j[i].size() != 5) r.fail(p, "must be [value, r, g, b, alpha]");
    TfPoint point;
    point.value = r.number(j[i][0], p);
    for (int c = 0; c < 4; ++c) point.rgba[c] = r.number(j[i][std::size_t(c) + 1], p);
    points.push_back(point);
  }
  validate_tf_points(points, r.name() + ": " + path);
  return TransferFunction(std::move(points));
}

json vec_json(const double* v, int n);

// --- Effects: channel modes, isovalues, light, gradient stencil, shadow LOD -------------------

void read_channel_effects(const Reader& r, const json& j, const std::string& path,
                          ChannelSettings& c) {
  if (const json* mode = r.find(j, "mode")) {
    const std::string mp = Reader::join(path, "mode");
    const std::string m = r.string(*mode, mp);
    if (m == "dvr") {
      c.mode = ChannelMode::dvr;
    } else if (m == "iso") {
      c.mode = ChannelMode::iso;
    } else if (m == "mip") {
      c.mode = ChannelMode::mip;
    } else if (m == "aip") {
      c.mode = ChannelMode::aip;
    } else {
      r.fail(mp, "'" + m + "' is not a mode (\"dvr\", \"iso\", \"mip\", \"aip\")");
    }
  }
  if (const json* iso = r.find(j, "isovalues")) {
    const std::string ip = Reader::join(path, "isovalues");
    r.array(*iso, ip);
    for (std::size_t i = 0; i < iso->size(); ++i) {
      c.isovalues.push_back(r.number((*iso)[i], Reader::index(ip, i)));
    }
  }
}

Light read_light(const Reader& r, const json& j) {
  r.object(j, "light");
  r.only_keys(j, "light", {"direction", "position", "ambient", "diffuse", "specular", "shininess"});
  Light l;
  const json* dir = r.find(j, "direction");
  const json* pos = r.find(j, "position");
  if (dir != nullptr && pos != nullptr) r.fail("light", "give a direction or a position, not both");
  if (dir != nullptr) {
    l.kind = Light::Kind::directional;
    l.vector = r.vector<3>(*dir, "light.direction");
  } else if (pos != nullptr) {
    l.kind = Light::Kind::point;
    l.vector = r.vector<3>(*pos, "light.position");
  }
  if (const json* v = r.find(j, "ambient")) l.ambient = r.number(*v, "light.ambient");
  if (const json* v = r.find(j, "diffuse")) l.diffuse = r.number(*v, "light.diffuse");
  if (const json* v = r.find(j, "specular")) l.specular = r.number(*v, "light.specular");
  if (const json* v = r.find(j, "shininess")) l.shininess = r.number(*v, "light.shininess");
  return l;
}

void read_effect_options(const Reader& r, const json& doc, Scene& s) {
  if (const json* v = r.find(doc, "light")) s.light = read_light(r, *v);
  if (const json* v = r.find(doc, "gradient")) {
    const std::string g = r.string(*v, "gradient");
    if (g == "central") {
      s.gradient = GradientStencil::central;
    } else if (g == "forward") {
      s.gradient = GradientStencil::forward;
    } else {
      r.fail("gradient", "'" + g + "' is not \"central\" or \"forward\"");
    }
  }
  if (const json* v = r.find(doc, "shadow_lod_factor")) {
    const std::int64_t f = r.integer(*v, "shadow_lod_factor");
    if (f < 1 || f > 16 || (f & (f - 1)) != 0) {
      r.fail("shadow_lod_factor", std::to_string(f) + " is not a power of two in 1..16");
    }
    s.shadow_lod_factor = std::uint32_t(f);
  }
}

template <class Fail>
void check_effects(const Scene& s, const Fail& fail) {
  for (std::size_t i = 0; i < s.channels.size(); ++i) {
    const ChannelSettings& c = s.channels[i];
    const std::string p = "channels[" + std::to_string(i) + "]";
    if (c.mode == ChannelMode::iso) {
      if (c.isovalues.empty() || c.isovalues.size() > kMaxIsovalues) {
        fail(p + ".isovalues",
             "mode \"iso\" needs 1.." + std::to_string(kMaxIsovalues) + " isovalues");
      }
      for (std::size_t k = 0; k < c.isovalues.size(); ++k) {
        if (!(c.isovalues[k] >= 0.0 && c.isovalues[k] <= 1.0)) {
          fail(p + ".isovalues[" + std::to_string(k) + "]",
               fmt(c.isovalues[k]) + " outside the normalized range [0,1]");
        }
      }
    } else if (!c.isovalues.empty()) {
      fail(p + ".isovalues", std::string("only channels of mode \"iso\" take isovalues, not \"") +
                                 to_string(c.mode) + "\"");
    }
  }
  const Light& l = s.light;
  const bool finite =
      std::isfinite(l.vector.x) && std::isfinite(l.vector.y) && std::isfinite(l.vector.z);
  if (!finite) fail("light", "must be finite");
  if (l.kind == Light::Kind::directional && l.vector == glm::dvec3(0.0)) {
    fail("light.direction", "must not be zero");
  }
  const double coef[3] = {l.ambient, l.diffuse, l.specular};
  const char* names[3] = {"light.ambient", "light.diffuse", "light.specular"};
  for (int k = 0; k < 3; ++k) {
    if (!(coef[k] >= 0.0 && coef[k] <= 10.0)) fail(names[k], fmt(coef[k]) + " outside [0, 10]");
  }
  if (!(l.shininess >= 1.0 && l.shininess <= 1024.0)) {
    fail("light.shininess", fmt(l.shininess) + " outside [1, 1024]");
  }
  const std::uint32_t f = s.shadow_lod_factor;
  if (f < 1 || f > 16 || (f & (f - 1)) != 0) {
    fail("shadow_lod_factor", std::to_string(f) + " is not a power of two in 1..16");
  }
  if (s.has_effect(Effect::shadows) && !s.has_effect(Effect::shading)) {
    bool iso = false;
    for (const ChannelSettings& c : s.channels) iso = iso || c.mode == ChannelMode::iso;
    if (!iso) {
      fail("effects", "\"shadows\" darkens shaded samples: it needs \"shading\" or an iso channel");
    }
  }
}

void effects_to_json(const Scene& s, json& doc) {
  json light;
  if (s.light.kind == Light::Kind::directional) light["direction"] = vec_json(&s.light.vector.x, 3);
  if (s.light.kind == Light::Kind::point) light["position"] = vec_json(&s.light.vector.x, 3);
  light["ambient"] = s.light.ambient;
  light["diffuse"] = s.light.diffuse;
  light["specular"] = s.light.specular;
  light["shininess"] = s.light.shininess;
  doc["light"] = light;
  doc["gradient"] = s.gradient == GradientStencil::forward ? "forward" : "central";
  doc["shadow_lod_factor"] = s.shadow_lod_factor;
}

// ------------------------------------------------------------------------------------------------

ChannelSettings read_channel(const Reader& r, const json& j, const std::string& path) {
  r.object(j, path);
  r.only_keys(j, path, {"channel", "tf", "levels", "importance", "mode", "isovalues"});
  ChannelSettings c;
  const std::string channel_path = Reader::join(path, "channel");
  const std::int64_t channel = r.integer(r.require(j, path, "channel"), channel_path);
  if (channel < 0 || channel >= std::int64_t(kMaxChannels)) {
    r.fail(channel_path, "must be in 0.." + std::to_string(kMaxChannels - 1));
  }
  c.channel = std::uint32_t(channel);
  c.tf = read_tf(r, r.require(j, path, "tf"), Reader::join(path, "tf"));
  if (const json* levels = r.find(j, "levels")) {
    const std::string lp = Reader::join(path, "levels");
    r.array(*levels, lp);
    if (levels->size() != 2) r.fail(lp, "must be [finest, coarsest]");
    const std::int64_t a = r.integer((*levels)[0], Reader::index(lp, 0));
    const std::int64_t b = r.integer((*levels)[1], Reader::index(lp, 1));
    if (a < 0 || a > kMaxSceneLevel || b < 0 || b > kMaxSceneLevel) {
      r.fail(lp, "levels must be in 0.." + std::to_string(kMaxSceneLevel));
    }
    c.finest_level = std::uint32_t(a);
    c.coarsest_level = std::uint32_t(b);
  }
  if (const json* imp = r.find(j, "importance")) {
    const std::string ip = Reader::join(path, "importance");
    const std::int64_t v = r.integer(*imp, ip);
    if (v < INT32_MIN || v > INT32_MAX) r.fail(ip, "out of range");
    c.importance = std::int32_t(v);
  }
  read_channel_effects(r, j, path, c);
  return c;
}

void check_scene(const Scene& s, const std::string& what) {
  auto fail = [&](const std::string& path, const std::string& why) {
    throw Error(ErrorCode::invalid_argument, what + ": " + path + ": " + why);
  };
  const Camera& cam = s.camera;
  const auto finite3 = [](const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite3(cam.eye)) fail("camera.eye", "must be finite");
  if (!finite3(cam.target)) fail("camera.target", "must be finite");
  if (!finite3(cam.up)) fail("camera.up", "must be finite");
  if (!(cam.fov_deg > 0.0 && cam.fov_deg < 180.0)) {
    fail("camera.fov_deg", fmt(cam.fov_deg) + " outside (0, 180)");
  }
  if (!(cam.ortho_height > 0.0) || !std::isfinite(cam.ortho_height)) {
    fail("camera.ortho_height", "must be a positive finite number");
  }
  if (s.viewport.width < 1 || s.viewport.width > 16384) {
    fail("viewport.width", "must be in 1..16384");
  }
  if (s.viewport.height < 1 || s.viewport.height > 16384) {
    fail("viewport.height", "must be in 1..16384");
  }
  // The remaining camera conditions (eye != target, up not parallel) are CameraRays' own.
  try {
    CameraRays(cam, s.viewport);
  } catch (const Error& e) {
    fail("camera", e.what());
  }
  if (s.channels.empty()) fail("channels", "must list at least one channel");
  for (std::size_t i = 0; i < s.channels.size(); ++i) {
    const ChannelSettings& c = s.channels[i];
    const std::string p = "channels[" + std::to_string(i) + "]";
    if (c.channel >= kMaxChannels) fail(p + ".channel", "out of range");
    for (std::size_t k = 0; k < i; ++k) {
      if (s.channels[k].channel == c.channel) {
        fail(p + ".channel", "channel " + std::to_string(c.channel) + " is listed twice");
      }
    }
    if (c.coarsest_level > kMaxSceneLevel) fail(p + ".levels", "coarsest level out of range");
    if (c.finest_level > c.coarsest_level) {
      fail(p + ".levels", "finest " + std::to_string(c.finest_level) + " above coarsest " +
                              std::to_string(c.coarsest_level));
    }
  }
  if (!(s.step_scale >= 1e-6 && s.step_scale <= 1000.0)) {
    fail("step_scale", fmt(s.step_scale) + " outside [1e-6, 1000]");
  }
  if (!(s.lod_error_px > 0.0 && s.lod_error_px <= 1e6)) {
    fail("lod_error_px", fmt(s.lod_error_px) + " outside (0, 1e6]");
  }
  if (!(s.lod_error_color >= 0.0 && s.lod_error_color <= 1.0)) {
    fail("lod_error_color", fmt(s.lod_error_color) + " outside [0, 1]");
  }
  if (!(s.ert_opacity > 0.0 && s.ert_opacity <= 1.0)) {
    fail("ert_opacity", fmt(s.ert_opacity) + " outside (0, 1]");
  }
  for (int c = 0; c < 4; ++c) {
    if (!(s.background[c] >= 0.0 && s.background[c] <= 1.0)) {
      fail("background[" + std::to_string(c) + "]", fmt(s.background[c]) + " outside [0,1]");
    }
  }
  for (std::size_t i = 0; i < s.effects.size(); ++i) {
    for (std::size_t k = 0; k < i; ++k) {
      if (s.effects[k] == s.effects[i]) {
        fail("effects[" + std::to_string(i) + "]",
             std::string("'") + to_string(s.effects[i]) + "' is listed twice");
      }
    }
  }
  detail::check_slices_and_lens(s, what);
  check_effects(s, fail);
}

json vec_json(const double* v, int n) {
  json a = json::array();
  for (int i = 0; i < n; ++i) a.push_back(v[i]);
  return a;
}

}  // namespace

const char* to_string(Effect e) noexcept {
  return e == Effect::shadows ? "shadows" : "shading";
}

const char* to_string(ChannelMode m) noexcept {
  switch (m) {
    case ChannelMode::iso: return "iso";
    case ChannelMode::mip: return "mip";
    case ChannelMode::aip: return "aip";
    case ChannelMode::dvr: break;
  }
  return "dvr";
}

bool Scene::has_effect(Effect e) const noexcept {
  for (Effect x : effects) {
    if (x == e) return true;
  }
  return false;
}

bool Scene::needs_gradients() const noexcept {
  if (has_effect(Effect::shading)) return true;
  for (const ChannelSettings& c : channels) {
    if (c.mode == ChannelMode::iso) return true;
  }
  return false;
}

void Scene::validate(const std::string& what) const {
  check_scene(*this, what);
}

void Scene::validate(const VolumeDesc& volume, const std::string& what) const {
  check_scene(*this, what);
  for (std::size_t i = 0; i < channels.size(); ++i) {
    if (channels[i].channel >= volume.channels) {
      throw Error(ErrorCode::invalid_argument,
                  what + ": channels[" + std::to_string(i) + "].channel: channel " +
                      std::to_string(channels[i].channel) + " not in the volume's " +
                      std::to_string(volume.channels) + " channels");
    }
  }
}

void Scene::validate(const VolumeDesc& volume, std::uint32_t timepoints,
                     const std::string& what) const {
  validate(volume, what);
  if (timepoint && *timepoint >= timepoints) {
    throw Error(ErrorCode::invalid_argument,
                what + ": timepoint: " + std::to_string(*timepoint) + " but the volume has " +
                    std::to_string(timepoints) + " timepoint" + (timepoints == 1 ? "" : "s") +
                    " (0.." + std::to_string(timepoints == 0 ? 0 : timepoints - 1) + ")");
  }
}

Scene parse_scene(std::string_view json_text, const std::string& name) {
  json doc;
  try {
    doc = json::parse(json_text.begin(), json_text.end());
  } catch (const json::parse_error& e) {
    throw file_error(ErrorCode::corrupt, name, e.byte, std::string("malformed JSON: ") + e.what());
  } catch (const json::exception& e) {
    // Not only parse_error: a number literal beyond double's range ("1e3080") is out_of_range
    // 406, which has no byte offset. Found by fuzz/fuzz_scene_json.cpp.
    throw Error(ErrorCode::corrupt, name + ": malformed JSON: " + e.what());
  }
  const Reader r(name);
  if (!doc.is_object()) r.fail("(root)", "must be an object");
  r.only_keys(doc, "",
              {"camera", "viewport", "channels", "step_scale", "lod_error_px", "lod_error_color",
               "ert_opacity", "background", "effects", "slices", "lens", "light", "gradient",
               "shadow_lod_factor", "preintegration", "timepoint"});
  Scene s;
  s.camera = read_camera(r, r.require(doc, "", "camera"));
  if (const json* v = r.find(doc, "viewport")) s.viewport = read_viewport(r, *v);
  const json& channels = r.array(r.require(doc, "", "channels"), "channels");
  for (std::size_t i = 0; i < channels.size(); ++i) {
    s.channels.push_back(read_channel(r, channels[i], Reader::index("channels", i)));
  }
  if (const json* v = r.find(doc, "step_scale")) s.step_scale = r.number(*v, "step_scale");
  if (const json* v = r.find(doc, "lod_error_px")) s.lod_error_px = r.number(*v, "lod_error_px");
  if (const json* v = r.find(doc, "lod_error_color")) {
    s.lod_error_color = r.number(*v, "lod_error_color");
  }
  if (const json* v = r.find(doc, "ert_opacity")) s.ert_opacity = r.number(*v, "ert_opacity");
  if (const json* v = r.find(doc, "background")) s.background = r.vector<4>(*v, "background");
  if (const json* v = r.find(doc, "effects")) {
    r.array(*v, "effects");
    for (std::size_t i = 0; i < v->size(); ++i) {
      const std::string p = Reader::index("effects", i);
      const std::string e = r.string((*v)[i], p);
      if (e == "shading") {
        s.effects.push_back(Effect::shading);
      } else if (e == "shadows") {
        s.effects.push_back(Effect::shadows);
      } else {
        r.fail(p, "unknown effect '" + e + "' (known: \"shading\", \"shadows\")");
      }
    }
  }
  if (const json* v = r.find(doc, "preintegration")) {
    if (!v->is_boolean()) r.fail("preintegration", "must be true or false");
    s.preintegration = v->get<bool>();
  }
  if (const json* v = r.find(doc, "timepoint")) {
    const std::int64_t t = r.integer(*v, "timepoint");
    if (t < 0 || t > std::int64_t(UINT32_MAX)) {
      r.fail("timepoint", std::to_string(t) + " is not in 0.." + std::to_string(UINT32_MAX));
    }
    s.timepoint = std::uint32_t(t);
  }
  detail::read_slices_and_lens(doc, name, s);
  read_effect_options(r, doc, s);
  check_scene(s, name);
  return s;
}

Scene load_scene(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::io, path + ": cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::io, path + ": read failed");
  return parse_scene(text.str(), path);
}

std::string scene_to_json(const Scene& s) {
  json doc;
  json cam;
  cam["eye"] = vec_json(&s.camera.eye.x, 3);
  cam["target"] = vec_json(&s.camera.target.x, 3);
  cam["up"] = vec_json(&s.camera.up.x, 3);
  cam["fov_deg"] = s.camera.fov_deg;
  cam["ortho_height"] = s.camera.ortho_height;
  cam["projection"] = to_string(s.camera.projection);
  doc["camera"] = cam;
  doc["viewport"] = {{"width", s.viewport.width}, {"height", s.viewport.height}};
  json channels = json::array();
  for (const ChannelSettings& c : s.channels) {
    json tf = json::array();
    for (const TfPoint& p : c.tf.points()) {
      tf.push_back({p.value, p.rgba.r, p.rgba.g, p.rgba.b, p.rgba.a});
    }
    channels.push_back({{"channel", c.channel},
                        {"tf", tf},
                        {"levels", {c.finest_level, c.coarsest_level}},
                        {"importance", c.importance},
                        {"mode", to_string(c.mode)}});
    if (c.mode == ChannelMode::iso) channels.back()["isovalues"] = c.isovalues;
  }
  doc["channels"] = channels;
  doc["step_scale"] = s.step_scale;
  doc["lod_error_px"] = s.lod_error_px;
  // Written only when on, so that documents of scenes without it are unchanged.
  if (s.lod_error_color > 0.0) doc["lod_error_color"] = s.lod_error_color;
  doc["ert_opacity"] = s.ert_opacity;
  doc["background"] = vec_json(&s.background.x, 4);
  json effects = json::array();
  for (Effect e : s.effects) effects.push_back(to_string(e));
  doc["effects"] = effects;
  // Written only when on, so that documents of scenes without it are unchanged.
  if (s.preintegration) doc["preintegration"] = true;
  if (s.timepoint) doc["timepoint"] = *s.timepoint;  // likewise, only when given
  detail::slices_and_lens_to_json(s, doc);
  effects_to_json(s, doc);
  return doc.dump(2) + "\n";
}

void save_scene(const Scene& scene, const std::string& path) {
  scene.validate(path);
  const std::string text = scene_to_json(scene);
  AtomicFileWriter out(path);
  out.append(std::as_bytes(std::span(text.data(), text.size())));
  out.commit();
}

}  // namespace resoct
