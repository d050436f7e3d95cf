#include "resoct/io/open_source.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <sys/stat.h>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/io/formats/channel_stack.hpp"
#include "resoct/io/formats/nifti.hpp"
#include "resoct/io/formats/nrrd.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/formats/tiff_stack.hpp"
#include "resoct/io/http/http_store.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/io/http/open_random_access_file.hpp"
#include "resoct/io/http/s3_store.hpp"
#include "resoct/io/store/format.hpp"

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
  // NIfTI-1/2 single files, and either file of a NIfTI / Analyze 7.5 pair (.hdr + .img).
  for (const char* ext : {".nii", ".hdr", ".img"}) {
    if (ends_with(name, ext) || ends_with(name, std::string(ext) + ".gz")) return SourceKind::nifti;
  }
  if (ends_with(name, ".nrrd") || ends_with(name, ".nhdr")) return SourceKind::nrrd;
  if (ends_with(name, ".tif") || ends_with(name, ".tiff")) return SourceKind::tiff;
  return SourceKind::unknown;
}

std::unique_ptr<BrickSource> open_stack(std::string_view list, const BrickLayout& layout,
                                        const SourceOptions& options) {
  std::vector<std::shared_ptr<const BrickSource>> parts;
  while (true) {
    const std::size_t plus = list.find('+');
    const std::string_view part = list.substr(0, plus);
    if (part.empty()) throw invalid_parameter("spec", "empty part in a stack: spec" + accepted());
    parts.push_back(open_source(part, layout, options));
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

/// An OME-Zarr image when `store` has zarr metadata at its root, else nullptr. S3 asks with GET:
/// a 404 for a missing bucket carries the store's error code in its body, so that it fails
/// there (HttpStore::get) instead of reading as "no such object" (a HEAD answer has no body).
std::unique_ptr<BrickSource> open_if_zarr(const std::shared_ptr<const HttpStore>& store,
                                          bool probe_with_get, const BrickLayout& layout) {
  constexpr std::uint64_t kProbeBytes = 64 << 20;  // zarr metadata is small
  // .zattrs / .zarray: 0.4 over zarr v2; zarr.json: 0.5 over zarr v3.
  for (const char* key : {".zattrs", ".zarray", "zarr.json"}) {
    const bool found =
        probe_with_get ? store->get(key, kProbeBytes).has_value() : store->size(key).has_value();
    if (found) return open_ome_zarr(store, layout);
  }
  return nullptr;
}

std::unique_ptr<BrickSource> open_brick_store_file(std::unique_ptr<RandomAccessFile> file,
                                                   const std::string& spec) {
  if (!has_store_magic(*file)) {
    throw file_error(
        ErrorCode::invalid_argument, spec, 0,
        "neither an OME-Zarr image (no .zattrs/.zarray/zarr.json below it) nor a resoct "
        "brick store (no store magic)" +
            accepted());
  }
  return std::make_unique<BrickStoreSource>(std::move(file));
}

/// An http(s) URL: an OME-Zarr image when a URL map is given or the URL has zarr metadata below
/// it, else a brick store file read by Range requests.
std::unique_ptr<BrickSource> open_url(const std::string& spec, const BrickLayout& layout,
                                      const HttpOptions& http) {
  if (spec.find_first_of("?#") != std::string::npos) {
    throw invalid_parameter("spec",
                            "URL '" + spec + "' has a query or fragment, which is unsupported");
  }
  std::shared_ptr<const HttpStore> store = open_http_store(spec, http);
  if (spec.find(',') != std::string::npos) return open_ome_zarr(store, layout);
  if (auto zarr = open_if_zarr(store, false, layout)) return zarr;
  // Range requests only: the store's index and metadata are read once, bricks on demand.
  return open_brick_store_file(open_random_access_file(spec, http), spec);
}

/// An s3://bucket/key spec: as open_url, in an S3-compatible object store.
std::unique_ptr<BrickSource> open_s3(const std::string& spec, const BrickLayout& layout,
                                     const SourceOptions& options) {
  S3Config config;
  try {
    config = resolve_s3_config(options.s3);
  } catch (const Error& e) {
    // The configuration comes from elsewhere (options, environment); say which spec needed it.
    throw Error(e.code(), "'" + spec + "': " + e.what());
  }
  std::shared_ptr<const HttpStore> store = open_s3_store(spec, config, options.http);
  if (auto zarr = open_if_zarr(store, true, layout)) return zarr;
  return open_brick_store_file(open_s3_object(spec, config, options.http), spec);
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
  return open_source(spec, layout, SourceOptions{});
}

std::unique_ptr<BrickSource> open_source(std::string_view spec, const BrickLayout& layout,
                                         const SourceOptions& options) {
  if (spec.starts_with(kProceduralPrefix)) return make_procedural_source(spec, layout);
  if (spec.starts_with(kStackPrefix)) {
    return open_stack(spec.substr(kStackPrefix.size()), layout, options);
  }
  if (spec.empty()) throw invalid_parameter("spec", "empty source" + accepted());
  const std::string path(spec);
  if (is_http_url(spec)) return open_url(path, layout, options.http);
  if (is_s3_url(spec)) return open_s3(path, layout, options);
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
    case SourceKind::nifti: return open_nifti(path, layout, options.nifti);
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
