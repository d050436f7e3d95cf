#include "io/storage/confined_path.hpp"

#include <string>
#include <system_error>

#include "resoct/base/error.hpp"

namespace resoct::detail {

namespace {

namespace fs = std::filesystem;

/// True when `p` lies strictly below `root`, compared component by component ("/a/bc" is not
/// below "/a/b", which a string prefix test would accept).
bool strictly_below(const fs::path& root, const fs::path& p) {
  auto r = root.begin();
  auto q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    // A trailing separator of `root` iterates as an empty component.
    if (r->empty() && std::next(r) == root.end()) break;
    if (q == p.end() || *q != *r) return false;
  }
  return q != p.end() && !q->empty();
}

[[noreturn]] void refuse(std::string_view referrer, std::string_view what, std::string_view name,
                         std::string_view why) {
  throw Error(ErrorCode::invalid_argument, std::string(referrer) + ": " + std::string(what) + " '" +
                                               std::string(name) + "' " + std::string(why));
}

/// weakly_canonical reports failures (a loop of symlinks, a component that is not a directory)
/// as exceptions or error codes; both become the same refusal.
fs::path resolve(const fs::path& p, std::string_view referrer, std::string_view what,
                 std::string_view name) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(p, ec);
  if (ec) refuse(referrer, what, name, "cannot be resolved: " + ec.message());
  return r;
}

}  // namespace

fs::path canonical_root(const fs::path& root) {
  std::error_code ec;
  fs::path r = fs::canonical(root, ec);
  if (ec) throw Error(ErrorCode::io, root.string() + ": cannot resolve directory: " + ec.message());
  return r;
}

fs::path confined_path(const fs::path& root, std::string_view name, std::string_view referrer,
                       std::string_view what) {
  const fs::path p(name);
  if (name.empty()) refuse(referrer, what, name, "is empty");
  if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) {
    refuse(referrer, what, name, "is absolute; only paths below " + root.string() + " are read");
  }
  for (const fs::path& part : p) {
    if (part == "..") {
      refuse(referrer, what, name,
             "has a '..' component; only paths below " + root.string() + " are read");
    }
  }
  const fs::path resolved = resolve(root / p, referrer, what, name);
  if (!strictly_below(root, resolved)) {
    refuse(referrer, what, name,
           "resolves to " + resolved.string() + ", which is not below " + root.string());
  }
  return resolved;
}

fs::path check_confined(const fs::path& root, const fs::path& path, std::string_view referrer) {
  const std::string name = path.string();
  const fs::path resolved = resolve(path, referrer, "entry", name);
  if (!strictly_below(root, resolved)) {
    refuse(referrer, "entry", name,
           "resolves to " + resolved.string() + ", which is not below " + root.string());
  }
  return resolved;
}

}  // namespace resoct::detail
