#include "scene/scene_slices.hpp"

#include <cmath>
#include <cstdint>
#include <sstream>

#include <nlohmann/json.hpp>

#include "resoct/base/error.hpp"

namespace resoct::detail {
namespace {

using nlohmann::json;

// Orthonormality tolerance of the lens axes: loose enough for axes typed with 6-7 digits.
constexpr double kAxisTolerance = 1e-5;

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

class Reader {
 public:
  explicit Reader(const std::string& name) : name_(name) {}

  [[noreturn]] void fail(const std::string& path, const std::string& why) const {
    throw Error(ErrorCode::invalid_argument, name_ + ": " + path + ": " + why);
  }
  void object(const json& j, const std::string& path) const {
    if (!j.is_object()) fail(path, "must be an object");
  }
  void array(const json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, "must be an array");
  }
  void only_keys(const json& obj, const std::string& path,
                 std::initializer_list<const char*> keys) const {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      bool known = false;
      for (const char* k : keys) known = known || it.key() == k;
      if (!known) fail(path + "." + it.key(), "unknown key");
    }
  }
  const json* find(const json& obj, const char* key) const {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
  const json& require(const json& obj, const std::string& path, const char* key) const {
    const json* j = find(obj, key);
    if (j == nullptr) fail(path + "." + key, "missing");
    return *j;
  }
  double number(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "must be a number");
    return j.get<double>();
  }
  std::int64_t integer(const json& j, const std::string& path) const {
    if (!j.is_number_integer()) fail(path, "must be an integer");
    if (j.is_number_unsigned() && j.get<std::uint64_t>() > std::uint64_t(INT64_MAX)) {
      fail(path, "out of range");
    }
    return j.get<std::int64_t>();
  }
  glm::dvec3 vec3(const json& j, const std::string& path) const {
    array(j, path);
    if (j.size() != 3) fail(path, "must have 3 numbers");
    glm::dvec3 v;
    for (int i = 0; i < 3; ++i) v[i] = number(j[std::size_t(i)], index(path, std::size_t(i)));
    return v;
  }
  std::uint32_t channel(const json& j, const std::string& path) const {
    const std::int64_t c = integer(j, path);
    if (c < 0 || c >= std::int64_t(kMaxChannels)) {
      fail(path, "must be in 0.." + std::to_string(kMaxChannels - 1));
    }
    return std::uint32_t(c);
  }
  static std::string index(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }

 private:
  const std::string& name_;
};

SlicePlane read_slice(const Reader& r, const json& j, const std::string& path) {
  r.object(j, path);
  r.only_keys(j, path, {"point", "normal", "channels", "window", "level"});
  SlicePlane s;
  s.point = r.vec3(r.require(j, path, "point"), path + ".point");
  s.normal = r.vec3(r.require(j, path, "normal"), path + ".normal");
  const std::string cp = path + ".channels";
  const json& channels = r.require(j, path, "channels");
  r.array(channels, cp);
  for (std::size_t i = 0; i < channels.size(); ++i) {
    s.channels.push_back(r.channel(channels[i], Reader::index(cp, i)));
  }
  if (const json* w = r.find(j, "window")) s.window = r.number(*w, path + ".window");
  if (const json* l = r.find(j, "level")) s.level = r.number(*l, path + ".level");
  return s;
}

LensOutside read_outside(const Reader& r, const json& j, const std::string& path) {
  r.object(j, path);
  r.only_keys(j, path, {"channel", "hide", "levels"});
  LensOutside o;
  o.channel = r.channel(r.require(j, path, "channel"), path + ".channel");
  const json* hide = r.find(j, "hide");
  const json* levels = r.find(j, "levels");
  if (hide != nullptr) {
    if (!hide->is_boolean()) r.fail(path + ".hide", "must be true or false");
    o.hide = hide->get<bool>();
  }
  if (levels != nullptr) {
    const std::string lp = path + ".levels";
    if (hide != nullptr && o.hide) r.fail(lp, "a hidden channel takes no level range");
    r.array(*levels, lp);
    if (levels->size() != 2) r.fail(lp, "must be [finest, coarsest]");
    const std::int64_t a = r.integer((*levels)[0], Reader::index(lp, 0));
    const std::int64_t b = r.integer((*levels)[1], Reader::index(lp, 1));
    if (a < 0 || a > kMaxSceneLevel || b < 0 || b > kMaxSceneLevel) {
      r.fail(lp, "levels must be in 0.." + std::to_string(kMaxSceneLevel));
    }
    o.hide = false;
    o.finest_level = std::uint32_t(a);
    o.coarsest_level = std::uint32_t(b);
  } else if (hide != nullptr && !o.hide) {
    r.fail(path + ".hide", "false needs \"levels\": the level range shown outside the lens");
  }
  return o;
}

Lens read_lens(const Reader& r, const json& j) {
  const std::string path = "lens";
  r.object(j, path);
  r.only_keys(j, path, {"center", "size", "axes", "outside"});
  Lens l;
  l.center = r.vec3(r.require(j, path, "center"), "lens.center");
  l.size = r.vec3(r.require(j, path, "size"), "lens.size");
  if (const json* axes = r.find(j, "axes")) {
    r.array(*axes, "lens.axes");
    if (axes->size() != 3) r.fail("lens.axes", "must hold 3 axes");
    for (std::size_t i = 0; i < 3; ++i) {
      l.axes[int(i)] = r.vec3((*axes)[i], Reader::index("lens.axes", i));
    }
  }
  if (const json* outside = r.find(j, "outside")) {
    r.array(*outside, "lens.outside");
    for (std::size_t i = 0; i < outside->size(); ++i) {
      l.outside.push_back(read_outside(r, (*outside)[i], Reader::index("lens.outside", i)));
    }
  }
  return l;
}

bool finite3(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

json vec_json(const glm::dvec3& v) {
  return json::array({v.x, v.y, v.z});
}

}  // namespace

void read_slices_and_lens(const json& doc, const std::string& name, Scene& scene) {
  const Reader r(name);
  if (const json* slices = r.find(doc, "slices")) {
    r.array(*slices, "slices");
    for (std::size_t i = 0; i < slices->size(); ++i) {
      scene.slices.push_back(read_slice(r, (*slices)[i], Reader::index("slices", i)));
    }
  }
  if (const json* lens = r.find(doc, "lens")) {
    if (!lens->is_null()) scene.lens = read_lens(r, *lens);
  }
}

void check_slices_and_lens(const Scene& s, const std::string& what) {
  auto fail = [&](const std::string& path, const std::string& why) {
    throw Error(ErrorCode::invalid_argument, what + ": " + path + ": " + why);
  };
  auto in_scene = [&](std::uint32_t channel) {
    for (const ChannelSettings& c : s.channels) {
      if (c.channel == channel) return true;
    }
    return false;
  };
  if (s.slices.size() > kMaxSlices) {
    fail("slices",
         std::to_string(s.slices.size()) + " planes, at most " + std::to_string(kMaxSlices));
  }
  for (std::size_t i = 0; i < s.slices.size(); ++i) {
    const SlicePlane& p = s.slices[i];
    const std::string path = "slices[" + std::to_string(i) + "]";
    if (!finite3(p.point)) fail(path + ".point", "must be finite");
    if (!finite3(p.normal)) fail(path + ".normal", "must be finite");
    if (!(glm::length(p.normal) > 1e-12)) fail(path + ".normal", "must not be zero");
    if (p.channels.empty()) fail(path + ".channels", "must list at least one channel");
    for (std::size_t k = 0; k < p.channels.size(); ++k) {
      const std::string cp = path + ".channels[" + std::to_string(k) + "]";
      if (!in_scene(p.channels[k])) {
        fail(cp,
             "channel " + std::to_string(p.channels[k]) + " is not one of the scene's channels");
      }
      for (std::size_t m = 0; m < k; ++m) {
        if (p.channels[m] == p.channels[k]) fail(cp, "listed twice");
      }
    }
    if (p.window.has_value() != p.level.has_value()) {
      fail(path + (p.window ? ".level" : ".window"), "window and level go together");
    }
    if (p.window && !(std::isfinite(*p.window) && *p.window > 0.0)) {
      fail(path + ".window", fmt(*p.window) + " must be a positive finite number");
    }
    if (p.level && !std::isfinite(*p.level)) fail(path + ".level", "must be finite");
  }
  if (!s.lens) return;
  const Lens& l = *s.lens;
  if (!finite3(l.center)) fail("lens.center", "must be finite");
  for (int a = 0; a < 3; ++a) {
    if (!(std::isfinite(l.size[a]) && l.size[a] > 0.0)) {
      fail("lens.size[" + std::to_string(a) + "]", fmt(l.size[a]) + " must be positive");
    }
  }
  for (int a = 0; a < 3; ++a) {
    const std::string ap = "lens.axes[" + std::to_string(a) + "]";
    if (!finite3(l.axes[a])) fail(ap, "must be finite");
    if (!(std::abs(glm::length(l.axes[a]) - 1.0) <= kAxisTolerance)) {
      fail(ap, "must be a unit vector (axes must be orthonormal)");
    }
    for (int b = 0; b < a; ++b) {
      if (!(std::abs(glm::dot(l.axes[a], l.axes[b])) <= kAxisTolerance)) {
        fail(ap,
             "not orthogonal to lens.axes[" + std::to_string(b) + "] (axes must be orthonormal)");
      }
    }
  }
  for (std::size_t i = 0; i < l.outside.size(); ++i) {
    const LensOutside& o = l.outside[i];
    const std::string path = "lens.outside[" + std::to_string(i) + "]";
    if (!in_scene(o.channel)) {
      fail(path + ".channel",
           "channel " + std::to_string(o.channel) + " is not one of the scene's channels");
    }
    for (std::size_t k = 0; k < i; ++k) {
      if (l.outside[k].channel == o.channel) fail(path + ".channel", "listed twice");
    }
    if (!o.hide) {
      if (o.coarsest_level > kMaxSceneLevel) fail(path + ".levels", "coarsest level out of range");
      if (o.finest_level > o.coarsest_level) {
        fail(path + ".levels", "finest " + std::to_string(o.finest_level) + " above coarsest " +
                                   std::to_string(o.coarsest_level));
      }
    }
  }
}

void slices_and_lens_to_json(const Scene& s, json& doc) {
  if (!s.slices.empty()) {
    json slices = json::array();
    for (const SlicePlane& p : s.slices) {
      json j = {
          {"point", vec_json(p.point)}, {"normal", vec_json(p.normal)}, {"channels", p.channels}};
      if (p.window) j["window"] = *p.window;
      if (p.level) j["level"] = *p.level;
      slices.push_back(j);
    }
    doc["slices"] = slices;
  }
  if (s.lens) {
    const Lens& l = *s.lens;
    json outside = json::array();
    for (const LensOutside& o : l.outside) {
      json j = {{"channel", o.channel}};
      if (o.hide) {
        j["hide"] = true;
      } else {
        j["levels"] = {o.finest_level, o.coarsest_level};
      }
      outside.push_back(j);
    }
    doc["lens"] = {{"center", vec_json(l.center)},
                   {"size", vec_json(l.size)},
                   {"axes", {vec_json(l.axes[0]), vec_json(l.axes[1]), vec_json(l.axes[2])}},
                   {"outside", outside}};
  }
}

}  // namespace resoct::detail
