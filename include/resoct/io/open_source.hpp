#pragma once
/// \file
/// One entry point that turns a user-supplied string (a command-line argument, a config entry)
/// into a BrickSource, whatever kind of source it names.

#include <memory>
#include <string_view>

#include "resoct/sources/brick_source.hpp"
#include "resoct/io/formats/nifti.hpp"
#include "resoct/io/http/http_store.hpp"
#include "resoct/io/http/s3_store.hpp"

namespace resoct {

/// The accepted forms, for help texts and error messages.
inline constexpr std::string_view kSourceSpecForms =
    "procedural:NAME[:WxHxD[:CHANNELS]], a resoct brick store (.rbs), an OME-Zarr directory, "
    "a NIfTI-1/2 file (.nii, .nii.gz) or NIfTI / Analyze pair (.hdr + .img), an NRRD file (.nrrd, "
    ".nhdr), a TIFF file or a directory of "
    "TIFF files (.tif, .tiff), stack:SPEC+SPEC+... (sources on one grid as channels), an "
    "http(s):// URL of a brick store or an OME-Zarr image (URL[,PREFIX=URL]..., docs/http.md), or "
    "an s3://bucket/key of one (S3-compatible object stores, docs/http.md)";

/// What a spec names, decided from its prefix, the file's magic bytes (brick store), the
/// directory's content (OME-Zarr: a .zattrs or .zarray; TIFF: .tif/.tiff files) or the file
/// name's extension (case-insensitive).
enum class SourceKind {
  unknown,
  procedural,
  brick_store,
  ome_zarr,
  nifti,
  nrrd,
  tiff,
  stack,
};

/// "unknown", "procedural", "store", "ome-zarr", "nifti", "nrrd", "tiff", "stack".
std::string_view to_string(SourceKind k) noexcept;

/// Classifies `spec` without opening it as a source (a brick store's first bytes are read).
/// A path that does not exist is `unknown`. Thread-safety: a pure function.
SourceKind detect_source_kind(std::string_view spec);

/// How remote sources are reached (network behaviour, S3 endpoint and credentials).
struct SourceOptions {
  HttpOptions http;
  S3Options s3;        ///< empty fields are taken from the environment (resolve_s3_config)
  NiftiOptions nifti;  ///< for NIfTI / Analyze files (the timepoint of a 4-D image)
};

/// Opens the source `spec` names:
/// - `procedural:...` gives make_procedural_source(spec, layout);
/// - a brick store, recognized by its magic bytes (not its extension), gives a
///   BrickStoreSource. `layout` is ignored: a store's brick layout is fixed when it is written;
/// - an OME-Zarr directory, a NIfTI, NRRD or TIFF file, or a directory of TIFF files gives the
///   format's source (include/resoct/io/formats/, docs/formats.md), bricked with `layout`;
/// - `stack:A+B+...` opens every part with open_source and stacks their channels
///   (io/formats/channel_stack.hpp);
/// - an http:// or https:// URL (default HttpOptions, docs/http.md): an OME-Zarr image when the
///   URL has a `.zattrs` or `.zarray` below it, read through an HttpStore (a URL map
///   "URL,PREFIX=URL,..." routes key prefixes to other hosts and always means OME-Zarr), else a
///   brick store read by Range requests (recognized by its magic bytes);
/// - an s3://bucket/key spec: the same, from an S3-compatible object store (options.s3,
///   docs/http.md "S3-compatible object stores"); a missing bucket is an Error(io) saying so.
/// Raw files need extent, type and byte order, so they are not accepted here: open them with
/// open_raw_volume() and wrap the result in an InMemorySource (or convert them with
/// resoct-convert).
/// Throws Error(io) naming the path when it does not exist or cannot be read,
/// Error(invalid_argument) naming the path when it is none of the accepted forms, and whatever
/// the procedural parser or the format readers throw for a bad spec or damaged data. Every
/// message lists the accepted forms when the spec itself is not understood.
/// Thread-safety: a pure function; the returned source is thread-safe as BrickSource requires.
std::unique_ptr<BrickSource> open_source(std::string_view spec, const BrickLayout& layout = {});
/// As above with explicit options for remote sources (the parts of a stack: spec get them too).
std::unique_ptr<BrickSource> open_source(std::string_view spec, const BrickLayout& layout,
                                         const SourceOptions& options);

}  // namespace resoct
