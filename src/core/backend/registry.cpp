#include <map>
#include <mutex>

#include "resoct/backend/backend.hpp"
#include "resoct/base/error.hpp"

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
      // The usual cause is a backend library whose register_backend() was never called; a
      // backend object (resoct::cpu::make_backend()) needs no registration at all.
      throw invalid_parameter("backend", "'" + std::string(name) + "' is not registered (known: " +
                                             (known.empty() ? "none" : known) +
                                             "); call resoct::cpu::register_backend() (or "
                                             "resoct::vk::register_backend()) first, or pass a "
                                             "backend object to the Renderer");
    }
    factory = it->second;
  }
  return factory(options);
}

}  // namespace resoct
