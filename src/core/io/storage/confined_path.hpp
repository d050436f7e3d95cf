#pragma once
// Confinement of file names that untrusted files write (a detached NRRD header's data file, a
// zarr key, an entry of a TIFF directory) to the directory that holds them (internal). A file
// that names another file must not make resoct read what its author chose elsewhere on the
// machine (/etc/passwd, another user's data, a device), whoever opens it.

#include <filesystem>
#include <string_view>

namespace resoct::detail {

/// The canonical form of directory `root` (symlinks resolved), the reference for
/// confined_path() and check_confined(). Throws Error(io) naming `root` when it cannot be
/// resolved.
std::filesystem::path canonical_root(const std::filesystem::path& root);

/// Resolves `name`, written in the file `referrer`, against the directory `root` (canonical,
/// from canonical_root). `name` must be relative and must not contain a ".." component; the
/// path it reaches with every symlink resolved (std::filesystem::weakly_canonical: the name may
/// not exist yet) must lie strictly below `root`. Returns that resolved path, so that the
/// caller opens what was checked and not a path whose links could be swapped later. Throws
/// Error(invalid_argument) whose message names `referrer`, `what` (the field) and `name`.
std::filesystem::path confined_path(const std::filesystem::path& root, std::string_view name,
                                    std::string_view referrer, std::string_view what);

/// Checks that `path` (an existing entry of `root`, e.g. found by listing it) resolves, symlinks
/// followed, to a path strictly below `root` (canonical). Returns the resolved path. Throws
/// Error(invalid_argument) naming `referrer` and `path` otherwise.
std::filesystem::path check_confined(const std::filesystem::path& root,
                                     const std::filesystem::path& path, std::string_view referrer);

}  // namespace resoct::detail
