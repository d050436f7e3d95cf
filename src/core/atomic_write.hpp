#pragma once
// Internal: replace a file atomically, so readers never see a half-written scene or image and a
// failed write leaves the old file (or nothing) in place.

#include <cstdio>
#include <functional>
#include <string>

namespace resoct::detail {

/// Creates "<path>.tmp-XXXXXX" in the directory of `path` (mkstemp), lets `write` fill it,
/// flushes, fsyncs, renames it over `path` and fsyncs the directory. If anything fails,
/// including `write` throwing or reporting failure by returning false, the temporary is removed
/// and Error(io) naming `path` is thrown (a resoct::Error thrown by `write` propagates as is).
void write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write);

}  // namespace resoct::detail
