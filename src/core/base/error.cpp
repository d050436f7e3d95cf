#include "resoct/base/error.hpp"

#include <string>

namespace resoct {

std::string_view to_string(ErrorCode code) noexcept {
  switch (code) {
    case ErrorCode::invalid_argument: return "invalid_argument";
    case ErrorCode::io: return "io";
    case ErrorCode::truncated: return "truncated";
    case ErrorCode::bad_magic: return "bad_magic";
    case ErrorCode::unsupported_version: return "unsupported_version";
    case ErrorCode::checksum_mismatch: return "checksum_mismatch";
    case ErrorCode::out_of_range: return "out_of_range";
    case ErrorCode::decompress_failed: return "decompress_failed";
    case ErrorCode::size_mismatch: return "size_mismatch";
    case ErrorCode::overflow: return "overflow";
    case ErrorCode::corrupt: return "corrupt";
    case ErrorCode::unsupported: return "unsupported";
    case ErrorCode::device: return "device";
    case ErrorCode::out_of_memory: return "out_of_memory";
  }
  return "unknown";
}

Error::Error(ErrorCode code, const std::string& message)
    : std::runtime_error(message), code_(code) {}

Error invalid_parameter(std::string_view name, std::string_view why) {
  return Error(ErrorCode::invalid_argument,
               "parameter '" + std::string(name) + "': " + std::string(why));
}

Error file_error(ErrorCode code, std::string_view file, std::uint64_t offset,
                 std::string_view what) {
  return Error(code,
               std::string(file) + ": offset " + std::to_string(offset) + ": " + std::string(what));
}

}  // namespace resoct
