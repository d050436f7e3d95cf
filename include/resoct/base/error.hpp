#pragma once
/// \file
/// The one exception type resoct throws for bad input, bad parameters and failed I/O.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace resoct {

/// Why an operation failed. Each corruption class has its own code so that callers (and the
/// corrupted-store tests) can tell them apart without parsing messages.
enum class ErrorCode : std::uint32_t {
  invalid_argument,     ///< a parameter is out of its documented range
  io,                   ///< the operating system refused a read, write, open or rename
  truncated,            ///< a file ended before the data it announces
  bad_magic,            ///< not a file of the expected kind
  unsupported_version,  ///< a format version this build does not read
  checksum_mismatch,    ///< stored and computed checksums differ
  out_of_range,         ///< an index or offset points outside its container
  decompress_failed,    ///< the codec rejected a payload
  size_mismatch,        ///< a payload decoded to a size other than announced
  overflow,             ///< a size computation would overflow 64 bits
  corrupt,              ///< a field holds a value that cannot be valid
  unsupported,          ///< valid input that this build cannot handle
  device,               ///< a GPU device failed or lacks a required feature
  out_of_memory,        ///< host or device memory was exhausted
};

/// Stable, lowercase name of a code, e.g. "checksum_mismatch".
std::string_view to_string(ErrorCode code) noexcept;

/// Thrown for invalid input at open or configure time. The message names the file and byte
/// offset, or the parameter, that is at fault. Never thrown for ordinary conditions such as a full
/// request set.
class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message);
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

/// Shorthand for the most common case: `throw invalid_parameter("brick_size", "must be >= 4")`.
Error invalid_parameter(std::string_view name, std::string_view why);

/// An error about a file position: the message reads "<file>: offset <n>: <what>".
Error file_error(ErrorCode code, std::string_view file, std::uint64_t offset,
                 std::string_view what);

}  // namespace resoct
