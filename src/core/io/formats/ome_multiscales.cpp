#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "resoct/io/storage/byte_store.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/ome_multiscales.hpp"

namespace resoct {

namespace {

using Json = nlohmann::json;

Error corrupt(std::string_view location, const std::string& key, std::string_view why) {
  return Error(ErrorCode::corrupt,
               std::string(location) + ": key '" + key + "': " + std::string(why));
}

int axis_rank(char a) {
  switch (a) {
    case 't': return 0;
    case 'c': return 1;
    case 'z': return 2;
    case 'y': return 3;
    case 'x': return 4;
    default: return -1;
  }
}

void parse_axes(const Json& j, std::string_view location, const std::string& key,
                OmeMultiscales& m) {
  if (!j.is_array() || j.empty() || j.size() > 5) {
    throw corrupt(location, key, "expected an array of 1..5 axes");
  }
  int last = -1;
  bool spatial = false;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const Json& a = j[i];
    std::string name, unit;
    // 0.4 writes objects; 0.3 wrote bare names, which cost nothing to accept.
    if (a.is_string()) {
      name = a.get<std::string>();
    } else if (a.is_object() && a.contains("name") && a["name"].is_string()) {
      name = a["name"].get<std::string>();
      if (a.contains("unit") && a["unit"].is_string()) unit = a["unit"].get<std::string>();
    } else {
      throw corrupt(location, key + "[" + std::to_string(i) + "]",
                    "expected a name or an object with a string 'name'");
    }
    const int rank = name.size() == 1 ? axis_rank(name[0]) : -1;
    if (rank < 0) {
      throw corrupt(location, key + "[" + std::to_string(i) + "]",
                    "axis '" + name + "' is not one of t, c, z, y, x");
    }
    if (rank <= last) {
      throw corrupt(location, key,
                    "axes must be a subset of t, c, z, y, x in that order, each once");
    }
    last = rank;
    spatial = spatial || rank >= 2;
    m.axes.push_back(name[0]);
    m.units.push_back(unit);
  }
  if (!spatial) throw corrupt(location, key, "no spatial axis (z, y or x)");
}

std::vector<double> numbers(const Json& j, std::size_t n, std::string_view location,
                            const std::string& key, bool positive) {
  if (!j.is_array() || j.size() != n) {
    throw corrupt(location, key, "expected " + std::to_string(n) + " numbers (one per axis)");
  }
  std::vector<double> v;
  for (const Json& x : j) {
    if (!x.is_number()) throw corrupt(location, key, "expected numbers, got " + x.dump());
    const double d = x.get<double>();
    if (!std::isfinite(d) || (positive && !(d > 0.0))) {
      throw corrupt(location, key,
                    std::string(positive ? "scales must be positive finite numbers"
                                         : "translations must be finite numbers") +
                        ", got " + x.dump());
    }
    v.push_back(d);
  }
  return v;
}

/// Applies a coordinateTransformations list to (scale, translation).
void transforms(const Json& j, std::size_t n, std::string_view location, const std::string& key,
                std::vector<double>& scale, std::vector<double>& translation, bool need_scale) {
  if (!j.is_array()) throw corrupt(location, key, "expected an array");
  bool have_scale = false;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const Json& t = j[i];
    const std::string k = key + "[" + std::to_string(i) + "]";
    if (!t.is_object() || !t.contains("type") || !t["type"].is_string()) {
      throw corrupt(location, k, "expected an object with a string 'type'");
    }
    const std::string type = t["type"].get<std::string>();
    if (type == "scale") {
      if (!t.contains("scale")) throw corrupt(location, k, "scale transformation without 'scale'");
      const auto s = numbers(t["scale"], n, location, k + ".scale", true);
      for (std::size_t a = 0; a < n; ++a) {
        scale[a] *= s[a];
        translation[a] *= s[a];
      }
      have_scale = true;
    } else if (type == "translation") {
      if (!t.contains("translation")) {
        throw corrupt(location, k, "translation transformation without 'translation'");
      }
      const auto s = numbers(t["translation"], n, location, k + ".translation", false);
      for (std::size_t a = 0; a < n; ++a) translation[a] += s[a];
    } else if (type != "identity") {
      throw corrupt(location, k, "unknown transformation type '" + type + "'");
    }
  }
  if (need_scale && !have_scale) throw corrupt(location, key, "no scale transformation");
}

void parse_omero(const Json& j, std::string_view location, const std::string& prefix,
                 OmeMultiscales& m) {
  if (!j.is_object() || !j.contains("channels")) return;
  const Json& chans = j["channels"];
  if (!chans.is_array()) throw corrupt(location, prefix + "omero.channels", "expected an array");
  for (std::size_t i = 0; i < chans.size(); ++i) {
    const Json& c = chans[i];
    const std::string key = prefix + "omero.channels[" + std::to_string(i) + "]";
    if (!c.is_object()) throw corrupt(location, key, "expected an object");
    OmeChannel ch;
    if (c.contains("label") && c["label"].is_string()) ch.label = c["label"].get<std::string>();
    if (c.contains("color") && c["color"].is_string()) ch.color = c["color"].get<std::string>();
    if (c.contains("window")) {
      const Json& w = c["window"];
      if (!w.is_object() || !w.contains("start") || !w.contains("end") || !w["start"].is_number() ||
          !w["end"].is_number()) {
        throw corrupt(location, key + ".window", "expected numbers 'start' and 'end'");
      }
      const double lo = w["start"].get<double>(), hi = w["end"].get<double>();
      if (std::isfinite(lo) && std::isfinite(hi) && lo < hi) ch.window = ValueRange{lo, hi};
    }
    m.channels.push_back(std::move(ch));
  }
}

}  // namespace

int OmeMultiscales::axis_index(char axis) const noexcept {
  for (std::size_t i = 0; i < axes.size(); ++i) {
    if (axes[i] == axis) return int(i);
  }
  return -1;
}

namespace {

Json parse_json(std::string_view json, std::string_view location) {
  try {
    return Json::parse(json.begin(), json.end());
  } catch (const Json::exception& e) {
    throw Error(ErrorCode::corrupt, std::string(location) + ": not valid JSON: " + e.what());
  }
}

/// The image metadata of `attrs` (the `.zattrs` object of 0.4, `attributes.ome` of 0.5); keys
/// in messages start with `prefix`. `version` is 0.5's `attributes.ome.version`, or empty for
/// 0.4, whose version sits in each multiscales entry.
OmeMultiscales parse_image_attributes(const Json& j, std::string_view location,
                                      const std::string& prefix, const std::string& version) {
  if (!j.is_object() || !j.contains("multiscales")) {
    throw Error(ErrorCode::bad_magic, std::string(location) + ": no '" + prefix +
                                          "multiscales' key (not an OME-Zarr image group)");
  }
  const Json& all = j["multiscales"];
  if (!all.is_array() || all.empty() || !all[0].is_object()) {
    throw corrupt(location, prefix + "multiscales", "expected a non-empty array of objects");
  }
  const Json& ms = all[0];
  const std::string base = prefix + "multiscales[0]";
  OmeMultiscales m;
  if (version.empty()) {
    if (!ms.contains("version") || !ms["version"].is_string()) {
      throw corrupt(location, base + ".version", "missing or not a string");
    }
    m.version = ms["version"].get<std::string>();
    if (m.version != "0.4") {
      throw Error(ErrorCode::unsupported_version, std::string(location) + ": key '" + base +
                                                      ".version': '" + m.version +
                                                      "' is not supported (NGFF 0.4)");
    }
  } else {
    m.version = version;
  }
  if (ms.contains("name") && ms["name"].is_string()) m.name = ms["name"].get<std::string>();
  if (!ms.contains("axes")) throw corrupt(location, base + ".axes", "missing");
  parse_axes(ms["axes"], location, base + ".axes", m);
  const std::size_t n = m.axes.size();
  if (!ms.contains("datasets") || !ms["datasets"].is_array() || ms["datasets"].empty()) {
    throw corrupt(location, base + ".datasets", "expected a non-empty array");
  }
  const Json& sets = ms["datasets"];
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const std::string key = base + ".datasets[" + std::to_string(i) + "]";
    const Json& d = sets[i];
    if (!d.is_object() || !d.contains("path") || !d["path"].is_string()) {
      throw corrupt(location, key + ".path", "missing or not a string");
    }
    OmeDataset ds;
    ds.path = d["path"].get<std::string>();
    try {
      check_store_key(ds.path);
    } catch (const Error&) {
      throw corrupt(location, key + ".path", "'" + ds.path + "' is not a relative store key");
    }
    ds.scale.assign(n, 1.0);
    ds.translation.assign(n, 0.0);
    if (!d.contains("coordinateTransformations")) {
      throw corrupt(location, key + ".coordinateTransformations", "missing");
    }
    transforms(d["coordinateTransformations"], n, location, key + ".coordinateTransformations",
               ds.scale, ds.translation, true);
    m.datasets.push_back(std::move(ds));
  }
  if (ms.contains("coordinateTransformations")) {
    for (OmeDataset& ds : m.datasets) {
      transforms(ms["coordinateTransformations"], n, location, base + ".coordinateTransformations",
                 ds.scale, ds.translation, false);
    }
  }
  if (j.contains("omero")) parse_omero(j["omero"], location, prefix, m);
  return m;
}

}  // namespace

OmeMultiscales parse_ome_multiscales(std::string_view json, std::string_view location) {
  return parse_image_attributes(parse_json(json, location), location, "", "");
}

OmeMultiscales parse_ome_zarr_group(std::string_view json, std::string_view location) {
  const Json j = parse_json(json, location);
  if (!j.is_object()) throw corrupt(location, "(root)", "expected a JSON object");
  if (!j.contains("zarr_format") || j["zarr_format"] != 3) {
    throw Error(ErrorCode::unsupported_version,
                std::string(location) + ": key 'zarr_format': " +
                    (j.contains("zarr_format") ? j["zarr_format"].dump() : "missing") +
                    " (a zarr v3 group has 3)");
  }
  if (!j.contains("node_type") || j["node_type"] != "group") {
    throw Error(ErrorCode::bad_magic,
                std::string(location) + ": key 'node_type': not \"group\" (not an image group)");
  }
  if (!j.contains("attributes") || !j["attributes"].is_object() ||
      !j["attributes"].contains("ome")) {
    throw Error(ErrorCode::bad_magic,
                std::string(location) + ": no 'attributes.ome' key (not an OME-Zarr image group)");
  }
  const Json& ome = j["attributes"]["ome"];
  if (!ome.is_object()) throw corrupt(location, "attributes.ome", "expected an object");
  if (!ome.contains("version") || !ome["version"].is_string()) {
    throw corrupt(location, "attributes.ome.version", "missing or not a string");
  }
  const std::string version = ome["version"].get<std::string>();
  if (version != "0.5") {
    throw Error(ErrorCode::unsupported_version, std::string(location) +
                                                    ": key 'attributes.ome.version': '" + version +
                                                    "' is not supported (NGFF 0.5)");
  }
  return parse_image_attributes(ome, location, "attributes.ome.", version);
}

}  // namespace resoct
