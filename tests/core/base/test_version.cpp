// resoct/version.hpp: the macros agree with each other, with the project version CMake generated
// them from, and with the library loaded at run time.
#include <gtest/gtest.h>

#include <string>

#include "resoct/version.hpp"

namespace resoct::test {
namespace {

TEST(Version, MacrosMatchTheLoadedLibrary) {
  const std::string composed = std::to_string(RESOCT_VERSION_MAJOR) + "." +
                               std::to_string(RESOCT_VERSION_MINOR) + "." +
                               std::to_string(RESOCT_VERSION_PATCH);
  EXPECT_EQ(composed, RESOCT_VERSION_STRING);
  EXPECT_EQ(std::string(library_version()), RESOCT_VERSION_STRING);
  EXPECT_EQ(std::string(library_version()), RESOCT_PROJECT_VERSION);
}

}  // namespace
}  // namespace resoct::test
