#pragma once
/// \file
/// One entry point that turns a user-supplied string (a command-line argument, a config entry)
/// into a BrickSource, whatever kind of source it names.

#include <memory>
#include <string_view>

#include "resoct/brick_source.hpp"

namespace resoct {

/// The accepted forms, for help texts and error messages.
inline constexpr std::string_view kSourceSpecForms =
    "procedural:NAME[:WxHxD[:CHANNELS]], or the path or http(s):// URL of a resoct brick store "
    "(.rbs)";

/// Opens the source `spec` names:
/// - `procedural:...` gives make_procedural_source(spec, layout);
/// - a path to a brick store, recognized by its magic bytes (not its extension), gives a
///   BrickStoreSource. `layout` is ignored: a store's brick layout is fixed when it is written;
/// - an http:// or https:// URL of a brick store gives a BrickStoreSource reading by HTTP Range
///   requests (open_random_access_file, default HttpOptions).
/// Raw files need extent, type and byte order, so they are not accepted here: open them with
/// open_raw_volume() and wrap the result in an InMemorySource (or convert them with
/// resoct-convert).
/// Throws Error(io) naming the path when it does not exist or cannot be read,
/// Error(invalid_argument) naming the path when it is not a brick store, and whatever the
/// procedural parser or the store reader throws for a bad spec or a damaged store. Every
/// message lists the accepted forms when the spec itself is not understood.
/// Thread-safety: a pure function; the returned source is thread-safe as BrickSource requires.
std::unique_ptr<BrickSource> open_source(std::string_view spec, const BrickLayout& layout = {});

}  // namespace resoct
