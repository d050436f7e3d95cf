#include "support/output_path.hpp"

#include <sys/stat.h>

#include "resoct/base/error.hpp"

namespace resoct::tools {

void check_output_path(const std::string& option, const std::string& path) {
  if (path.empty()) throw invalid_parameter(option, "empty path");
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    throw file_error(ErrorCode::io, path, 0, "output directory '" + dir + "' does not exist");
  }
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    throw file_error(ErrorCode::io, path, 0, "output is a directory");
  }
}

}  // namespace resoct::tools
