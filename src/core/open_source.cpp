#include "resoct/open_source.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <sys/stat.h>

#include "resoct/brick_store.hpp"
#include "resoct/error.hpp"
#include "resoct/file_io.hpp"
#include "resoct/formats/channel_stack.hpp"
#include "resoct/formats/nifti.hpp"
#include "resoct/formats/nrrd.hpp"
#include "resoct/formats/ome_zarr.hpp"
#include "resoct/formats/tiff_stack.hpp"
#include "resoct/http_store.hpp"
#include "resoct/procedural_source.hpp"
#include "resoct/store/format.hpp"

namespace resoct {

namespace {

constexpr std::string_view kProceduralPrefix = "procedural:";
constexpr std::string_view kStackPrefix = "stack:";

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

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](char c) { return char(std::tolower(c)); });
  return s;
}

bool ends_with(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

SourceKind kind_of_directory(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(fs::path(path) / ".zattrs", ec) || fs::exists(fs::path(path) / ".zarray", ec) ||
      fs::exists(fs::path(path) / "zarr.json", ec)) {
    return SourceKind::ome_zarr;
  }
  for (const auto& e : fs::directory_iterator(path, ec)) {
    const std::string name = lower(e.path().filename().string());
    if (ends_with(name, ".tif") || ends_with(name, ".tiff")) return SourceKind::tiff;
  }
  return SourceKind::unknown;
}

SourceKind kind_of_file(const std::string& path) {
  if (has_store_magic(ReadFile(path))) return SourceKind::brick_store;
  const std::string name = lower(std::filesystem::path(path).filename().string());
  if (ends_with(name, ".nii") || ends_with(name, ".nii.gz")) return SourceKind::nifti;
  if (ends_with(name, ".nrrd") || ends_with(name, ".nhdr")) return SourceKind::nrrd;
  if (ends_with(name, ".tif") || ends_with(name, ".tiff")) return SourceKind::tiff;
  return SourceKind::unknown;
}

std::unique_ptr<BrickSource> open_stack(std::string_view list, const BrickLayout& layout) {
  std::vector<std::shared_ptr<const BrickSource>> parts;
  while (true) {
    const std::size_t plus = list.find('+');
    const std::string_view part = list.substr(0, plus);
    if (part.empty()) throw invalid_parameter("spec", "empty part in a stack: spec" + accepted());
    parts.push_back(open_source(part, layout));
    if (plus == std::string_view::npos) break;
    list.remove_prefix(plus + 1);
  }
  std::string name = std::string(kStackPrefix);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i != 0) name += '+';
    name += parts[i]->name();
  }
  return stack_channels(std::move(parts), std::move(name));
}

/// An http(s) URL: an OME-Zarr image when a URL map is given or the URL has zarr metadata below
/// it (.zattrs or .zarray: 0.4 over zarr v2; zarr.json: 0.5 over zarr v3), else a brick store file
/// read by Range requests.
std::unique_ptr<BrickSource> open_url(const std::string& spec, const BrickLayout& layout) {
  if (spec.find_first_of("?#") != std::string::npos) {
    throw invalid_parameter("spec",
                            "URL '" + spec + "' has a query or fragment, which is unsupported");
  }
  std::shared_ptr<const HttpStore> store = open_http_store(spec);
  if (spec.find(',') != std::string::npos || store->size(".zattrs") || store->size(".zarray") ||
      store->size("zarr.json")) {
    return open_ome_zarr(store, layout);
  }
  // Range requests only: the store's index and metadata are read once, bricks on demand.
  auto file = open_random_access_file(spec);
  if (!has_store_magic(*file)) {
    throw file_error(
        ErrorCode::invalid_argument, spec, 0,
        "neither an OME-Zarr image (no .zattrs/.zarray/zarr.json below the URL) nor a resoct "
        "brick store (no store magic)" +
            accepted());
  }
  return std::make_unique<BrickStoreSource>(std::move(file));
}

}  // namespace

std::string_view to_string(SourceKind k) noexcept {
  switch (k) {
    case SourceKind::unknown: return "unknown";
    case SourceKind::procedural: return "procedural";
    case SourceKind::brick_store: return "store";
    case SourceKind::ome_zarr: return "ome-zarr";
    case SourceKind::nifti: return "nifti";
    case SourceKind::nrrd: return "nrrd";
    case SourceKind::tiff: return "tiff";
    case SourceKind::stack: return "stack";
  }
  return "unknown";
}

SourceKind detect_source_kind(std::string_view spec) {
  if (spec.starts_with(kProceduralPrefix)) return SourceKind::procedural;
  if (spec.starts_with(kStackPrefix)) return SourceKind::stack;
  if (spec.empty()) return SourceKind::unknown;
  const std::string path(spec);
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return SourceKind::unknown;
  if (S_ISDIR(st.st_mode)) return kind_of_directory(path);
  if (!S_ISREG(st.st_mode)) return SourceKind::unknown;
  return kind_of_file(path);
}

std::unique_ptr<BrickSource> open_source(std::string_view spec, const BrickLayout& layout) {
  if (spec.starts_with(kProceduralPrefix)) return make_procedural_source(spec, layout);
  if (spec.starts_with(kStackPrefix)) return open_stack(spec.substr(kStackPrefix.size()), layout);
  if (spec.empty()) throw invalid_parameter("spec", "empty source" + accepted());
  const std::string path(spec);
  if (is_http_url(spec)) return open_url(path, layout);
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    throw file_error(ErrorCode::io, path, 0,
                     std::string("cannot open: ") + std::strerror(err) +
                         (err == ENOENT ? accepted() : std::string()));
  }
  if (S_ISDIR(st.st_mode)) {
    switch (kind_of_directory(path)) {
      case SourceKind::ome_zarr: return open_ome_zarr(path, layout);
      case SourceKind::tiff: return open_tiff_stack(path, layout);
      default:
        throw file_error(
            ErrorCode::invalid_argument, path, 0,
            "directory is neither an OME-Zarr image (.zattrs/.zarray/zarr.json) nor holds TIFF "
            "files" +
                accepted());
    }
  }
  if (!S_ISREG(st.st_mode)) {
    throw file_error(ErrorCode::io, path, 0, "not a regular file" + accepted());
  }
  switch (kind_of_file(path)) {
    case SourceKind::brick_store: return std::make_unique<BrickStoreSource>(path);
    case SourceKind::nifti: return open_nifti(path, layout);
    case SourceKind::nrrd: return open_nrrd(path, layout);
    case SourceKind::tiff: return open_tiff_stack(path, layout);
    default:
      throw file_error(ErrorCode::invalid_argument, path, 0,
                       "not a resoct brick store (no store magic) nor a file of a known "
                       "extension" +
                           accepted() + " (raw files: resoct-convert --dims --type)");
  }
}

}  // namespace resoct
