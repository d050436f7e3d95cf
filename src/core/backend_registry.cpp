#include <map>
#include <mutex>

#include "resoct/backend.hpp"
#include "resoct/error.hpp"

namespace resoct {

namespace {
struct Registry {
  std::mutex mutex;
  std::map<std::string, BackendFactory, std::less<>> factories;
};
Registry& registry() {
  static Registry r;
  return r;
}
}  // namespace

const char* to_string(RenderMode m) noexcept {
  switch (m) {
    case RenderMode::residency: return "residency";
    case RenderMode::pagetable: return "pagetable";
    case RenderMode::octree: return "octree";
  }
  return "unknown";
}

RenderMode parse_render_mode(std::string_view s) {
  if (s == "residency") return RenderMode::residency;
  if (s == "pagetable") return RenderMode::pagetable;
  if (s == "octree") return RenderMode::octree;
  throw invalid_parameter("mode",
                          "'" + std::string(s) + "' is not one of residency, pagetable, octree");
}

void register_backend(const std::string& name, BackendFactory factory) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.factories[name] = std::move(factory);
}

std::vector<std::string> backend_names() {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, factory] : r.factories) names.push_back(name);
  return names;
}

std::unique_ptr<Backend> create_backend(std::string_view name, const BackendOptions& options) {
  BackendFactory factory;
  {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    auto it = r.factories.find(name);
    if (it == r.factories.end()) {
      std::string known;
      for (const auto& [n, f] : r.factories) known += (known.empty() ? "" : ", ") + n;
      throw invalid_parameter("backend", "'" + std::string(name) + "' is not registered (known: " +
                                             (known.empty() ? "none" : known) + ")");
    }
    factory = it->second;
  }
  return factory(options);
}

}  // namespace resoct
