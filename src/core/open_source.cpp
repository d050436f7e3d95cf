#include "resoct/open_source.hpp"

#include <array>
#include <cerrno>
#include <cstring>
#include <string>

#include <sys/stat.h>

#include "resoct/brick_store.hpp"
#include "resoct/error.hpp"
#include "resoct/file_io.hpp"
#include "resoct/http_store.hpp"
#include "resoct/procedural_source.hpp"
#include "resoct/store/format.hpp"

namespace resoct {

namespace {

constexpr std::string_view kProceduralPrefix = "procedural:";

std::string accepted() {
  return "; accepted: " + std::string(kSourceSpecForms);
}

bool has_store_magic(const RandomAccessFile& file) {
  const auto& magic = detail::kStoreMagic;
  if (file.size() < magic.size()) return false;
  std::array<std::byte, detail::kStoreMagic.size()> head{};
  file.read_at(0, head);
  for (std::size_t i = 0; i < magic.size(); ++i) {
    if (head[i] != std::byte(magic[i])) return false;
  }
  return true;
}

}  // namespace

std::unique_ptr<BrickSource> open_source(std::string_view spec, const BrickLayout& layout) {
  if (spec.starts_with(kProceduralPrefix)) return make_procedural_source(spec, layout);
  if (spec.empty()) throw invalid_parameter("spec", "empty source" + accepted());
  const std::string path(spec);
  if (is_http_url(spec)) {
    // Range requests only: the store's index and metadata are read once, bricks on demand.
    auto file = open_random_access_file(path);
    if (!has_store_magic(*file)) {
      throw file_error(ErrorCode::invalid_argument, path, 0,
                       "not a resoct brick store (no store magic)" + accepted());
    }
    return std::make_unique<BrickStoreSource>(std::move(file));
  }
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    throw file_error(ErrorCode::io, path, 0,
                     std::string("cannot open: ") + std::strerror(err) +
                         (err == ENOENT ? accepted() : std::string()));
  }
  if (!S_ISREG(st.st_mode)) {
    throw file_error(ErrorCode::io, path, 0, "not a regular file" + accepted());
  }
  const ReadFile file(path);
  if (!has_store_magic(file)) {
    throw file_error(ErrorCode::invalid_argument, path, 0,
                     "not a resoct brick store (no store magic)" + accepted() +
                         " (raw files: resoct-convert --dims --type)");
  }
  return std::make_unique<BrickStoreSource>(path);
}

}  // namespace resoct
